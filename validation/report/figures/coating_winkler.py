"""The map of the coating study (:mod:`validation.studies.coating_winkler`): where a linear Winkler layer
stands for a coating.

One panel per Poisson's ratio of the coating (columns) and per layer (rows: the best layer, the
oedometric one), over ``a_H/t`` and ``E_c/E_s`` on log axes; each cell is coloured by the layer's
worst relative error (the largest of ``p_max``, contact radius, approach and the RMS of ``p(r)``)
in the bands below 1 %, 5 %, 20 % and above, and carries the value in per cent.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..render.style import new_figure, save_figure

__all__ = ["BANDS", "plot_coating_map"]

#: the truths' names in the title
_TRUTHS = {"rings": "axisymmetric rings, coated half-space", "fem": "FEM reference, coating meshed"}

#: the error bands: (upper bound, colour, label)
BANDS = ((0.01, "#1a9850", "< 1 %"), (0.05, "#a6d96a", "1 - 5 %"), (0.2, "#fee08b", "5 - 20 %"),
         (np.inf, "#f46d43", "> 20 %"))


def _edges(values):
    """Cell edges of log-spaced centres: geometric midpoints, the ends mirrored."""
    v = np.log10(np.asarray(values, dtype=float))
    mid = 0.5 * (v[1:] + v[:-1])
    return 10.0 ** np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def _percent(v):
    """A cell's label: the error in per cent, 2 significant digits below 10 %, whole above, ``>999`` beyond."""
    return f"{100 * v:.2g}" if v < 0.1 else (f"{100 * v:.0f}" if v < 10 else ">999")


def _grid(rows, nu, key, xs, ys):
    grid = np.full((len(ys), len(xs)), np.nan)
    for r in rows:
        if r["nu_c"] == nu:
            grid[ys.index(r["modulus_ratio"]), xs.index(r["a_over_t"])] = r[key]
    return grid


def plot_coating_map(data, out, *, name="coating_winkler_map.png"):
    """The map from ``data`` (``coating_winkler.json``) as ``out/name``; returns the file."""
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    rows = data["rows"]
    xs = sorted({r["a_over_t"] for r in rows})
    ys = sorted({r["modulus_ratio"] for r in rows})
    nus = sorted({r["nu_c"] for r in rows})
    cmap = ListedColormap([c for _, c, _ in BANDS])
    norm = BoundaryNorm([0.0, *[b for b, _, _ in BANDS[:-1]], 1e9], cmap.N)
    xe, ye = _edges(xs), _edges(ys)
    path = Path(out) / name
    path.parent.mkdir(parents=True, exist_ok=True)
    with new_figure((3.6 * len(nus) + 0.6, 7.4), nrows=2, ncols=len(nus), sharex=True, sharey=True,
                    squeeze=False) as (fig, axes):
        for i, (model, label) in enumerate((("best", "best linear layer (lam fitted)"),
                                            ("oed", "oedometric layer"))):
            for j, nu in enumerate(nus):
                ax = axes[i, j]
                grid = _grid(rows, nu, f"{model}_worst", xs, ys)
                ax.pcolormesh(xe, ye, grid, cmap=cmap, norm=norm, shading="flat", edgecolors="white", linewidth=0.5)
                for (k, m), v in np.ndenumerate(grid):
                    if np.isfinite(v):
                        ax.text(xs[m], ys[k], _percent(v), ha="center", va="center", fontsize=6.5, color="black")
                ax.axhline(1.0, color="0.3", lw=0.8, ls=":")
                ax.set_xscale("log")
                ax.set_yscale("log")
                ax.grid(False)
                ax.set_title(f"{label}\nnu_c = {nu:g}", fontsize="medium")
                if i == 1:
                    ax.set_xlabel("a_H / t  (Hertz radius / coating thickness)")
                if j == 0:
                    ax.set_ylabel("E_c / E_s  (coating / substrate modulus)")
        handles = [Patch(color=c, label=lab) for _, c, lab in BANDS]
        fig.legend(handles=handles, loc="outside lower center", ncols=len(BANDS),
                   title="worst relative error of p_max, contact radius, approach, RMS of p(r) (numbers: per cent)",
                   fontsize="small", title_fontsize="small")
        truth = _TRUTHS.get(data.get("truth"), data.get("truth"))
        fig.suptitle("Sphere on a coated flat: a linear Winkler layer w = lam p on the bare substrate "
                     f"against the coated solution (truth: {truth})", fontsize="medium")
        return save_figure(fig, path)
