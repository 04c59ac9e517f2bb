"""The figure of the coated BEM against the FEM (:mod:`validation.studies.coating_fem`): per case, the
BEM-vs-FEM differences of the extrapolated values and the observed convergence orders of both methods."""

from __future__ import annotations

from pathlib import Path

from ..render.style import new_figure, save_figure

__all__ = ["case_label", "plot_coating_fem"]

#: marker per compared quantity
_MARKERS = {"p_max": "o", "radius": "s", "approach": "^"}


def case_label(row):
    """``a/t, Ec/Es, nu_c`` of a row, with ``+root`` for the layered case."""
    return f"{row['a_over_t']:g}, {row['modulus_ratio']:g}, {row['nu_c']:g}" + (" +root" if row["layer"] else "")


def plot_coating_fem(data, out, *, name="coating_fem.png"):
    """The figure from ``data`` (``coating_fem.json``) as ``out/name``; returns the file."""
    rows = data["rows"]
    x = list(range(len(rows)))
    path = Path(out) / name
    path.parent.mkdir(parents=True, exist_ok=True)
    with new_figure((max(7.0, 0.42 * len(rows) + 2.0), 7.6), nrows=2, sharex=True) as (fig, (top, bottom)):
        floor = 1e-7
        for q, m in _MARKERS.items():
            top.semilogy(x, [max(abs(r["diff"][q]["extrapolated"]), floor) for r in rows], m, ls="none", label=q)
        top.semilogy(x, [max(r["rms"], floor) for r in rows], "x", ls="none", color="0.3",
                     label="RMS of p(r), finest levels")
        edge_aware = [(i, r["pressure"]["total"]["finest"]) for i, r in zip(x, rows) if r.get("pressure")]
        if edge_aware:
            top.semilogy([i for i, _ in edge_aware], [max(v, floor) for _, v in edge_aware], "+", ls="none",
                         color="tab:purple", label="RMS of p(r), edge-aware, finest levels")
        where = {(r["a_over_t"], r["modulus_ratio"], r["nu_c"]): i for i, r in zip(x, rows) if not r["layer"]}
        finer = [(where[k], c["rows"][-1]["total"]) for c in data.get("refined") or ()
                 if (k := (c["a_over_t"], c["modulus_ratio"], c["nu_c"])) in where]
        if finer:
            top.semilogy([i for i, _ in finer], [max(v, floor) for _, v in finer], "*", ls="none", ms=9,
                         color="tab:purple", label="the same, one level finer in both")
        after = [(where[k], max(abs(d["extrapolated"]) for d in c["after"]["diff"].values()))
                 for c in data.get("refined") or () if c.get("after")
                 and (k := (c["a_over_t"], c["modulus_ratio"], c["nu_c"])) in where]
        if after:
            top.semilogy([i for i, _ in after], [max(v, floor) for _, v in after], "D", ls="none", mfc="none",
                         color="tab:green", label="worst of p_max, radius, approach, one level finer in both")
        top.axhline(5e-3, color="tab:red", lw=0.8, ls="--", label="0.5 %")
        top.set_ylim(floor / 2, 1.0)
        top.set_ylabel("|BEM / FEM - 1|, extrapolated")
        top.legend(fontsize="small", ncols=3, loc="upper left")
        for method, colour in (("bem", "tab:blue"), ("fem", "tab:orange")):
            for q, m in _MARKERS.items():
                orders = [r[f"{method}_x"][q]["order"] for r in rows]
                bottom.plot([i for i, o in zip(x, orders) if o is not None], [o for o in orders if o is not None],
                            m, ls="none", color=colour, mfc="none" if method == "fem" else colour,
                            label=f"{method.upper()} {q}")
        bottom.axhline(2.0, color="0.5", lw=0.8, ls=":")
        bottom.set_ylim(-2.0, 7.0)
        bottom.set_ylabel("observed order (last three levels)")
        bottom.legend(fontsize="x-small", ncols=3, loc="upper left")
        bottom.set_xticks(x, [case_label(r) for r in rows], rotation=70, fontsize="x-small")
        bottom.set_xlabel("case: a_H/t, E_c/E_s, nu_c")
        fig.suptitle("Sphere on a coated flat: the coated BEM against the FEM with the coating meshed",
                     fontsize="medium")
        return save_figure(fig, path)
