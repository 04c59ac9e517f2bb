"""The results a report is drawn from: a result directory of ``contactlab run``, or a run in memory.

What is read (names from ``result.json["files"]``, else :data:`validation.run.runner.FILES`, the one
list of the files a run writes):

``result.json`` (required)
    The run's :class:`validation.run.record.RunResult` (docs/results.md): the BEM scalars,
    ``bem``, ``layer``, ``profile``, ``scales``, ``unit_symbols``, and, ``None`` unless they
    ran, ``fem`` / ``fem_profile``, ``analytic`` (with its ``profile``), ``comparison``,
    ``stress``, ``periodic``; ``report`` when the scene had a ``[report]``. A file of another
    schema is refused (:class:`validation.run.record.ResultFileError`).
``scene.toml``
    The effective scene (overrides applied): bodies, gap, layer, load, options.
``bem_field.vtu``, ``fem_field.vtu``
    The BEM nodal pressure ``p`` and the FEM's (r, z) von Mises field.

Units are the symbols the run recorded (``unit_symbols``). A report shows each
quantity in one unit, in every table, caption and figure (:meth:`RunResults.display`): the
report's ``units`` (:data:`UNIT_CHOICES`) choose them.
"""

from __future__ import annotations

import functools
import json
import logging
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bem.checks import InputError, check_choice

from ...run.runner import FILES
from ...run.record import RunResult
from ...units import Units, parse_units
from ..render.content import fmt
from ..render.style import report_unit

__all__ = ["RunResults", "Shown", "load_results", "results_of", "units_of", "read_json", "is_number",
           "dimensionless_for", "UNIT_CHOICES", "file_inside"]

log = logging.getLogger(__name__)

#: ``units`` choices of a report: ``"auto"``: readable units (an SI scene's m and Pa shown as mm and
#: MPa, :func:`validation.report.render.style.report_unit`; dimensionless when the scene's units are
#: unknown); ``"scene"``: the scene's own units; ``"dimensionless"``: lengths and pressures divided
#: by the contact's scales (:meth:`RunResults.scales`)
UNIT_CHOICES = ("auto", "scene", "dimensionless")
#: unit kinds :meth:`RunResults.display` converts; any other kind (``"-"``, ``"s"``, ``"rad"``) is shown as it is
_KINDS = ("length", "pressure", "force", "area", "compliance")


class Shown(tuple):
    """``(factor, name, normalised)``: a quantity is shown as ``value / factor`` [``name``].

    ``name`` is the unit symbol (``"mm"``, ``"mm^2"``, ``"mm/MPa"``) or, when ``normalised``,
    the symbol of the scale (``"a_H"``, ``"p_H"``, ``"a_H^2"``).
    """

    __slots__ = ()

    def __new__(cls, factor, name, normalised):
        return super().__new__(cls, (float(factor), str(name), bool(normalised)))

    factor = property(lambda self: self[0])
    name = property(lambda self: self[1])
    normalised = property(lambda self: self[2])


