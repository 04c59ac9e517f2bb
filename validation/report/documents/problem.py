"""The problem statement of a run's report (the section ``scene``): gap, materials, layer law, load, units.

Everything is read from the effective scene (``scene.toml``) and the run's ``result.json``: the
layer is the one the solver used (``result.layer["parameters"]``), with the paper's relative
parameters (``lam_over_cnn``, ``alpha_a``, ...) shown next to the values they resolved to. Values
are shown in the report's units (:meth:`validation.report.documents.results.RunResults.display`),
which the section's text states once.
"""

from __future__ import annotations

from collections.abc import Mapping

from bem.gaps import GAPS

from ...scene.rough import GAP_UNITS as ROUGH_GAP_UNITS
from ...units import METRES
from .results import is_number
from ..render.content import Section, Table, fmt
from ..render.style import method_text

__all__ = ["scene_section"]

_LAW_TEXT = {
    "linear": "linear (Winkler) layer w = lam p",
    "elastic_rigid": "elastic-rigid layer w = lam min(p, p_cr)",
    "bilinear": "bilinear layer: slope lam1 up to p_star, lam2 beyond",
    "root": "root layer w = lam sqrt(p)",
    "power": "power-law layer w = lam p^s",
    "tabulated": "tabulated layer: w(p) linear between the measured points",
    "series": "two layers in series: w = w1(p) + w2(p)",
    "custom": "user-defined layer law",
}
_MEASURED = "measured surface read from a file, interpolated onto the lattice"
_PAPER_ROWS = (("c_nn", "C_nn = c w_t(0,0) / (pi E*), diagonal influence coefficient (eq. 6) of this lattice",
                "compliance"),
               ("lam_over_cnn", "lam / C_nn on this lattice", "-"),
               ("lam_ref", "compliance of the linear reference layer", "compliance"),
               ("p_max_lambda", "p_max^lambda: peak with the linear layer lam (reference solve)", "pressure"),
               ("alpha_a", "alpha_a = p_cr / p_max^lambda (paper parameter)", "-"),
               ("alpha_c", "alpha_c = arctan(lam2 / lam1) (paper parameter)", "rad"),
               ("alpha_b", "alpha_b = p_max / p_max^lambda", "-"))
_MATERIALS = (("E1", "Young's modulus E1 (body 1)"), ("nu1", "Poisson's ratio nu1 (body 1)"),
              ("E2", "Young's modulus E2 (body 2)"), ("nu2", "Poisson's ratio nu2 (body 2)"))


def _param_kind(law, key, params):
    """``(kind, power)`` of a layer parameter for :meth:`RunResults.display`."""
    if key in ("p_cr", "p_star"):
        return "pressure", 1.0
    if key in ("lam", "lam1", "lam2"):
        return "compliance", {"root": 0.5, "power": float(params.get("s", 1.0))}.get(law, 1.0)
    return "-", 1.0


def _layer_rows(res):
    """Rows of the layer: its law, the parameters used, and the paper's relative ones."""
    info = res.result.layer
    params = info["parameters"] or {}
    law = params.get("law") or info.get("law") or res.section("layer").get("law")
    if law in (None, "none"):
        return [("interface layer", "none (smooth bodies, w = 0)", "-")]
    rows = [("interface layer", _LAW_TEXT.get(law, law), "-")]
    for key, value in params.items():
        if key == "law":
            continue
        if isinstance(value, list) and law == "tabulated":
            kind = "pressure" if key == "p" else "length"
            shown = [res.shown(v, kind) for v in value]
            rows.append((f"layer {key} (table)", f"{len(value)} points, {fmt(min(shown))} to {fmt(max(shown))}",
                         res.display(kind).name))
        elif is_number(value):
            kind, power = _param_kind(law, key, params)
            rows.append((f"layer {key}", fmt(res.shown(value, kind, power)), res.display(kind, power).name))
        elif isinstance(value, Mapping):
            rows.append((f"layer {key}", _LAW_TEXT.get(value.get("law"), str(value.get("law", "?"))), "-"))
    for key, text, kind in _PAPER_ROWS:
        value = info.get(key)
        if key == "alpha_b" and key not in res.section("layer"):
            continue  # an output unless the scene gave it (then the layer was fitted to it)
        if key == "lam_ref" and value == params.get("lam"):
            continue
        if is_number(value):
            rows.append((text, fmt(res.shown(value, kind)), res.display(kind).name))
    return rows


