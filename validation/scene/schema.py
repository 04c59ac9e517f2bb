"""Validators of the sections of a scene file (one function per section).

Each takes the raw TOML table (and what earlier sections produced) and returns the
normalised section, raising :class:`validation.scene.checks.SceneError` that names the dotted key.
Nothing here solves anything: the whole scene is checked before any work.
"""

from __future__ import annotations

import inspect
import math
import re
from functools import partial

from bem import gaps
from bem.gaps import gap_from_dict
from bem.layers import LAWS, from_dict
from bem.materials import effective_modulus
from bem.stress import Z_MAX_STEPS

from ..units import DEFAULT_LABEL as DEFAULT_UNITS
from ..units import parse_units
from . import checks as ck
from .coatings import COATING_KEYS, coating
from .layer_file import is_layer_file, read_layer_file
from .measured import KEYS as MEASURED_KEYS
from .measured import measured_gap
from .paper import ALIASES, PAPER_LAWS, check_layer, is_paper_law, paper_keys
from .rough import GAP_KEYS as ROUGH_GAP_KEYS
from .rough import PERIODIC_KEYS, ROUGH_TYPES, rough_gap
from .sizing import KEYS as BEM_KEYS

__all__ = ["scene_meta", "bodies", "gap", "load", "layer", "fem_options", "analytic", "report", "sweep_spec",
           "stress_options", "stress_depth_bound", "hardness_bound", "scene_keys", "KEYS", "report_sections",
           "REPORT_SECTIONS", "ANALYTIC_KINDS", "DEFAULT_UNITS", "BODY_KEYS", "COATING_KEYS", "Unimported"]

ANALYTIC_KINDS = ("hertz", "hertz_elliptic", "rigid_layer")
_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.-]*$")
BODY_KEYS = ("E1", "nu1", "E2", "nu2")
#: the ``[fem]`` options and their checks, in the order they are checked
_FEM_OPTIONS = {"n_contact_elements": partial(ck.integer, minimum=4, maximum=400),
                **dict.fromkeys(("domain_factor", "fine_radius", "growth", "penalty"), ck.positive), "rtol": ck.rtol,
                "maxiter": partial(ck.integer, minimum=1), "remesh": ck.boolean, "truncation_correction": ck.boolean,
                "refine_edge": partial(ck.integer, minimum=2, maximum=16)}
#: keys of the sections whose keys do not depend on a gap type or layer law (see :func:`scene_keys`)
KEYS = {"scene": ("name", "title", "description", "units"), "bodies": ("E_star", *BODY_KEYS, *COATING_KEYS, "hardness"),
        "load": ("force", "approach", "mean_pressure"), "bem": (*BEM_KEYS, *PERIODIC_KEYS),
        "fem": tuple(_FEM_OPTIONS), "analytic": ("kind",),
        "sweep": ("parameter", "values"), "report": ("sections", "format"),
        "stress": ("depths", "n_depths", "max_depth", "bodies")}
GAP_TYPES = gaps.GAPS
STRESS_BODIES = ("body1", "body2")


def _section(name, d):
    """``d`` must be a table holding only the keys of ``[name]`` (:data:`KEYS`)."""
    ck.table(name, d)
    ck.unknown_keys(name, d, KEYS[name])


def _gap_parameters(cls):
    """The constructor parameters of a :mod:`bem.gaps` shape, by name."""
    return {name: p for name, p in inspect.signature(cls.__init__).parameters.items() if name != "self"}


#: the sections of a run's report in their default order, the names a scene's ``[report] sections``
#: may list; the report registers one function for each
#: (:data:`validation.report.documents.sections.SECTIONS`)
REPORT_SECTIONS = ("scene", "layer_law", "summary", "timings", "profile", "pressure_map", "convergence",
                   "fem_field", "stress", "comparison", "sweep", "rough")


def report_sections():
    """The names a scene's ``[report] sections`` may list (:data:`REPORT_SECTIONS`)."""
    return REPORT_SECTIONS