def is_number(value):
    """True for an int or a float of a scene (``scene.toml``) or a sweep's ``summary.json`` (not a bool)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def units_of(result):
    """The :class:`validation.units.Units` a :class:`validation.run.record.RunResult` recorded."""
    return Units.from_dict(result.units, result.unit_symbols)


@dataclass
class RunResults:
    """The results of one run, as a report reads them.

    Attributes
    ----------
    directory : Path
    result : validation.run.record.RunResult or None
        ``result.json`` (``None``: results that only carry units, a sweep without computed points).
    scene : dict
        ``scene.toml`` (empty when missing).
    units : validation.units.Units
    bem_field : tuple of ndarray or None
        ``(x, y, p)``: nodal BEM pressures [length], [pressure].
    fem_field : tuple of ndarray or None
        ``(r, z, triangles, von_mises)`` of the FEM reference [length], [pressure], when it ran.
    dimensionless : bool
        Show lengths and pressures divided by the contact's scales (:meth:`scales`) instead of
        in units (:meth:`display`).
    scene_units : bool
        Show every quantity in the scene's own units (``units = "scene"``); otherwise an SI
        scene's m and Pa are shown as mm and MPa (:func:`validation.report.render.style.report_unit`).
    hertz_peak : str
        The name of Hertz's peak pressure in a dimensionless report (``"p_H"``; the paper
        report calls it ``"p_0"``, as the paper does): one name for it throughout a report.
    files : dict
        ``{key: Path}`` of the run's files found in ``directory`` (keys of
        :data:`validation.run.runner.FILES`); empty for a run in memory.
    """

    directory: Path
    result: RunResult | None
    scene: dict = field(default_factory=dict)
    units: Units = field(default_factory=lambda: parse_units(None))
    bem_field: tuple | None = None
    fem_field: tuple | None = None
    dimensionless: bool = False
    scene_units: bool = False
    hertz_peak: str = "p_H"
    files: dict = field(default_factory=dict)

    def section(self, name):
        """A table of ``scene.toml`` (empty dict when absent)."""
        value = self.scene.get(name)
        return value if isinstance(value, Mapping) else {}

    @property
    def name(self):
        return self.result.scene

    @property
    def title(self):
        return self.result.title

    @property
    def bem(self):
        """The BEM part (:class:`validation.run.record.BemPart`)."""
        return self.result.bem

    @property
    def fem(self):
        """The FEM part (:class:`validation.run.record.FemPart`), or ``None`` when the FEM did not run."""
        return self.result.fem

    @property
    def contact_size(self):
        """The contact radius, else the half-width along x (``None`` for a periodic cell)."""
        r = self.result
        if r.contact_radius is not None:
            return r.contact_radius
        return None if r.contact_extent is None else r.contact_extent["x"]

    @property
    def axisymmetric(self):
        """Axisymmetric scenes record ``contact_radius``."""
        return self.result.axisymmetric

    @property
    def law(self):
        """The name of the layer law the run used, as it recorded it (``result.layer["law"]``), or ``None``
        (smooth bodies): it holds when the law cannot be rebuilt (:attr:`layer` ``None``)."""
        law = (getattr(self.result, "layer", None) or {}).get("law")
        return None if law in (None, "none") else str(law)

    @functools.cached_property
    def layer(self):
        """The :class:`bem.layers.Layer` the run used, or ``None`` (smooth bodies, not rebuildable, or a
        law that names Python code: a report reads a folder as data and never imports code)."""
        from bem.layers import from_dict

        from ...scene.trust import code_names

        params = self.result.layer["parameters"]
        if not isinstance(params, Mapping):
            params = self.section("layer") if self.section("layer").get("law") not in (None, "none") else None
        code = code_names({"layer": params})
        if code:
            log.warning("no w(p) plot: the layer of the run names Python code (%s = %r), and a report never imports "
                        "the code a result names", *code[0])
            return None
        try:
            return from_dict(dict(params)) if params else None
        except (ValueError, TypeError, KeyError) as exc:
            log.warning("the layer of the run cannot be rebuilt (%s): no w(p) plot", exc)
            return None

    def scales(self):
        """``(p0, a, p_name, a_name)`` of a dimensionless report, or ``None`` (scene units).

        Hertz's peak and radius (:attr:`hertz_peak`, ``a_H``) when the run recorded them, else the BEM peak
        pressure and the contact radius (or half-width along x): ``p_{max}``, ``a_c``.
        """
        if not self.dimensionless:
            return None
        sc = self.result.scales
        if sc is not None and sc.p_hertz > 0 and sc.a_hertz > 0:
            return float(sc.p_hertz), float(sc.a_hertz), self.hertz_peak, "a_H"
        p0, a = self.result.p_max, self.contact_size
        return (float(p0), float(a), "p_{max}", "a_c") if p0 and a and p0 > 0 and a > 0 else None


    def display(self, kind, power=1.0):
        """How a quantity of ``kind`` is shown in every table, caption and figure of the report: a
        :class:`Shown` ``(factor, name, normalised)``, the value shown being ``value / factor``.

        ``kind``: ``"length"``, ``"pressure"`` (moduli and stresses too), ``"force"``, ``"area"``
        or ``"compliance"`` (length per pressure to the ``power``, a layer's ``lam``); any other
        kind is returned as the name with factor 1. Lengths and pressures are divided by the
        contact's scales in a dimensionless report (forces stay in units), else shown in the
        scene's units (:attr:`scene_units`) or in readable ones (mm, MPa for an SI scene).
        """
        if kind == "area":
            f, name, norm = self.display("length")
            return Shown(f * f, f"{name}^2" if name != "-" else "-", norm)
        if kind == "compliance":
            (lf, ln, norm), (pf, pn, _) = self.display("length"), self.display("pressure")
            power = float(power)
            exponent = "" if power == 1.0 else f"^{power:g}"
            return Shown(lf / pf**power, f"{ln}/{pn}{exponent}" if "-" not in (ln, pn) else "-", norm)
        if kind not in _KINDS:
            return Shown(1.0, kind, False)
        scales = self.scales() if kind in ("length", "pressure") else None
        if scales is not None:
            return Shown(scales[1], scales[3], True) if kind == "length" else Shown(scales[0], scales[2], True)
        unit = getattr(self.units, kind)
        name, factor = (unit or "", 1.0) if self.scene_units else report_unit(unit)
        return Shown(factor, name or "-", False)

    def shown(self, value, kind, power=1.0):
        """``value`` [scene unit of ``kind``] as :meth:`display` shows it (``None``: not computed, unchanged)."""
        return None if value is None else value / self.display(kind, power).factor

    def engineering(self, kind):
        """``(factor, name)`` of ``kind`` (``"length"``, ``"pressure"``, ``"force"``) in units, never
        scales: those of :meth:`display` when it does not normalise; how a dimensionless report states
        its scales (``a_H = 0.1866 mm``). ``name`` is ``""`` when the scene names no such unit."""
        unit = getattr(self.units, kind)
        name, factor = (unit or "", 1.0) if self.scene_units else report_unit(unit)
        return factor, name

    def units_text(self):
        """The sentence stating the report's units once (in the problem statement)."""
        u = self.units
        scene = f"scene units: {u.label}" if u.label else "the scene names no units"
        (lf, ln, normalised), (pf, pn, _) = self.display("length"), self.display("pressure")
        force = self.display("force").name
        forces = f"forces in {force}" if force != "-" else "forces in the scene's units"
        if normalised:
            def value(factor, kind):
                f, unit = self.engineering(kind)
                return " ".join((fmt(factor / f), unit)).strip()

            of_l = "Hertz's contact radius" if ln == "a_H" else "the contact half-width along x"
            of_p = "Hertz's peak pressure" if pn == self.hertz_peak else "the BEM peak pressure"
            return (f"Units ({scene}): every length is shown divided by {of_l} {ln} = {value(lf, 'length')}, every "
                    f"pressure, modulus and stress divided by {of_p} {pn} = {value(pf, 'pressure')}; {forces}.")
        if not u.known:
            return f"Units: {u.label or 'not named'}."
        return (f"Units ({scene}): throughout this report lengths are in {ln}, pressures, moduli and stresses in "
                f"{pn}, {forces}, areas in {self.display('area').name}.")

def read_json(path):
    """The JSON content of ``path``; InputError when it cannot be read."""
    try:
        return json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError) as exc:  # RecursionError: nested too deep
        raise InputError(f"{path} is not allowed: it must be a readable JSON file ({exc}).") from None


