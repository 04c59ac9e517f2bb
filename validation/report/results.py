"""Reading a result directory written by ``contactlab run`` (:func:`validation.run.runner.run_scene`).

What is read (the names are those of :data:`validation.run.runner.FILES`, taken from
``result.json["files"]`` when present):

``result.json`` (required)
    The run's result dict (:func:`validation.run.result.build_result`, schema
    ``contactlab.result/1``): top-level BEM scalars ``p_max``, ``force``, ``approach``,
    ``contact_area``, ``contact_radius`` (axisymmetric scenes), ``contact_extent``,
    ``iterations``, ``converged``, ``kkt_residual``, ``message``, ``messages``,
    ``wall_time_s`` ``{bem, fem, layer_reference, total}``; ``bem`` (the BEM summary with
    ``step``, ``extent``, ``n_nodes``, ``n_contact``, ``E_star``, ``history``), ``layer``
    (``law``, ``parameters`` and the paper quantities ``c_nn``, ``p_max_lambda``, ...),
    ``profile`` (the axial sections), ``scales`` (Hertz ``p_hertz``, ``a_hertz``, ... of a
    paraboloid), and only when they ran ``fem`` / ``fem_profile``, ``analytic`` and
    ``comparison``; ``scene``, ``title``, ``units`` (the scene's units label).
``scene.toml``
    The effective scene (overrides applied): bodies, gap, layer, load, options.
``bem_field.vtu``, ``fem_field.vtu``
    The BEM nodal field (pressure ``p`` on the lattice nodes) and the FEM (r, z) field.
"""

from __future__ import annotations

import json
import logging
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bem.checks import InputError, check_choice

__all__ = ["RunResults", "Units", "load_results", "parse_units", "display_unit", "report_unit", "REPORT_UNITS",
           "UNIT_CHOICES"]

log = logging.getLogger(__name__)

_DEFAULT_FILES = {"result": "result.json", "scene": "scene.toml", "bem_field": "bem_field.vtu",
                  "fem_field": "fem_field.vtu"}
_KINDS = {  # unit kind -> regular expression of a unit token of that kind
    "pressure": re.compile(r"^(?:[kMG]?Pa|psi|ksi|bar)$"),
    "force": re.compile(r"^(?:[mkM]?N|lbf|kgf)$"),
    "length": re.compile(r"^(?:[nuµcmk]?m|in|ft)$"),
}


@dataclass(frozen=True)
class Units:
    """Units of a scene, parsed from its ``[scene] units`` label.

    Attributes
    ----------
    label : str
        The label as written in the scene (e.g. ``"SI (m, Pa, N)"``).
    length, pressure, force : str or None
        Unit symbols; ``None`` when the label does not name them.
    """

    label: str
    length: str | None = None
    pressure: str | None = None
    force: str | None = None

    @property
    def known(self):
        """Whether all three units were recognised."""
        return None not in (self.length, self.pressure, self.force)

    def of(self, kind):
        """Unit of a quantity kind: ``length``, ``pressure``, ``force``, ``area``,
        ``compliance`` (length/pressure), ``s`` or ``-``; ``"-"`` when unknown."""
        if kind in ("-", "s"):
            return kind
        if kind == "area":
            return f"{self.length}^2" if self.length else "-"
        if kind == "compliance":
            return f"{self.length}/{self.pressure}" if self.length and self.pressure else "-"
        return getattr(self, kind, None) or "-"

    def as_dict(self):
        """``{"length", "pressure", "force"}`` of the known units."""
        return {k: v for k, v in (("length", self.length), ("pressure", self.pressure), ("force", self.force)) if v}


_PREFIXES = {"m": (("", 1.0), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9)),
             "Pa": (("GPa", 1e9), ("MPa", 1e6), ("kPa", 1e3), ("", 1.0)),
             "N": (("MN", 1e6), ("kN", 1e3), ("", 1.0), ("mN", 1e-3))}


def display_unit(unit, magnitude):
    """``(symbol, factor)`` to draw values of size ``magnitude`` [unit] as ``value / factor``.

    SI base units (m, Pa, N) get the prefix that puts ``magnitude`` in [1, 1000)
    (e.g. 1.9e-4 m -> ("µm", 1e-6)); any other unit is kept (factor 1, "" when unknown).
    """
    if unit not in _PREFIXES:
        return (unit or ""), 1.0
    choices = _PREFIXES[unit]
    if not (magnitude > 0 and np.isfinite(magnitude)):
        return unit, 1.0
    for prefix, factor in choices:
        if magnitude >= factor:
            return (prefix or unit), factor
    prefix, factor = choices[-1]
    return (prefix or unit), factor


#: how a report draws values in an SI base unit: lengths in mm, pressures and stresses in MPa
REPORT_UNITS = {"m": ("mm", 1e-3), "Pa": ("MPa", 1e6)}
#: ``units`` choices of a report: the scene's units (``"auto"``: when its label names them), or
#: lengths and pressures divided by the contact's scales
UNIT_CHOICES = ("auto", "scene", "dimensionless")


def report_unit(unit):
    """``(symbol, factor)`` to draw values in ``unit`` as ``value / factor``: m as mm and Pa as MPa
    (:data:`REPORT_UNITS`), any other unit as it is ("" when unknown)."""
    return REPORT_UNITS.get(unit, (unit or "", 1.0))