def _file_length(res, value, file_unit):
    """``(value, unit)`` of a measured file's length (in its ``length_unit``: a unit symbol or the factor
    to the scene's length unit) in the report's length unit; as the file gives it when either unit is unknown."""
    if is_number(file_unit):
        to_scene = float(file_unit)
    else:
        to_scene = METRES.get(file_unit) and res.units.metres and METRES[file_unit] / res.units.metres
    if not to_scene:
        return fmt(value), file_unit if isinstance(file_unit, str) else res.units.of("length")
    return fmt(res.shown(value * to_scene, "length")), res.display("length").name


def _gap_rows(res):
    gap = res.section("gap") or {"type": "not recorded"}
    kind = str(gap.get("type", "?"))
    shape = GAPS.get(kind)  # the shape says what it is and the kind of each parameter
    rows = [("gap h(x, y)", _MEASURED if kind == "measured" else shape.describe() if shape else kind, "-")]

    def kind_of(key):
        return shape.units.get(key, "-") if shape else ROUGH_GAP_UNITS.get(key, "-")

    for key, value in gap.items():
        if key == "type":
            continue
        if kind == "measured" and key in ("spacing", "nodata") and is_number(value):
            rows.append((f"gap {key}", *_file_length(res, value, gap.get("length_unit"))))
        elif is_number(value):
            rows.append((f"gap {key}", fmt(res.shown(value, kind_of(key))), res.display(kind_of(key)).name))
        elif isinstance(value, str):
            rows.append((f"gap {key}", value, "-"))
        elif isinstance(value, list) and len(value) == 2 and all(isinstance(v, (int, float)) for v in value):
            rows.append((f"gap {key}", ", ".join(fmt(res.shown(v, kind_of(key))) for v in value),
                         res.display(kind_of(key)).name))
        elif isinstance(value, list):
            rows.append((f"gap {key}", f"table of {len(value)} values", "-"))
    return rows


def _material_rows(res):
    bodies, pressure = res.section("bodies"), res.display("pressure")
    rows = [(label, fmt(float(bodies[key])), "-") if key.startswith("nu") else
            (label, fmt(res.shown(float(bodies[key]), "pressure")), pressure.name)
            for key, label in _MATERIALS if key in bodies]
    rows.append(("effective modulus E* = 1 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2)",
                 fmt(res.shown(float(res.bem.E_star), "pressure")), pressure.name))
    return rows


def _load_rows(res):
    load = res.section("load")
    if "force" in load:
        return [("load: total force P (force control)", fmt(res.shown(float(load["force"]), "force")),
                 res.display("force").name)]
    if "approach" in load:
        return [("load: approach delta (approach control)", fmt(res.shown(float(load["approach"]), "length")),
                 res.display("length").name)]
    if "mean_pressure" in load:  # a periodic cell
        return [("load: mean pressure over the cell", fmt(res.shown(float(load["mean_pressure"]), "pressure")),
                 res.display("pressure").name)]
    return []


def scene_section(res, work):
    """The problem statement: the effective scene's inputs (``work``: unused, no figure)."""
    meta, law = res.section("scene"), getattr(res.layer, "law", None)
    text = [str(meta["description"])] if meta.get("description") else []
    text.append("Frictionless normal contact of two elastic half-spaces whose surfaces are separated by the "
                "initial gap h(x, y)" + (", with an interface layer between them whose closure w(p) depends "
                                         "on the contact pressure p." if law else " (no interface layer).")
                + f" Solved by the BEM: {method_text(res.result.method, law)}.")
    if res.result.overrides:
        text.append("Scene overrides of this run: " + ", ".join(map(str, res.result.overrides)) + ".")
    text.append(res.units_text())
    rows = _gap_rows(res) + _material_rows(res) + _layer_rows(res) + _load_rows(res)
    return Section("Problem statement", kind="problem", text=tuple(text), items=(
        Table(("quantity", "value", "unit"), tuple(rows),
              caption="Input data of the problem, from the effective scene (scene.toml) of the run."),))
