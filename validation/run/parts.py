"""The parts of a run result (:class:`validation.run.record.RunResult`) and their JSON reading.

Each part is a dataclass whose fields are those of its object in ``result.json``; reading checks
that every field is there and no other (:class:`ResultFileError`, naming the field). Every field and
its unit: docs/results.md.
"""

from __future__ import annotations

import dataclasses
import types
import typing
from dataclasses import dataclass

from bem.checks import InputError

__all__ = ["SCHEMA", "ResultFileError", "BemPart", "FemMesh", "FemPart", "FemProfile", "ClosedForm", "PairMetrics",
           "ForceBalance", "Comparison", "Scales", "StressFem", "StressCoated", "StressBody", "StressPart", "SpotSummary",
           "PeriodicPart", "AxialProfile"]

#: The schema string of ``result.json``; a file with another one is refused.
SCHEMA = "contactlab.result/4"


class ResultFileError(InputError):
    """A ``result.json`` that is not a :class:`RunResult` of :data:`SCHEMA` (a :class:`ValueError`)."""


class _Part:
    """JSON conversion shared by the parts of :class:`RunResult`."""

    def to_json(self):
        """Plain JSON types (:func:`validation.io.to_jsonable`): nested parts as objects, ``None`` as ``null``."""
        from ..io import to_jsonable

        return to_jsonable(dataclasses.asdict(self))

    @classmethod
    def from_json(cls, data, *, where=None, source="result.json"):
        """The part stored as ``data`` (a dict of :meth:`to_json`).

        Raises
        ------
        ResultFileError
            ``data`` is not an object, lacks a field or has a field the schema does not have;
            the message names the field (``where``: its path in the file) and ``source``.
        """
        where = where or cls.__name__
        if not isinstance(data, dict):
            raise ResultFileError(f"{where} = {_short(data)} in {source} is not allowed: it must be an object "
                                  f"(schema {SCHEMA!r}).")
        hints = typing.get_type_hints(cls)
        names = [f.name for f in dataclasses.fields(cls)]
        unknown = sorted(set(data) - set(names))
        if unknown:
            raise ResultFileError(f"{where}.{unknown[0]} in {source} is not allowed: schema {SCHEMA!r} has no such "
                                  f"field (fields of {where}: {', '.join(names)}).")
        missing = [name for name in names if name not in data]
        if missing:
            raise ResultFileError(f"{where}.{missing[0]} is missing in {source}, which is not allowed: schema "
                                  f"{SCHEMA!r} requires it (null where it does not apply).")
        return cls(**{name: _parse(hints[name], data[name], f"{where}.{name}", source) for name in names})


def _short(value):
    text = repr(value)
    return text if len(text) <= 80 else text[:60] + "..."


def _parse(hint, value, where, source):
    """``value`` read as ``hint``: a part, an optional part or a dict of parts; anything else as it is."""
    args = [a for a in typing.get_args(hint) if a is not type(None)]
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        if value is None:
            return None
        hint = args[0] if len(args) == 1 else hint
    if isinstance(hint, type) and issubclass(hint, _Part):
        return hint.from_json(value, where=where, source=source)
    if typing.get_origin(hint) is dict and len(typing.get_args(hint)) == 2:
        item = typing.get_args(hint)[1]
        if isinstance(item, type) and issubclass(item, _Part):
            if not isinstance(value, dict):
                raise ResultFileError(f"{where} = {_short(value)} in {source} is not allowed: it must be an object.")
            return {k: item.from_json(v, where=f"{where}.{k}", source=source) for k, v in value.items()}
    return value


@dataclass
class BemPart(_Part):
    """The BEM solution's scalars (:meth:`bem.ContactResult.summary`) and its lattice.

    ``extent`` and ``nodes_across_contact`` (``2 sqrt(A / pi) / step``) are those of an isolated
    contact, ``None`` for a periodic cell; ``cell``, ``size``, ``mean_pressure``,
    ``contact_fraction`` and ``mean_gap`` those of a periodic cell, ``None`` otherwise.
    ``coating1``, ``coating2``: the coating of each body (``thickness``, ``E``, ``nu``), ``None`` for an
    uncoated body.
    ``history``: per-iteration scalar lists (``residual``, ``p_max``, ``n_contact``, ...).
    ``hardness``: the cap of the pressure (``bodies.hardness``), ``None`` for an elastic solve;
    ``plastic_area``: the area of the nodes at the hardness (0 when elastic); ``plastic_fraction``
    its share of a periodic cell (``None`` otherwise).
    """

    method: str
    converged: bool
    status: str
    message: str
    p_max: float | None
    force: float | None
    approach: float | None
    contact_area: float | None
    contact_radius: float | None
    iterations: int
    n_matvec: int
    kkt_residual: float | None
    rtol: float
    wall_time_s: float
    n_nodes: int
    n_contact: int
    step: float
    E_star: float
    history: dict
    extent: list | None = None
    nodes_across_contact: float | None = None
    cell: list | None = None
    size: list | None = None
    mean_pressure: float | None = None
    contact_fraction: float | None = None
    mean_gap: float | None = None
    hardness: float | None = None
    plastic_area: float | None = None
    plastic_fraction: float | None = None
    coating1: dict | None = None
    coating2: dict | None = None


@dataclass
class FemMesh(_Part):
    """The FEM mesh: estimated contact radius ``a_est`` and element size ``h_fine`` [length] at the
    contact, elements across it ``n_contact_elements``, domain radius / contact radius ``domain_factor``;
    ``edge``: ``[r_e, k]`` of the edge band (``refine_edge``) or ``None``."""

    a_est: float
    h_fine: float
    n_contact_elements: int
    domain_factor: float
    remeshed: bool
    edge: list | None = None