def scene_keys():
    """Every key a scene file may hold: the schema that ``docs/scenes.md`` documents.

    Returns
    -------
    dict
        ``{section: {variant: keys}}``. Variant ``""`` holds the keys of every table of the
        section; ``[gap]`` has one more variant per gap type (its parameters, from the
        :mod:`bem.gaps` constructors), ``[layer]`` one per law (its :mod:`bem.layers`
        parameters, and the paper's keys for the four paper laws, :mod:`validation.scene.paper`).
    """
    out = {name: {"": keys} for name, keys in KEYS.items()}
    out["gap"] = {"": ("type",), **{kind: tuple(_gap_parameters(cls)) for kind, cls in GAP_TYPES.items()},
                  "measured": tuple(k for k in MEASURED_KEYS if k != "type"), **ROUGH_GAP_KEYS}
    out["layer"] = {"": ("law",)}
    for law, cls in LAWS.items():
        keys = [*cls._required, *cls._optional]
        if law in PAPER_LAWS:
            keys += [k for k in paper_keys(law) if k not in keys]
        out["layer"][law] = tuple(keys) + (("file",) if law == "tabulated" else ())
    return out


def scene_meta(d):
    """``[scene]``: name (required), title, description, units."""
    _section("scene", d)
    name = ck.string("scene.name", ck.require("scene", d, "name", 'give a short name, e.g. name = "hertz"'))
    if not _NAME.match(name):
        raise ck.SceneError(f"scene.name = {name!r} is not allowed: it must be letters, digits, '_', '.', '-' "
                            "(it names the result directory).")
    out = {"name": name, "units": DEFAULT_UNITS, "title": name, "description": ""}
    for key in ("title", "description", "units"):
        if key in d:
            out[key] = ck.string(f"scene.{key}", d[key])
    out["units"] = parse_units(out["units"])
    return out


def bodies(d):
    """``[bodies]``: ``E_star`` alone, or ``E1, nu1, E2, nu2`` (``E = inf``: rigid body) and optionally
    ``coating1``, ``coating2`` (``{thickness, E, nu}``, on the body of that number; ``coatings`` in the
    result: ``{"coating1": {...} or None, "coating2": ...}``, or ``None`` without a coating); and
    ``hardness`` [pressure], the cap of the contact pressure (elastic-perfectly-plastic surface,
    :func:`bem.solve`), ``None`` when absent (elastic)."""
    _section("bodies", d)
    hardness = None if "hardness" not in d else ck.scale("bodies.hardness", d["hardness"])
    coated = [k for k in COATING_KEYS if k in d]
    if coated and "E_star" in d:
        raise ck.SceneError(f"bodies.{coated[0]} is not allowed with bodies.E_star: a coating's substrate is its "
                            "body's material; give bodies.E1, nu1, E2, nu2 instead of E_star.")
    if "E_star" in d:
        if any(k in d for k in BODY_KEYS):
            given = ", ".join(f"bodies.{k}" for k in BODY_KEYS if k in d)
            raise ck.SceneError(f"bodies.E_star = {d['E_star']!r} is not allowed together with {given}: "
                                "give E_star alone or all of E1, nu1, E2, nu2.")
        return {"E_star": ck.scale("bodies.E_star", d["E_star"]), "materials": None, "coatings": None,
                "hardness": hardness}
    for key in BODY_KEYS:
        ck.require("bodies", d, key, "give E1, nu1, E2, nu2 [Pa, -] (or E_star alone)")
    with ck.scene_errors("bodies."):
        E_star = effective_modulus(*(d[k] for k in BODY_KEYS))
    coatings = {k: coating(f"bodies.{k}", d[k]) if k in d else None for k in COATING_KEYS} if coated else None
    return {"E_star": E_star, "materials": {k: float(d[k]) for k in BODY_KEYS}, "coatings": coatings,
            "hardness": hardness}


def hardness_bound(body, load, bem, fem, analytic):
    """``bodies.hardness`` with the rest of the scene: the references that are elastic (``[fem]``,
    ``[analytic]``) are refused with it, and a periodic cell's mean pressure (``load.mean_pressure``, or
    ``load.force`` over the cell) must lie below it (a cell's mean pressure is at most the hardness,
    reached when every node flows)."""
    hardness = body["hardness"]
    if hardness is None:
        return hardness
    for name, part, what in (("fem", fem, "the FEM reference"), ("analytic", analytic, "the closed form")):
        if part is not None:
            raise ck.SceneError(f"bodies.hardness = {hardness!r} is not allowed with [{name}]: {what} is elastic; "
                                f"remove [{name}] or the hardness.")
    if bem.get("periodic"):
        lx, ly = bem["size"]
        key, mean = (("mean_pressure", load["mean_pressure"]) if load.get("mean_pressure") is not None
                     else ("force", None if load["force"] is None else load["force"] / (lx * ly)))
        if mean is not None and mean >= hardness:
            raise ck.SceneError(f"bodies.hardness = {hardness!r} is not allowed with load.{key} = {load[key]!r}: the "
                                f"cell's mean pressure {mean:.6g} must be below the hardness (it is at most the "
                                "hardness, reached when every node flows).")
    return hardness


