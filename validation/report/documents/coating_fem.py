"""Section of the study of the coated BEM against the FEM (``coating_fem.json``,
:mod:`validation.studies.coating_fem`) in the studies report."""

from __future__ import annotations

from ..render import Figure, Section, Table

__all__ = ["coating_fem_sections", "comparison_table", "levels_table"]


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


def levels_table(data):
    """``(headings, rows)``: per case, RMS of p(r), the interface stresses and the run time."""
    heads = ("a_H/t", "E_c/E_s", "nu_c", "layer", "converged", "RMS p", "sigma_zz at bond", "sigma_rz at bond",
             "von Mises coating", "von Mises substrate", "time [s]")
    rows = []
    for r in data["rows"]:
        st = r.get("stresses") or {}
        cell = (lambda k: f"{st[k]:+.2%}" if st.get(k) is not None else "-")  # noqa: E731
        rows.append((*_case(r), r["converged"], f"{r['rms']:.2%}", cell("szz"), cell("srz"), cell("vm_coating"),
                     cell("vm_substrate"), f"{r['wall_time_s']:.0f}"))
    return heads, rows


def coating_fem_sections(data, work=None):
    """The figure (with a figures folder ``work``) and the two tables."""
    s = data.get("settings", {})
    text = [f"An elastic sphere (R = {s.get('R')} m, E_s = {s.get('E_s'):g} Pa, nu_s = {s.get('nu_s')}) on a flat "
            f"with a bonded coating, under the force of the Hertz radius a_H = {s.get('a_H')} m of the uncoated pair; "
            f"the BEM on lattices a_H/step = {s.get('bem_levels')}, the FEM with {s.get('fem_levels')} elements "
            "across the contact radius. Orders from the last three levels; extrapolated values by Richardson with "
            "the observed order where it lies in [0.5, 6] and the differences keep their sign (else the finest "
            "value, '-'). diff = BEM / FEM - 1. Stresses: the BEM's ring-averaged pressure through the coated "
            "half-space's Hankel fields against the FEM's nodal stresses (relative to the FEM's largest value at "
            "the bond; von Mises at the FEM's maximum node per material)."]
    items = []
    if work is not None and data.get("rows"):
        from ..figures.coating_fem import plot_coating_fem

        items.append(Figure(plot_coating_fem(data, work),
                            "Top: BEM-vs-FEM difference of the extrapolated p_max, contact radius and approach, and "
                            "the RMS of p(r) at the finest levels, per case. Bottom: observed orders."))
    heads, rows = comparison_table(data)
    items.append(Table(heads, tuple(rows), caption="Per case and quantity: extrapolated values, observed orders "
                                                   "and BEM-vs-FEM differences."))
    heads, rows = levels_table(data)
    items.append(Table(heads, tuple(rows), caption="Per case: RMS of the BEM nodes' pressure against the FEM's "
                                                   "p(r) (finest levels), interface stresses, run time."))
    return [Section("Coatings: the coated BEM against the FEM", "validation", text, tuple(items))]