@dataclass
class FemPart(_Part):
    """The FEM reference's scalars (:class:`fem_reference.FemResult`); ``edge_radius``: the interpolated
    edge of the loaded zone [length]; ``timings``, ``penalty``, ``truncation`` as the FEM reports them."""

    p_max: float | None
    force: float | None
    approach: float | None
    edge_radius: float | None
    converged: bool
    status: str
    message: str
    iterations: int
    n_dofs: int
    n_elements: int
    n_elements_across_contact: float | None
    timings: dict
    penalty: dict
    truncation: dict
    mesh: FemMesh


@dataclass
class FemProfile(_Part):
    """The FEM interface pressure ``p`` [pressure] at the radii ``r`` [length]."""

    r: list
    p: list


@dataclass
class ClosedForm(_Part):
    """The closed-form reference (:mod:`bem.reference`): ``kind`` (``"hertz"``, ``"hertz_elliptic"``,
    ``"rigid_layer"``), its scalars (``a``, ``b``: semi-axes of an ellipse, else ``contact_radius``) and
    ``profile`` (``x, p`` along the x axis, ``y, p_y`` along the y axis)."""

    kind: str
    force: float | None
    approach: float | None
    p_max: float | None
    contact_area: float | None
    contact_radius: float | None
    a: float | None
    b: float | None
    profile: dict


@dataclass
class PairMetrics(_Part):
    """One comparison (:func:`validation.compare.pair_metrics`), signed differences ``(a - b) / b``.

    The radius compared is ``contact_radius_rel`` when both sides give ``sqrt(A / pi)`` or an exact
    radius (BEM against a closed form), ``edge_radius_rel`` when a side is the FEM's interpolated edge
    (``None`` in the other field).
    """

    l2_rel: float | None
    max_rel: float | None
    peak_rel: float | None
    contact_radius_rel: float | None
    edge_radius_rel: float | None
    approach_rel: float | None
    force_rel: float | None
    n_points: int


@dataclass
class ForceBalance(_Part):
    """Target force ``target`` [force] and ``|F - P| / P`` of the BEM and the FEM (``None``: no FEM)."""

    target: float
    bem: float | None
    fem: float | None


@dataclass
class Comparison(_Part):
    """The comparisons a run made (:func:`validation.compare.compare`); ``None`` where not made."""

    bem_vs_fem: PairMetrics | None
    bem_vs_analytic: PairMetrics | None
    fem_vs_analytic: PairMetrics | None
    force_balance: ForceBalance | None

    def pairs(self):
        """``{name: PairMetrics}`` of the comparisons made, in the order of the fields."""
        return {name: m for name in ("bem_vs_fem", "bem_vs_analytic", "fem_vs_analytic")
                if (m := getattr(self, name)) is not None}


@dataclass
class Scales(_Part):
    """Hertz's peak, radius, approach and force of the gap's paraboloid without layer (Fig. 5's scale)."""

    p_hertz: float
    a_hertz: float
    approach_hertz: float
    force_hertz: float


@dataclass
class StressFem(_Part):
    """A body's maxima from the FEM's recovered stresses, against the BEM
    (:func:`validation.run.stress.compare_with_fem`)."""

    max_von_mises: float
    max_tresca: float
    on_axis: bool
    axis_depth_of_max: float
    bem_axis_depth_of_max: float
    axis: dict
    max_von_mises_rel: float | None
    max_tresca_rel: float | None
    axis_depth_of_max_rel: float | None


@dataclass
class StressCoated(_Part):
    """A coated body's stresses (:func:`validation.run.stress_coated.coated_block`): von Mises maxima per material,
    the interface tractions' extremes, and the interface along the x-z section (``None``: rigid substrate)."""

    thickness: float
    max_von_mises_coating: float
    location_of_max_coating: list
    max_von_mises_substrate: float | None
    location_of_max_substrate: list | None
    interface_min_sigma_zz: float
    location_of_interface_min_sigma_zz: list
    interface_max_sigma_zz: float
    location_of_interface_max_sigma_zz: list
    interface_max_shear: float
    location_of_interface_max_shear: list
    interface: dict


@dataclass
class StressBody(_Part):
    """One body's stresses (:meth:`bem.SubsurfaceStress.summary`), its axis profile and x-z section; ``coated``
    for a coated body (``None`` otherwise)."""

    nu: float
    max_von_mises: float
    depth_of_max: float
    location_of_max: list
    max_tresca: float
    depth_of_max_tresca: float
    location_of_max_tresca: list
    n_depths: int
    n_points: int
    wall_time_s: float
    axis: dict
    section: dict
    fem: StressFem | None
    coated: StressCoated | None


@dataclass
class StressPart(_Part):
    """The ``[stress]`` part (:func:`validation.run.stress.stress_summary`): depths, scale, time, bodies."""

    depths: list
    scale: float
    wall_time_s: float
    bodies: dict[str, StressBody]


@dataclass
class SpotSummary(_Part):
    """The contact spots of a periodic cell: count, largest and mean area [area], single-node spots."""

    count: int
    largest_area: float
    mean_area: float
    single_node: int


@dataclass
class PeriodicPart(_Part):
    """A periodic cell's summary (:mod:`validation.run.periodic`); ``surface``: the surface's statistics."""

    mean_pressure: float | None
    contact_fraction: float | None
    mean_gap: float | None
    n_spots: int
    spots: SpotSummary
    surface: dict


@dataclass
class AxialProfile(_Part):
    """BEM pressure and closure along the x axis (``x, p, closure``) and the pressure along y (``y_axis``)."""

    x: list
    p: list
    closure: list
    y_axis: dict
