"""Section of the coating study (``coating_winkler.json``, :mod:`validation.studies.coating_winkler`) in the
studies report."""

from __future__ import annotations

from ..render import Figure, Section, Table

__all__ = ["coating_winkler_sections", "rule_table", "errors_table", "problem_sentence"]


def problem_sentence(s):
    """The coating studies' problem in words, from their settings ``s`` (SI units)."""
    return (f"An elastic sphere (R = {s.get('R')} m, the substrate's material E_s = {s.get('E_s'):g} Pa, nu_s = "
            f"{s.get('nu_s')}) on a flat with a bonded coating, under the force of the Hertz radius a_H = "
            f"{s.get('a_H')} m of the uncoated pair")


def rule_table(data, model="oed", level=0.05):
    """``(headings, rows)``: per ``nu_c`` and ``E_c/E_s``, the smallest ``a_H/t`` from which the layer
    stays within ``level`` (:func:`validation.studies.coating_winkler.rule`)."""
    from validation.studies.coating_winkler import rule

    found = rule(data["rows"], model, level)
    ratios = sorted({float(k) for per in found.values() for k in per})
    heads = ("nu_c", *(f"E_c/E_s = {r:g}" for r in ratios))
    rows = [(nu, *("never" if per[f"{r:g}"] is None else f"a_H/t >= {per[f'{r:g}']:g}" for r in ratios))
            for nu, per in found.items()]
    return heads, rows


def errors_table(data):
    """``(headings, rows)``: every case's truth and the worst errors of both layers."""
    heads = ("a_H/t", "E_c/E_s", "nu_c", "p_max [Pa]", "radius [m]", "approach [m]", "lam_best/lam_oed",
             "oedometric: worst", "oedometric: RMS p", "best: worst", "best: RMS p")
    rows = [(r["a_over_t"], r["modulus_ratio"], r["nu_c"], f"{r['p_max']:.4g}", f"{r['radius']:.4g}",
             f"{r['approach']:.4g}", f"{r['lam_best'] / r['lam_oed']:.3g}", f"{r['oed_worst']:.2%}",
             f"{r['oed_rms']:.2%}", f"{r['best_worst']:.2%}", f"{r['best_rms']:.2%}") for r in data["rows"]]
    return heads, rows


def coating_winkler_sections(data, work=None):
    """The map (with a figures folder ``work``), the rule tables, the checks of the truth and every case."""
    s = data.get("settings", {})
    text = [f"{problem_sentence(s)}, against the same sphere on the bare substrate carrying the "
            "Winkler layer w = lam p: the oedometric lam = t (1 + nu_c)(1 - 2 nu_c) / ((1 - nu_c) E_c) and the "
            "best lam >= 0 (least RMS pressure error). Errors relative to the coated solution "
            f"(truth: {data.get('truth')}); worst = the largest of p_max, contact radius, approach and RMS of p(r)."]
    items = []
    if work is not None and data.get("rows"):
        from ..figures.coating_winkler import plot_coating_map

        items.append(Figure(plot_coating_map(data, work),
                            "Worst relative error of the best and of the oedometric Winkler layer per case, in "
                            "the bands 1 %, 5 %, 20 %; one column per Poisson's ratio of the coating."))
    for model, name in (("oed", "oedometric layer"), ("best", "best layer")):
        heads, rows = rule_table(data, model)
        items.append(Table(heads, tuple(rows), caption=f"The {name} within 5 %: from which a_H/t on (at every "
                                                       "larger a_H/t of the grid)."))
    ref = data.get("refinement")
    if ref:
        items.append(Table(("rings", "p_max [Pa]", "radius [m]", "approach [m]"),
                           tuple((lv["rings"], lv["p_max"], lv["radius"], lv["approach"]) for lv in ref["levels"]),
                           caption="The ring truth under refinement, case (a_H/t, E_c/E_s, nu_c) = "
                                   f"{tuple(ref['case'])}: relative changes between levels, p_max "
                                   + ", ".join(f"{c:.1e}" for c in ref["change"]["p_max"]) + "; radius "
                                   + ", ".join(f"{c:.1e}" for c in ref["change"]["radius"]) + "; approach "
                                   + ", ".join(f"{c:.1e}" for c in ref["change"]["approach"]) + "."))
    if data.get("fem_check"):
        items.append(Table(("a_H/t", "E_c/E_s", "nu_c", "FEM elements across a", "converged", "p_max", "radius",
                            "approach", "RMS p", "time [s]"),
                           tuple((r["a_over_t"], r["modulus_ratio"], r["nu_c"], r["elements"], r["converged"],
                                  f"{r['vs_rings_p_max']:+.2e}", f"{r['vs_rings_radius']:+.2e}",
                                  f"{r['vs_rings_approach']:+.2e}", f"{r['vs_rings_rms']:.2e}",
                                  f"{r['wall_time_s']:.1f}") for r in data["fem_check"]),
                           caption="The FEM reference with the coating meshed against the ring truth "
                                   "(relative differences; a FEM run that reports no convergence is listed "
                                   "with its last iterate)."))
    heads, rows = errors_table(data)
    items.append(Table(heads, tuple(rows), caption="Every case: the coated solution and the layers' errors."))
    return [Section("Coatings: when a linear Winkler layer stands for a coating", "validation", text, tuple(items))]
