"""Section of the study of the coated BEM against the FEM (``coating_fem.json``,
:mod:`validation.studies.coating_fem`) in the studies report."""

from __future__ import annotations

from ..render import Figure, Section, Table
from .coating_winkler import problem_sentence

__all__ = ["after_table", "coating_fem_sections", "comparison_table", "pressure_table", "refined_table", "stress_table"]


def _order(x):
    return "-" if x is None else f"{x:.2f}"


def _case(r):
    return (r["a_over_t"], r["modulus_ratio"], r["nu_c"], "root" if r["layer"] else "-")


def comparison_table(data):
    """``(headings, rows)``: per case and quantity, both methods' extrapolated values, orders, differences."""
    heads = ("a_H/t", "E_c/E_s", "nu_c", "layer", "quantity", "BEM extrapolated", "BEM order", "FEM extrapolated",
             "FEM order", "diff extrapolated", "diff finest")
    rows = []
    for r in data["rows"]:
        for q in ("p_max", "radius", "approach"):
            b, f, d = r["bem_x"][q], r["fem_x"][q], r["diff"][q]
            rows.append((*_case(r), q, "-" if b["extrapolated"] is None else f"{b['extrapolated']:.6g}",
                         _order(b["order"]), "-" if f["extrapolated"] is None else f"{f['extrapolated']:.6g}",
                         _order(f["order"]), f"{d['extrapolated']:+.3%}", f"{d['finest']:+.3%}"))
    return heads, rows


def _pct(x, digits=2):
    return "-" if x is None else f"{x:.{digits}%}"


def pressure_table(data):
    """``(headings, rows)``: per case, the RMS of p(r): the linear measure at the finest levels, the edge-aware
    one per paired level with its order and extrapolation, its interior and edge-band parts, the run time."""
    heads = ("a_H/t", "E_c/E_s", "nu_c", "layer", "converged", "RMS p linear, finest", "RMS p edge-aware per level",
             "order", "extrapolated", "interior, finest", "edge band, finest", "time [s]")
    rows = []
    for r in data["rows"]:
        pr = r.get("pressure")
        if pr is None:
            rows.append((*_case(r), r["converged"], _pct(r["rms"]), "-", "-", "-", "-", "-", f"{r['wall_time_s']:.0f}"))
            continue
        t = pr["total"]
        rows.append((*_case(r), r["converged"], _pct(r["rms"]), " / ".join(_pct(v["total"]) for v in pr["levels"]),
                     _order(t["order"]), _pct(t["extrapolated"]), _pct(pr["interior"]["finest"]),
                     _pct(pr["edge"]["finest"]), f"{r['wall_time_s']:.0f}"))
    return heads, rows


def stress_table(data):
    """``(headings, rows)``: per case, the interface stresses (finest levels) and the per-level scalars'
    orders (BEM / FEM) and differences of their extrapolated values."""
    heads = ("a_H/t", "E_c/E_s", "nu_c", "layer", "sigma_zz / sigma_rz at bond, of max traction",
             "of own max", "projected, of own max", "FEM sides", "von Mises coating", "von Mises substrate",
             "sigma_zz axis: orders, diff", "max sigma_rz: orders, diff")
    rows = []
    for r in data["rows"]:
        st = r.get("stresses") or {}
        cell = (lambda k: f"{st[k]:+.2%}" if st.get(k) is not None else "-")  # noqa: E731
        pair = (lambda a, b: f"{_pct(st.get(a))} / {_pct(st.get(b))}")  # noqa: E731
        lv = st.get("levels") or {}

        def scalar(q, lv=lv):
            if not lv:
                return "-"
            d = lv["diff"][q]
            return (f"{_order(lv['bem_x'][q]['order'])} / {_order(lv['fem_x'][q]['order'])}, "
                    + ("-" if d is None else f"{d:+.2%}"))

        rows.append((*_case(r), pair("szz", "srz"), pair("szz_own", "srz_own"),
                     pair("szz_projected", "srz_projected"), _pct(st.get("fem_sides")), cell("vm_coating"),
                     cell("vm_substrate"), scalar("szz_axis"), scalar("srz_max")))
    return heads, rows


def refined_table(data):
    """``(headings, rows)``: the refined cases' RMS of p(r), every BEM level against every FEM level."""
    heads = ("a_H/t", "E_c/E_s", "nu_c", "a_H/step (BEM)", "elements across a (FEM)", "RMS p linear",
             "RMS p edge-aware", "interior", "edge band")
    return heads, [(f"{c['a_over_t']:g}", f"{c['modulus_ratio']:g}", f"{c['nu_c']:g}", r["bem"], r["fem"],
                    _pct(r["linear"]), _pct(r["total"]), _pct(r["interior"]), _pct(r["edge"]))
                   for c in data["refined"] for r in c["rows"]]


