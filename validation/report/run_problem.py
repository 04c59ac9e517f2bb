"""The problem statement of a run's report: gap, materials, layer law (with its w(p) plot), load, units.

Everything is read from the effective scene (``scene.toml``) and the run's ``result.json``: the
layer drawn is the one the solver used (``result["layer"]["parameters"]``, rebuilt with
:func:`bem.layers.from_dict`), with the paper's relative parameters (``lam_over_cnn``,
``alpha_a``, ...) shown next to the values they resolved to.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping

from .results import display_unit, report_unit
from .sections import Figure, Section, Table, fmt

__all__ = ["problem_statement", "rebuild_layer", "method_text"]

log = logging.getLogger(__name__)

_GAP_TEXT = {
    "paraboloid": "paraboloid h = r^2 / (2 R) (two spheres of effective radius R, 1/R = 1/R1 + 1/R2)",
    "elliptic_paraboloid": "elliptic paraboloid h = x^2 / (2 Rx) + y^2 / (2 Ry)",
    "crowned_roller": "crowned roller: a cylinder of effective radius R and length l along x, with an end crown",
    "flat_punch": "flat punch: a flat of radius a whose edge is rounded with the radius edge_radius",
    "table": "gap tabulated on a grid, interpolated",
    "measured": "measured surface read from a file, interpolated onto the lattice",
    "callable": "gap given by a Python function",
}
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
_METHOD_TEXT = {
    "newton": "direct minimisation of the generalised Kalker functional with the layer's energy",
    "augmented_gap": "the paper's fixed-point iteration on the gap augmented by the layer closure",
    "variable_compliance": "the paper's fixed-point iteration with a pressure-dependent layer compliance",
}
_GAP_UNITS = {"R": "length", "Rx": "length", "Ry": "length", "length": "length", "a": "length",
              "edge_radius": "length", "crown_radius": "length", "design_force": "force", "A": "length",
              "scale": "length"}
_PAPER_ROWS = (("c_nn", "C_nn = c w_t(0,0) / (pi E*), diagonal influence coefficient (eq. 6)", "compliance"),
               ("lam_over_cnn", "lam / C_nn (paper parameter)", "-"),
               ("lam_ref", "compliance of the linear reference layer lam_over_cnn C_nn", "compliance"),
               ("p_max_lambda", "p_max^lambda: peak with the linear layer lam (reference solve)", "pressure"),
               ("alpha_a", "alpha_a = p_cr / p_max^lambda (paper parameter)", "-"),
               ("alpha_c", "alpha_c = arctan(lam2 / lam1) (paper parameter)", "rad"),
               ("alpha_b", "alpha_b = p_max / p_max^lambda", "-"))


def rebuild_layer(res):
    """The :class:`bem.layers.Layer` the run used, or ``None`` (smooth bodies or not rebuildable)."""
    from bem.layers import from_dict

    params = (res.get("layer") or {}).get("parameters")
    if not isinstance(params, Mapping):
        params = res.section("layer") if res.section("layer").get("law") not in (None, "none") else None
    if not params:
        return None
    try:
        return from_dict(dict(params))
    except (ValueError, TypeError, KeyError) as exc:
        log.warning("the layer of the run cannot be rebuilt (%s): no w(p) plot", exc)
        return None


def method_text(method, law, *, short=False):
    """What the BEM solved, in words: the QP for quadratic problems, else the named method."""
    from .style import method_label

    if method in ("newton", "kalker") and law in (None, "none", "linear"):
        if short:
            return "Kalker QP (eq. 11, projected conjugate gradients)"
        return ("Kalker's quadratic programme (eq. 11), solved by projected conjugate gradients "
                "(the functional is quadratic without a layer or with a linear one)")
    if short or method not in _METHOD_TEXT:
        return method_label(method)
    return f"{method_label(method)}: {_METHOD_TEXT[method]}"


def _param_unit(law, key, params, units):
    if key in ("p_cr", "p_star"):
        return units.of("pressure")
    if key in ("lam", "lam1", "lam2"):
        if not (units.length and units.pressure):
            return "-"
        power = {"root": "0.5", "power": fmt(params.get("s", 1.0))}.get(law)
        return f"{units.length}/{units.pressure}" + (f"^{power}" if power else "")
    return "-"


def _layer_rows(res, layer):
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
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            rows.append((f"layer {key}", fmt(value), _param_unit(law, key, params, u)))
        elif isinstance(value, Mapping):
            rows.append((f"layer {key}", _LAW_TEXT.get(value.get("law"), str(value.get("law", "?"))), "-"))
    for key, text, kind in _PAPER_ROWS:
        value = info.get(key)
        if key == "alpha_b" and key not in res.section("layer"):
            continue  # an output unless the scene gave it (then the layer was fitted to it)
        if key == "lam_ref" and value == params.get("lam"):
            continue
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            rows.append((text, fmt(value), u.of(kind) if kind not in ("-", "rad") else kind))
    return rows


def _gap_rows(res):
    gap = res.section("gap") or {"type": "not recorded"}
    kind = str(gap.get("type", "?"))
    rows = [("gap h(x, y)", _GAP_TEXT.get(kind, kind), "-")]

    def unit(key):
        if kind == "measured" and key in ("spacing", "nodata"):  # in the file's length unit
            file_unit = gap.get("length_unit")
            return file_unit if isinstance(file_unit, str) else res.units.of("length")
        return res.units.of(_GAP_UNITS.get(key, "-"))

    for key, value in gap.items():
        if key == "type":
            continue
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            rows.append((f"gap {key}", fmt(value), unit(key)))
        elif isinstance(value, str):
            rows.append((f"gap {key}", value, "-"))
        elif isinstance(value, list) and len(value) == 2 and all(isinstance(v, (int, float)) for v in value):
            rows.append((f"gap {key}", ", ".join(fmt(v) for v in value), unit(key)))
        elif isinstance(value, list):
            rows.append((f"gap {key}", f"table of {len(value)} values", "-"))
    return rows


def _material_rows(res):
    bodies = res.section("bodies")
    u = res.units
    rows = []
    for key, label in (("E1", "Young's modulus E1 (body 1)"), ("nu1", "Poisson's ratio nu1 (body 1)"),
                       ("E2", "Young's modulus E2 (body 2)"), ("nu2", "Poisson's ratio nu2 (body 2)")):
        if key in bodies:
            rows.append((label, fmt(float(bodies[key])), "-" if key.startswith("nu") else u.of("pressure")))
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
    return []


class _Scaled:
    """A layer drawn in display units: ``w(p) = layer.w(p * pf) / wf``."""

    def __init__(self, layer, pf, wf):
        self.layer, self.pf, self.wf, self.law = layer, pf, wf, layer.law

    def w(self, p):
        return self.layer.w(p * self.pf) / self.wf


def _layer_figure(res, layer, work):
    """The w(p) plot of the layer over ``0 .. 1.25 max(p_max, p_cr, ...)`` with the BEM peak marked."""
    import numpy as np

    from .figures_profiles import plot_layer_laws

    params = layer.to_dict()
    p_top = 1.25 * max(float(res.data.get("p_max") or 0.0), *(float(params.get(k) or 0.0)
                                                             for k in ("p_cr", "p_star")))
    if p_top <= 0:
        return None
    w_top = float(np.max(layer.w(np.linspace(0.0, p_top, 200))))
    u = res.units
    p_unit, pf = report_unit(u.pressure)
    w_unit, wf = display_unit(u.length, w_top)  # closures of a few micrometres: the readable prefix
    marks = [(rf"$p_{{max}}$ (BEM) = {fmt(res.data['p_max'] / pf, 3)} {p_unit}".rstrip(), res.data["p_max"] / pf)]
    for key, name in (("p_cr", r"$p_{cr}$"), ("p_star", r"$p^*$")):
        if params.get(key):
            marks.append((f"{name} = {fmt(params[key] / pf, 3)} {p_unit}".rstrip(), params[key] / pf))
    path = plot_layer_laws([(params["law"].replace("_", "-"), _Scaled(layer, pf, wf))], work / "layer_law.png",
                           p_max=p_top / pf, p_unit=p_unit, w_unit=w_unit, marks=marks,
                           title="interface layer law: closure $w(p)$ under the pressure $p$")
    return Figure(path, f"The layer law w(p) used by the solver ({_LAW_TEXT.get(params['law'], params['law'])}), "
                        "rebuilt from the run's result with bem.layers.from_dict and evaluated at 200 pressures "
                        "from 0 to 1.25 times the largest of the computed peak pressure and the law's kink "
                        "pressures (marked).")


def problem_statement(res, work):
    """The problem-statement :class:`Section` of a run (figures written to ``work``)."""
    meta = res.section("scene")
    text = []
    if meta.get("description"):
        text.append(str(meta["description"]))
    layer = rebuild_layer(res)
    law = getattr(layer, "law", None)
    text.append("Frictionless normal contact of two elastic half-spaces whose surfaces are separated by the "
                "initial gap h(x, y)" + (", with an interface layer between them whose closure w(p) depends "
                                         "on the contact pressure p." if law else " (no interface layer).")
                + f" Solved by the BEM: {method_text(res.data.get('method'), law)}.")
    if res.data.get("overrides"):
        text.append("Scene overrides of this run: " + ", ".join(map(str, res.data["overrides"])) + ".")
    u = res.units
    text.append(f"Units: {u.label}" + (f" - lengths in {u.length}, pressures and moduli in {u.pressure}, forces in "
                                       f"{u.force}, areas in {u.of('area')}." if u.known else "."))
    rows = _gap_rows(res) + _material_rows(res) + _layer_rows(res, layer) + _load_rows(res)
    items = [Table(("quantity", "value", "unit"), tuple(rows),
                   caption="Input data of the problem, from the effective scene (scene.toml) of the run.")]
    if layer is not None:
        fig = _layer_figure(res, layer, work)
        if fig is not None:
            items.append(fig)
    return Section("Problem statement", kind="problem", text=tuple(text), items=tuple(items))