def parse_units(label):
    """Units named by a scene's units label.

    ``"SI (m, Pa, N)"`` and ``"SI"`` give m, Pa, N; ``"mm, MPa, N"`` gives mm, MPa, N; the
    tokens may come in any order (each is recognised by its form). A label naming none
    (e.g. ``"normalised: R = E* = P = 1"``) gives unknown units.
    """
    label = str(label or "SI (m, Pa, N)")
    inner = re.search(r"\(([^)]*)\)", label)
    tokens = re.split(r"[\s,;/]+", inner.group(1) if inner else label)
    found = {}
    for token in (t.strip() for t in tokens if t.strip()):
        for kind, rx in _KINDS.items():
            if rx.match(token):
                found.setdefault(kind, token)
    if not found and re.match(r"^\s*SI\b", label):
        found = {"length": "m", "pressure": "Pa", "force": "N"}
    return Units(label, **found)


@dataclass
class RunResults:
    """The content of a result directory.

    Attributes
    ----------
    directory : Path
    data : dict
        ``result.json``.
    scene : dict
        ``scene.toml`` (empty when missing).
    units : Units
    bem_field : tuple of ndarray or None
        ``(x, y, p)`` nodal BEM pressures [length], [pressure].
    fem_field_path : Path or None
        The FEM field file, when the FEM ran.
    dimensionless : bool
        Draw lengths and pressures divided by the contact's scales (Hertz's radius and peak
        of a paraboloid, else the contact half-width and the peak pressure) instead of in the
        scene's units (:func:`report_unit`).
    """

    directory: Path
    data: dict
    scene: dict = field(default_factory=dict)
    units: Units = field(default_factory=lambda: parse_units(None))
    bem_field: tuple | None = None
    fem_field_path: Path | None = None
    dimensionless: bool = False

    def section(self, name):
        """A table of ``scene.toml`` (empty dict when absent)."""
        value = self.scene.get(name)
        return value if isinstance(value, Mapping) else {}

    @property
    def name(self):
        return str(self.data.get("scene") or self.section("scene").get("name") or self.directory.name)

    @property
    def title(self):
        return str(self.data.get("title") or self.section("scene").get("title") or self.name)

    @property
    def bem(self):
        value = self.data.get("bem")
        return value if isinstance(value, Mapping) else {}

    @property
    def fem(self):
        """The FEM summary, or ``None`` when the FEM did not run."""
        value = self.data.get("fem")
        return value if isinstance(value, Mapping) else None

    @property
    def axisymmetric(self):
        """Axisymmetric scenes record ``contact_radius``."""
        return self.data.get("contact_radius") is not None

    def get(self, key, default=None):
        """A top-level entry of ``result.json`` that is a dict (``default`` otherwise)."""
        value = self.data.get(key)
        return value if isinstance(value, Mapping) else default


def _read_json(path):
    try:
        return json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise InputError(f"{path} is not allowed: it must be a readable JSON file ({exc}).") from None


def _read_scene(path):
    if not path.is_file():
        log.warning("%s is missing: the problem statement is built from result.json alone", path)
        return {}
    try:
        with path.open("rb") as fh:
            return tomllib.load(fh)
    except (OSError, tomllib.TOMLDecodeError) as exc:
        log.warning("%s is not readable TOML (%s): the problem statement is built from result.json alone",
                    path, exc)
        return {}


def _bem_field(path):
    """``(x, y, p)`` of the BEM ``.vtu`` (pressure array ``p``), or None."""
    if not path.is_file():
        return None
    import meshio

    try:
        mesh = meshio.read(path)
    except Exception as exc:  # noqa: BLE001 - any reader error means "no field"
        log.warning("skipping %s: meshio cannot read it (%s)", path, exc)
        return None
    p = mesh.point_data.get("p")
    if p is None or np.asarray(p).size != mesh.points.shape[0]:
        log.warning("skipping %s: it has no nodal pressure 'p'", path)
        return None
    return mesh.points[:, 0].copy(), mesh.points[:, 1].copy(), np.asarray(p, dtype=float).ravel()


def load_results(directory, *, units="auto"):
    """Read a result directory of ``contactlab run`` (see the module docstring).

    ``units`` (:data:`UNIT_CHOICES`) sets :attr:`RunResults.dimensionless`: ``"auto"``
    draws in the scene's units when its units label names them, dimensionless otherwise.

    Raises
    ------
    bem.InputError
        ``directory`` is not a directory or has no readable ``result.json`` holding an object.
    """
    directory = Path(directory)
    if not directory.is_dir():
        raise InputError(f"directory = {str(directory)!r} is not allowed: it must be a result directory.")
    main = directory / _DEFAULT_FILES["result"]
    if not main.is_file():
        raise InputError(f"directory = {str(directory)!r} is not allowed: it has no result.json "
                         "(run the scene first: contactlab run SCENE --out DIR).")
    data = _read_json(main)
    if not isinstance(data, Mapping):
        raise InputError(f"{main} is not allowed: it must hold a JSON object.")
    if not str(data.get("schema", "")).startswith("contactlab.result/"):
        log.warning("%s has schema %r: it was not written by contactlab run; parts may be missing",
                    main, data.get("schema"))
    files = dict(_DEFAULT_FILES)
    if isinstance(data.get("files"), Mapping):
        files.update({k: str(v) for k, v in data["files"].items()})
    scene = _read_scene(directory / files["scene"])
    label = data.get("units") or (scene.get("scene") or {}).get("units")
    parsed = parse_units(label)
    units = check_choice("units", units, UNIT_CHOICES)
    res = RunResults(directory=directory, data=dict(data), scene=scene, units=parsed,
                     bem_field=_bem_field(directory / files["bem_field"]),
                     dimensionless=units == "dimensionless" or (units == "auto" and not parsed.known))
    fem_path = directory / files["fem_field"]
    if isinstance(data.get("fem"), Mapping) and fem_path.is_file():
        res.fem_field_path = fem_path
    return res