def file_inside(directory, name, entry):
    """``directory / name`` when it resolves to a path inside ``directory``, else ``None``.

    A report reads only files of the folder it reports: a name stored in a result or a sweep
    summary (``entry``, e.g. ``files.scene``) that is absolute, climbs out with ``..`` or goes
    through a link to elsewhere is skipped with a warning naming the entry.
    """
    root = Path(directory).resolve()
    try:
        path = (root / str(name)).resolve()
    except (OSError, RuntimeError, ValueError) as exc:
        log.warning("skipping %s = %r: it cannot be resolved (%s)", entry, name, exc)
        return None
    if not path.is_relative_to(root) or path == root:
        log.warning("skipping %s = %r: it points outside %s, and a report reads only the files inside its folder",
                    entry, str(name), root)
        return None
    return path


def _read_scene(path):
    try:
        with path.open("rb") as fh:
            return tomllib.load(fh)
    except (OSError, tomllib.TOMLDecodeError) as exc:
        log.warning("%s cannot be read (%s): the problem statement is built from result.json alone", path, exc)
        return {}


def _field(path, read):
    """``read(path)``, or None when the file is missing, outside the folder or unreadable (a report
    without that figure)."""
    if path is None or not path.is_file():
        return None
    try:
        return read(path)
    except Exception as exc:  # noqa: BLE001 - any reader error means "no field"
        log.warning("skipping %s: it cannot be read (%s)", path, exc)
        return None


