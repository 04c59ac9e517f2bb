"""The problem statement of a run's report (the section ``scene``): gap, materials, layer law, load, units.

Everything is read from the effective scene (``scene.toml``) and the run's ``result.json``: the
layer is the one the solver used (``result["layer"]["parameters"]``), with the paper's relative
parameters (``lam_over_cnn``, ``alpha_a``, ...) shown next to the values they resolved to.
"""

from __future__ import annotations

from collections.abc import Mapping

from bem.gaps import GAPS

from ...scene.rough import GAP_UNITS as ROUGH_GAP_UNITS
from ..render.content import Section, Table, fmt
from ..render.style import method_text
from .results import is_number

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


def _param_unit(law, key, params, units):
    if key in ("p_cr", "p_star"):
        return units.of("pressure")
    if key in ("lam", "lam1", "lam2"):
        if not (units.length and units.pressure):
            return "-"
        power = {"root": "0.5", "power": fmt(params.get("s", 1.0))}.get(law)
        return f"{units.length}/{units.pressure}" + (f"^{power}" if power else "")
    return "-"


def _layer_rows(res):
    """Rows of the layer: its law, the parameters used, and the paper's relative ones."""
    info = res.get("layer") or {}
    params = info.get("parameters") if isinstance(info.get("parameters"), Mapping) else {}
    law = params.get("law") or info.get("law") or res.section("layer").get("law")
    if law in (None, "none"):
        return [("interface layer", "none (smooth bodies, w = 0)", "-")]
    u = res.units
    rows = [("interface layer", _LAW_TEXT.get(law, law), "-")]
    for key, value in params.items():
        if key == "law":
            continue
        if isinstance(value, list) and law == "tabulated":
            unit = u.of("pressure" if key == "p" else "length")
            rows.append((f"layer {key} (table)", f"{len(value)} points, {fmt(min(value))} to {fmt(max(value))}", unit))
        elif is_number(value):
            rows.append((f"layer {key}", fmt(value), _param_unit(law, key, params, u)))
        elif isinstance(value, Mapping):
            rows.append((f"layer {key}", _LAW_TEXT.get(value.get("law"), str(value.get("law", "?"))), "-"))
    for key, text, kind in _PAPER_ROWS:
        value = info.get(key)
        if key == "alpha_b" and key not in res.section("layer"):
            continue  # an output unless the scene gave it (then the layer was fitted to it)
        if key == "lam_ref" and value == params.get("lam"):
            continue
        if is_number(value):
            rows.append((text, fmt(value), u.of(kind) if kind not in ("-", "rad") else kind))
    return rows


def _gap_rows(res):
    gap = res.section("gap") or {"type": "not recorded"}
    kind = str(gap.get("type", "?"))
    shape = GAPS.get(kind)  # the shape says what it is and the kind of each parameter
    rows = [("gap h(x, y)", _MEASURED if kind == "measured" else shape.describe() if shape else kind, "-")]

    def unit(key):
        if kind == "measured" and key in ("spacing", "nodata"):  # in the file's length unit
            file_unit = gap.get("length_unit")
            return file_unit if isinstance(file_unit, str) else res.units.of("length")
        return res.units.of(shape.units.get(key, "-") if shape else ROUGH_GAP_UNITS.get(key, "-"))

    for key, value in gap.items():
        if key == "type":
            continue
        if is_number(value):
            rows.append((f"gap {key}", fmt(value), unit(key)))
        elif isinstance(value, str):
            rows.append((f"gap {key}", value, "-"))
        elif isinstance(value, list) and len(value) == 2 and all(isinstance(v, (int, float)) for v in value):
            rows.append((f"gap {key}", ", ".join(fmt(v) for v in value), unit(key)))
        elif isinstance(value, list):
            rows.append((f"gap {key}", f"table of {len(value)} values", "-"))
    return rows


def _material_rows(res):
    bodies, u = res.section("bodies"), res.units
    rows = [(label, fmt(float(bodies[key])), "-" if key.startswith("nu") else u.of("pressure"))
            for key, label in _MATERIALS if key in bodies]
    e_star = res.bem.get("E_star", bodies.get("E_star"))
    if e_star is not None:
        rows.append(("effective modulus E* = 1 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2)", fmt(float(e_star)),
                     u.of("pressure")))
    return rows


def _load_rows(res):
    load = res.section("load")
    if "force" in load:
        return [("load: total force P (force control)", fmt(float(load["force"])), res.units.of("force"))]
    if "approach" in load:
        return [("load: approach delta (approach control)", fmt(float(load["approach"])), res.units.of("length"))]
    if "mean_pressure" in load:  # a periodic cell
        return [("load: mean pressure over the cell", fmt(float(load["mean_pressure"])), res.units.of("pressure"))]
    return []


def scene_section(res, work):
    """The problem statement: the effective scene's inputs (``work``: unused, no figure)."""
    meta, law, u = res.section("scene"), getattr(res.layer, "law", None), res.units
    text = [str(meta["description"])] if meta.get("description") else []
    text.append("Frictionless normal contact of two elastic half-spaces whose surfaces are separated by the "
                "initial gap h(x, y)" + (", with an interface layer between them whose closure w(p) depends "
                                         "on the contact pressure p." if law else " (no interface layer).")
                + f" Solved by the BEM: {method_text(res.data.get('method'), law)}.")
    if res.data.get("overrides"):
        text.append("Scene overrides of this run: " + ", ".join(map(str, res.data["overrides"])) + ".")
    text.append(f"Units: {u.label}" + (f" - lengths in {u.length}, pressures and moduli in {u.pressure}, forces in "
                                       f"{u.force}, areas in {u.of('area')}." if u.known else "."))
    rows = _gap_rows(res) + _material_rows(res) + _layer_rows(res) + _load_rows(res)
    return Section("Problem statement", kind="problem", text=tuple(text), items=(
        Table(("quantity", "value", "unit"), tuple(rows),
              caption="Input data of the problem, from the effective scene (scene.toml) of the run."),))