class Unimported(gaps.Gap):
    """Stands for a gap whose Python code was not imported (``contactlab check``): no estimate of
    the contact size, unbounded; it is never evaluated."""

    def __init__(self, type_name):
        self.type_name = type_name

    def _evaluate(self, x, y):
        raise ck.SceneError(f"gap.type = {self.type_name!r}: its code was not imported (contactlab check).")


def gap(d, E_star, *, units=None, build=True, base_dir=None):
    """``[gap]``: ``type`` and the parameters of the :mod:`bem.gaps` shape; returns (spec, Gap).

    ``build = False`` checks the keys only and returns an :class:`Unimported` stand-in for a shape
    that would import the Python code the scene names (:mod:`validation.scene.trust`).

    A log-crowned roller given by ``design_force`` takes ``E_star`` from ``[bodies]`` when the
    gap table leaves it out. ``type = "measured"`` reads a file (:mod:`validation.scene.measured`;
    ``units`` is the scene's units label) and returns a
    :class:`bem.gaps.Measured`, which the scene turns into a gap table over the candidate
    region.
    """
    ck.table("gap", d)
    kinds = (*GAP_TYPES, "measured", *ROUGH_TYPES)
    kind = ck.require("gap", d, "type", "give one of " + ", ".join(map(repr, kinds)))
    ck.choice("gap.type", kind, kinds)
    if kind == "measured":
        return measured_gap(d, units=units)
    if kind in ROUGH_TYPES:
        return rough_gap(d, units=units, base_dir=base_dir)
    params = _gap_parameters(GAP_TYPES[kind])
    ck.unknown_keys("gap", d, ["type", *params])
    spec = dict(d)
    if kind == "crowned_roller" and "design_force" in spec and "E_star" not in spec:
        spec["E_star"] = E_star
    for name, p in params.items():
        if p.default is inspect.Parameter.empty and name not in spec:
            raise ck.SceneError(f"gap.{name} is missing: a {kind!r} gap needs " + ", ".join(params) + ".")
    if not build:
        return spec, Unimported(kind)
    with ck.scene_errors("gap."):
        shape = gap_from_dict(spec)
    return spec, shape


def load(d):
    """``[load]``: exactly one of ``force`` [N], ``approach`` [m] and (periodic scenes) ``mean_pressure``
    [Pa], in :data:`bem.checks.SCALE_RANGE`; ``mean_pressure`` is in the dict only when given."""
    _section("load", d)
    key = ck.exactly_one("load", d, KEYS["load"], "force control: force [N]; approach control: "
                         "approach [m]; a periodic cell: mean_pressure [Pa]")
    return {"force": None, "approach": None, key: ck.scale(f"load.{key}", d[key])}


def layer(d, *, build=True, E_star=None):
    """``[layer]``: ``(spec, law)``; see :func:`validation.scene.paper.check_layer`, and
    :mod:`validation.scene.layer_file` for a tabulated law read from a ``file`` (``E_star``: the
    scene's modulus [pressure], compared with the file's).

    ``law`` is the :mod:`bem.layers` object, built here once from direct parameters (which
    checks their values); ``None`` without a layer (absent or ``law = "none"``), for a law of
    the paper's parameters, which the runner resolves by a solve, and with ``build = False``
    (a law whose Python code is not imported, :mod:`validation.scene.trust`).
    """
    if is_layer_file(d):
        spec = read_layer_file(d, E_star)
        with ck.scene_errors("layer."):
            return spec, from_dict({k: spec[k] for k in ("law", "p", "w")})
    spec = check_layer(d, "layer")
    if spec is None or is_paper_law(spec) or not build:
        return spec, None
    with ck.scene_errors("layer."):
        return spec, from_dict(spec)