def _bem_field(path):
    import meshio

    mesh = meshio.read(path)
    p = np.asarray(mesh.point_data["p"], dtype=float).ravel()
    if p.size != mesh.points.shape[0]:
        raise ValueError("it has no nodal pressure 'p'")
    return mesh.points[:, 0].copy(), mesh.points[:, 1].copy(), p


def dimensionless_for(units, parsed):
    """Whether a report with ``units`` (:data:`UNIT_CHOICES`) of a run in ``parsed`` units is dimensionless."""
    return check_choice("units", units, UNIT_CHOICES) == "dimensionless" or (units == "auto" and not parsed.known)


def load_results(directory, *, units="auto"):
    """Read a result directory of ``contactlab run`` (see the module docstring).

    ``units`` (:data:`UNIT_CHOICES`) sets :attr:`RunResults.dimensionless` and
    :attr:`RunResults.scene_units`: ``"auto"`` shows readable units (mm, MPa for an SI scene) when the
    scene's units are known, dimensionless otherwise.

    Raises
    ------
    bem.InputError
        ``directory`` is not a directory or has no ``result.json`` of the schema
        :data:`validation.run.record.SCHEMA` (:class:`validation.run.record.ResultFileError`).
    """
    from ..figures.fields import section_field_from_vtu

    directory = Path(directory)
    if not directory.is_dir():
        raise InputError(f"directory = {str(directory)!r} is not allowed: it must be a result directory.")
    main = directory / FILES["result"]
    if not main.is_file():
        raise InputError(f"directory = {str(directory)!r} is not allowed: it has no result.json "
                         "(run the scene first: contactlab run SCENE --out DIR).")
    result = RunResult.read(main)
    stored = result.files or {}
    files = {k: file_inside(directory, v, f"files.{k}" if k in stored else k)
             for k, v in {**FILES, **{k: str(v) for k, v in stored.items()}}.items()}
    scene = _read_scene(files["scene"]) if files["scene"] is not None else {}
    parsed = units_of(result)
    fem = _field(files["fem_field"], section_field_from_vtu) if result.fem is not None else None
    return RunResults(directory=directory, result=result, scene=scene, units=parsed,
                      bem_field=_field(files["bem_field"], _bem_field), fem_field=fem,
                      files={k: p for k, p in files.items() if p is not None and p.is_file()},
                      dimensionless=dimensionless_for(units, parsed), scene_units=units == "scene")


def results_of(outcome, *, units="auto", directory=".", hertz_peak="p_H"):
    """The :class:`RunResults` of a run in memory (:class:`validation.run.RunOutcome`), as
    :func:`load_results` would read them once written (``hertz_peak``: :attr:`RunResults.hertz_peak`)."""
    from ..figures.fields import von_mises_of

    res = outcome.bem
    return RunResults(directory=Path(directory), result=outcome.result, scene=outcome.scene.raw,
                      units=outcome.scene.units, bem_field=(res.x, res.y, res.p),
                      fem_field=None if outcome.fem is None else von_mises_of(outcome.fem),
                      dimensionless=dimensionless_for(units, outcome.scene.units), scene_units=units == "scene",
                      hertz_peak=hertz_peak)