def after_table(data):
    """``(headings, rows)``: the refined cases' scalars after refinement: per quantity, each method's order and
    extrapolated value from its last three levels (one beyond the study's finest) and their differences."""
    heads = ("a_H/t", "E_c/E_s", "nu_c", "quantity", "BEM levels", "BEM order", "FEM levels", "FEM order",
             "diff extrapolated", "diff finest")
    rows = []
    for c in data["refined"]:
        after = c.get("after")
        if after is None:
            continue
        for q in ("p_max", "radius", "approach"):
            b, f, d = after["bem_x"][q], after["fem_x"][q], after["diff"][q]
            rows.append((f"{c['a_over_t']:g}", f"{c['modulus_ratio']:g}", f"{c['nu_c']:g}", q,
                         " / ".join(f"{x[q]:.6g}" for x in c["bem"]), _order(b["order"]),
                         " / ".join(f"{x[q]:.6g}" for x in c["fem"]), _order(f["order"]),
                         f"{d['extrapolated']:+.3%}", f"{d['finest']:+.3%}"))
    return heads, rows


def coating_fem_sections(data, work=None):
    """The figure (with a figures folder ``work``) and the tables: per quantity, p(r) per level, the refined
    cases, the interface stresses."""
    s = data.get("settings", {})
    band = (f", each solved again with its interface elements {s['fem_refine_edge']} times smaller within one "
            "element of its contact edge" if s.get("fem_refine_edge") else "")
    across = (f" and {s['fem_across']} elements across the coating at the coarsest level, in proportion above it"
              if s.get("fem_across") else "")
    text = [f"{problem_sentence(s)}; the BEM on lattices a_H/step = {s.get('bem_levels')}, the FEM with "
            f"{s.get('fem_levels')} elements across the contact radius{across}{band}. Orders from the last three "
            "levels; extrapolated values by Richardson with "
            "the observed order where it lies in [0.5, 6] and the differences keep their sign (else the finest "
            "value, '-'). diff = BEM / FEM - 1. RMS of p(r): every BEM node against the FEM's p(r) at its "
            "radius, relative; 'linear': the FEM's p linear between its nodes (finest levels); 'edge-aware': "
            "p^2 linear between the FEM's loaded nodes and on to zero at its contact radius (with a layer, "
            "whose pressure has no square-root edge: linear), per paired level "
            "(coarsest first), split into the nodes inside 0.9 FEM contact radii and the edge band beyond. "
            "Stresses: the BEM's ring-averaged pressure through the coated half-space's Hankel fields against "
            "the FEM's one-sided nodal stresses (each material's own elements), on the bond within 1.5 "
            "max(a, t) (substrate side) relative to the FEM's largest traction magnitude there and to each "
            "component's own largest value; 'projected': the FEM's continuous projection within 1.5 a; "
            "'FEM sides': the FEM's coating side against its substrate side (of the largest traction); von "
            "Mises at the FEM's maximum node per material, the bond included on each side. Orders of "
            "sigma_zz on the axis at the bond and of the largest |sigma_rz| there from each method's levels."]
    items = []
    if work is not None and data.get("rows"):
        from ..figures.coating_fem import plot_coating_fem

        items.append(Figure(plot_coating_fem(data, work),
                            "Top: BEM-vs-FEM difference of the extrapolated p_max, contact radius and approach, and "
                            "the RMS of p(r) at the finest levels, per case. Bottom: observed orders."))
    heads, rows = comparison_table(data)
    items.append(Table(heads, tuple(rows), caption="Per case and quantity: extrapolated values, observed orders "
                                                   "and BEM-vs-FEM differences."))
    heads, rows = pressure_table(data)
    items.append(Table(heads, tuple(rows), caption="Per case: RMS of the BEM nodes' pressure against the FEM's "
                                                   "p(r) per paired level, orders, parts, run time."))
    if data.get("refined"):
        heads, rows = refined_table(data)
        items.append(Table(heads, tuple(rows), caption="The cases whose edge-aware RMS of p(r) at the finest "
                           "levels, or whose difference of an extrapolated p_max, radius or approach, is above "
                           f"{data['settings'].get('refine_above', 0.005):.2%}, or with a level that did not "
                           "converge, one level finer in each method: RMS of p(r) of every BEM level against every "
                           "FEM level."))
        heads, rows = after_table(data)
        if rows:
            items.append(Table(heads, tuple(rows), caption="The same cases' p_max, contact radius and approach "
                               "after refinement: the two finer levels of each method, the orders and extrapolated "
                               "values from each method's last three levels, and the differences."))
    heads, rows = stress_table(data)
    items.append(Table(heads, tuple(rows), caption="Per case: interface stresses of the BEM against the FEM's "
                                                   "one-sided recovery (finest levels) and the per-level orders."))
    return [Section("Coatings: the coated BEM against the FEM", "validation", text, tuple(items))]