def fem_options(d, shape, materials):
    """``[fem]``: options of :func:`fem_reference.solve`; axisymmetric gaps and E1..nu2 only."""
    if d is None:
        return None
    _section("fem", d)
    if not shape.is_axisymmetric:
        raise ck.SceneError(f"fem = {{...}} is not allowed with gap.type = {shape.type_name!r}: the FEM "
                            "reference is axisymmetric; remove [fem] or use an axisymmetric gap.")
    if materials is None:
        raise ck.SceneError("fem = {...} is not allowed with bodies.E_star: the FEM models each body; "
                            "give bodies.E1, nu1, E2, nu2.")
    for key in ("E1", "E2"):
        if not math.isfinite(materials[key]):
            raise ck.SceneError(f"bodies.{key} = inf is not allowed with [fem]: the FEM bodies are elastic.")
    for key in ("nu1", "nu2"):
        if materials[key] > 0.499:
            raise ck.SceneError(f"bodies.{key} = {materials[key]!r} is not allowed with [fem]: it must be "
                                "<= 0.499 (the displacement FEM locks).")
    out = ck.options("fem", d, _FEM_OPTIONS)
    domain, fine = out.get("domain_factor", 40.0), out.get("fine_radius", 1.5)
    if domain < 4 * fine:
        raise ck.SceneError(f"fem.domain_factor = {domain!r} is not allowed: it must be >= 4 * fem.fine_radius = "
                            f"{4 * fine!r} (domain size in expected contact radii).")
    return out


def analytic(d, shape, layer_spec):
    """``[analytic]``: ``kind`` of the closed-form comparison and its applicability."""
    if d is None:
        return None
    _section("analytic", d)
    kind = ck.choice("analytic.kind", ck.require("analytic", d, "kind", "give one of " + ", ".join(
        map(repr, ANALYTIC_KINDS))), ANALYTIC_KINDS)
    t = shape.type_name
    if kind in ("hertz", "hertz_elliptic"):
        if layer_spec is not None:
            raise ck.SceneError(f"analytic.kind = {kind!r} is not allowed with layer.law = {layer_spec['law']!r}: "
                                "Hertz's solution has no layer; remove [analytic] or the layer.")
        if kind == "hertz":
            ok = t == "paraboloid" or (t == "elliptic_paraboloid" and shape.is_axisymmetric)
            need = "paraboloid (or an elliptic_paraboloid with Rx = Ry)"
        else:
            ok = t in ("paraboloid", "elliptic_paraboloid")
            need = "elliptic_paraboloid or paraboloid"
        if not ok:
            raise ck.SceneError(f"analytic.kind = {kind!r} is not allowed with gap.type = {t!r}: it needs a "
                                f"{need} gap.")
    else:
        law = None if layer_spec is None else layer_spec["law"]
        if t != "paraboloid" or law not in ("linear", "power", "root"):
            raise ck.SceneError(f"analytic.kind = 'rigid_layer' is not allowed with gap.type = {t!r} and "
                                f"layer.law = {law!r}: it needs a paraboloid gap and a linear, power or root layer.")
    return {"kind": kind}


def report(d):
    """``[report]``: ``sections`` (names checked) and ``format``."""
    if d is None:
        return None
    _section("report", d)
    out = {"format": ck.choice("report.format", d.get("format", "html"), ("html", "markdown", "both"))}
    out["sections"] = ck.names("report.sections", d.get("sections", ["summary"]), report_sections(),
                               'section names, e.g. ["summary", "profile"]')
    return out


def sweep_spec(d, known_sections):
    """``[sweep]``: ``parameter`` (alpha_a, alpha_b, alpha_c or a dotted key) and ``values``."""
    if d is None:
        return None
    _section("sweep", d)
    param = ck.string("sweep.parameter", ck.require("sweep", d, "parameter",
                                                    "give alpha_a, alpha_b, alpha_c or a dotted key like layer.lam"))
    key = ALIASES.get(param, param)
    parts = key.split(".")
    if len(parts) < 2 or parts[0] not in known_sections or parts[0] in ("scene", "sweep", "report") or not all(parts):
        raise ck.SceneError(f"sweep.parameter = {param!r} is not allowed: it must be alpha_a, alpha_b, alpha_c "
                            "or a dotted key section.key of bodies, gap, layer, load, bem, fem (e.g. load.force).")
    values = ck.require("sweep", d, "values", "give a list of numbers, e.g. values = [0.0, 0.5, 1.0]")
    if not isinstance(values, list) or not values:
        raise ck.SceneError(f"sweep.values = {values!r} is not allowed: it must be a non-empty list.")
    ck.sweep_size("sweep.values", values, len(values))
    for i, value in enumerate(values):
        if isinstance(value, bool) or not isinstance(value, (int, float, str)):
            raise ck.SceneError(f"sweep.values[{i}] = {value!r} is not allowed: it must be a number or a string.")
        if isinstance(value, float) and not math.isfinite(value):
            raise ck.SceneError(f"sweep.values[{i}] = {value!r} is not allowed: it must be finite.")
    if len(set(map(repr, values))) != len(values):
        raise ck.SceneError(f"sweep.values = {values!r} is not allowed: the values must be distinct.")
    return {"parameter": param, "key": key, "values": list(values)}


def stress_options(d, materials, step=None):
    """``[stress]``: ``depths`` (``"auto"`` or a list [m], at most :data:`bem.stress.Z_MAX_STEPS`
    lattice steps ``step`` [m] deep), ``n_depths`` and ``max_depth`` (with ``"auto"``: that many
    depths from 0 down to ``max_depth`` contact half-widths), ``bodies``."""
    if d is None:
        return None
    _section("stress", d)
    if materials is None:
        raise ck.SceneError("stress = {...} is not allowed with bodies.E_star: the stresses depend on each body's "
                            "Poisson ratio; give bodies.E1, nu1, E2, nu2.")
    depths = d.get("depths", "auto")
    out = {"depths": depths}
    if depths == "auto":
        out["n_depths"] = ck.integer("stress.n_depths", d.get("n_depths", 32), 2, 1000)
        out["max_depth"] = ck.in_range("stress.max_depth", d.get("max_depth", 3.0), 0.0, 50.0, low_open=True)
    else:
        for key in ("n_depths", "max_depth"):
            if key in d:
                raise ck.SceneError(f"stress.{key} = {d[key]!r} is not allowed with a list of stress.depths: it sets "
                                    'the depths of depths = "auto" only.')
        if not isinstance(depths, list) or not depths or len(depths) > 1000:
            raise ck.SceneError(f"stress.depths = {depths!r} is not allowed: it must be \"auto\" or a list of 1 to "
                                "1000 depths below the surface [m], e.g. [0.0, 1e-4, 2e-4].")
        out["depths"] = [ck.nonnegative(f"stress.depths[{i}]", v) for i, v in enumerate(depths)]
        deepest = math.inf if step is None else Z_MAX_STEPS * step
        for i, z in enumerate(out["depths"]):
            if z > deepest:
                raise ck.SceneError(f"stress.depths[{i}] = {z!r} is not allowed: it must be at most {Z_MAX_STEPS:g} "
                                    f"lattice steps ({deepest:.6g} m) below the surface.")
        if len(set(out["depths"])) != len(depths):
            raise ck.SceneError(f"stress.depths = {depths!r} is not allowed: the depths must be distinct.")
    bodies = ck.names("stress.bodies", d.get("bodies", list(STRESS_BODIES)), STRESS_BODIES,
                      f"{', '.join(map(repr, STRESS_BODIES))} (body1: E1, nu1; body2: E2, nu2)")
    if len(set(bodies)) != len(bodies):
        raise ck.SceneError(f"stress.bodies = {bodies!r} is not allowed: name each body once.")
    out["bodies"] = bodies
    return out


#: deepest stress depth of a ``[stress] depths`` list, in half-widths of the candidate region
MAX_DEPTH_REGIONS = 100.0


def stress_depth_bound(stress, extent):
    """``[stress] depths`` (a list) at most :data:`MAX_DEPTH_REGIONS` times the larger half-width of
    the candidate region ``extent`` [m] (``bem.extent``): deeper, the stresses vanish and overflow."""
    if stress is None or stress["depths"] == "auto":
        return stress
    bound = MAX_DEPTH_REGIONS * max(extent)
    for i, depth in enumerate(stress["depths"]):
        if depth > bound:
            raise ck.SceneError(f"stress.depths[{i}] = {depth!r} is not allowed: a depth must be <= "
                                f"{MAX_DEPTH_REGIONS:g} times the candidate region's half-width (bem.extent), "
                                f"<= {bound:.6g} here.")
    return stress
