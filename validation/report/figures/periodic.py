"""Figures of a periodic cell (a rough surface on a flat, :mod:`validation.run.periodic`).

:func:`plot_cell_maps` draws the contact pressure and the contact spots over the cell;
:func:`plot_load_curves` the contact fraction and the mean gap against the mean pressure of a
sweep of the load. :func:`cell_maps` and :func:`sweep_curves` draw them from results.
Conventions: :mod:`validation.report.figures`.
"""

from __future__ import annotations

import numpy as np

from bem.checks import InputError

from ..render.content import Figure, Table, fmt
from ..render.style import new_figure, save_figure

__all__ = ["plot_cell_maps", "plot_load_curves", "cell_maps", "sweep_curves", "brick"]

_SPOT_MAPS = ("tab10", "Dark2")  # strong colours on white; spots cycle through them, shuffled


def brick(res, values):
    """Nodal values of a periodic result as a brick array ``(n_rows, n_cols)`` (``bem.cell``), or None."""
    cell = res.bem.cell
    values = np.asarray(values)
    if cell is None or values.size != cell[0] * cell[1]:
        return None
    return values.reshape(cell[1], cell[0])


def plot_cell_maps(p, labels, size, path, *, p_unit, l_unit, p_factor, l_factor, title=None):
    """The pressure and the contact spots over a periodic cell, side by side, to scale.

    Parameters
    ----------
    p : ndarray, shape (n_rows, n_cols)
        Nodal pressure [pressure], brick array (node ``(q, r)`` drawn as the cell ``q`` of row ``r``).
    labels : ndarray of int, same shape
        Spot of each node in contact, ``-1`` elsewhere (:func:`validation.run.periodic.contact_spots`).
    size : (float, float)
        The cell ``(Lx, Ly)`` [length].
    path : path-like
        The PNG written.
    p_unit, l_unit : str
        Display units; values are drawn as ``p / p_factor`` and ``x / l_factor``.
    """
    import matplotlib

    p, labels = np.asarray(p, float), np.asarray(labels)
    if p.ndim != 2 or p.shape != labels.shape:
        raise InputError(f"p of shape {p.shape} is not allowed: it must be a brick array of the labels' shape.")
    extent = (0.0, size[0] / l_factor, 0.0, size[1] / l_factor)
    n = int(labels.max(initial=-1)) + 1
    with new_figure((9.6, 4.3), ncols=2, title=title) as (fig, (ax_p, ax_s)):
        shown = np.ma.masked_where(p <= 0, p / p_factor)
        im = ax_p.imshow(shown, origin="lower", extent=extent, cmap="inferno_r", interpolation="nearest")
        ax_p.set_facecolor("white")
        fig.colorbar(im, ax=ax_p, shrink=0.85, label=f"contact pressure $p$ [{p_unit}]")
        ax_p.set_title("contact pressure (white: no contact)")
        rng = np.random.default_rng(0)
        palette = np.array([c for name in _SPOT_MAPS for c in matplotlib.colormaps[name].colors])
        colour = rng.permutation(max(n, 1)) % len(palette)
        rgb = np.ones((*labels.shape, 3))
        rgb[labels >= 0] = palette[colour[labels[labels >= 0]], :3]
        ax_s.imshow(rgb, origin="lower", extent=extent, interpolation="nearest")
        ax_s.set_title(f"{n} contact spots (a colour each)")
        for ax in (ax_p, ax_s):
            ax.set_aspect("equal")
            ax.grid(False)
            ax.spines[["top", "right"]].set_visible(True)  # the cell's edges
            ax.set_xlabel(f"$x$ [{l_unit}]")
            ax.set_ylabel(f"$y$ [{l_unit}]")
        return save_figure(fig, path)


def plot_load_curves(p_mean, fraction, gap, path, *, p_unit, l_unit, p_factor, l_factor, slope_modulus=None,
                     title=None):
    """Contact fraction against mean pressure (log-log) and mean pressure against mean gap (log-linear).

    Parameters
    ----------
    p_mean, fraction, gap : array_like
        Mean pressure [pressure], real contact fraction ``A/A0`` [-] and mean gap [length] per point.
    slope_modulus : float, optional
        ``E* h'_rms`` [pressure] (modulus times rms slope): draws the small-load line
        ``A/A0 = 2 pbar / (E* h'_rms)`` of Hyun et al. (PRE 70, 026117, 2004) for comparison.
    """
    p_mean, fraction, gap = (np.asarray(v, float) for v in (p_mean, fraction, gap))
    order = np.argsort(p_mean)
    p_mean, fraction, gap = p_mean[order], fraction[order], gap[order]
    if p_mean.size < 2 or not np.all(p_mean > 0):
        raise InputError(f"p_mean = {p_mean!r} is not allowed: it must hold at least two positive pressures.")
    with new_figure((9.6, 3.9), ncols=2, title=title) as (fig, (ax_a, ax_g)):
        ax_a.loglog(p_mean / p_factor, fraction, "o-", color="#1f77b4", label="BEM, periodic cell")
        if slope_modulus:
            ax_a.loglog(p_mean / p_factor, 2 * p_mean / slope_modulus, "--", color="0.4", lw=1.2,
                        label=r"$2\,\bar p\,/\,(E^* h'_{rms})$ (Hyun et al. 2004)")
            ax_a.legend(loc="upper left")
        ax_a.set_xlabel(rf"mean pressure $\bar p$ [{p_unit}]")
        ax_a.set_ylabel(r"contact fraction $A/A_0$ [-]")
        ax_a.set_title("load-area")
        ax_g.semilogy(gap / l_factor, p_mean / p_factor, "s-", color="#d62728")
        ax_g.set_xlabel(rf"mean gap $\bar u$ [{l_unit}]")
        ax_g.set_ylabel(rf"mean pressure $\bar p$ [{p_unit}]")
        ax_g.set_title("load-gap")
        return save_figure(fig, path)


def _units(res):
    """The report's pressure and length units (:meth:`RunResults.engineering`: mm and MPa for an SI scene,
    the scene's own with ``--units scene``), as every other table and figure of the report."""
    (pf, p_unit), (lf, l_unit) = res.engineering("pressure"), res.engineering("length")
    return {"p_unit": p_unit or "-", "p_factor": pf, "l_unit": l_unit or "-", "l_factor": lf}


def cell_maps(res, work):
    """The pressure and spot maps of a periodic result, or None for other results."""
    from ...run.periodic import contact_spots

    if res.result.periodic is None or res.bem_field is None:
        return None
    p = brick(res, res.bem_field[2])
    if p is None:
        return None
    labels, n = contact_spots(p > 0)
    size = res.bem.size
    kw = _units(res)
    (lf, lu), (pf, pu) = res.engineering("length"), res.engineering("pressure")
    path = plot_cell_maps(p, labels, size, work / "cell_maps.png", **kw)
    return Figure(path, f"Contact pressure (left) and the {n} contact spots (right) over the periodic cell "
                        f"({res.bem.cell[0]} x {res.bem.cell[1]} nodes of step {fmt(res.bem.step / lf)} "
                        f"{lu}; bem_field.vtu), each node drawn as one cell of its row, odd rows "
                        "shifted by half a step in the lattice. A spot is a set of nodes in contact connected "
                        "through the lattice's six nearest neighbours, across the cell's edges too (the cell "
                        "repeats): a spot cut by an edge has one colour on both sides. "
                        f"Mean pressure {fmt(res.result.periodic.mean_pressure / pf)} {pu}, contact "
                        f"fraction {fmt(res.result.periodic.contact_fraction)}.")


def sweep_curves(points, work, key):
    """The load-area and load-gap curves of a sweep of periodic runs (``[]`` with fewer than two points)."""
    keys = ("mean_pressure", "contact_fraction", "mean_gap")
    done = [res for _, res in points if res is not None and res.result.periodic is not None
            and all(getattr(res.result.periodic, k) is not None for k in keys)]
    if len(done) < 2:
        return []
    p, a, g = (np.array([getattr(r.result.periodic, k) for r in done], float) for k in keys)
    kw = _units(done[0])
    e_star, slope = done[0].bem.E_star, done[0].result.periodic.surface["rms_slope"]
    if slope is not None and e_star * slope > 0:
        kw["slope_modulus"] = e_star * slope
    path = plot_load_curves(p, a, g, work / "load_curves.png", **kw)
    pf, lf = kw["p_factor"], kw["l_factor"]
    table = Table((f"mean pressure [{kw['p_unit']}]", "contact fraction A/A0", f"mean gap [{kw['l_unit']}]",
                   "contact spots"), tuple((fmt(c.mean_pressure / pf), fmt(c.contact_fraction), fmt(c.mean_gap / lf),
                                            fmt(c.n_spots)) for c in (r.result.periodic for r in done)),
                  caption="The periodic cell at each computed point (result.json of each point).")
    return [table, Figure(path, f"Real contact fraction A/A0 against the mean pressure (left) and the mean pressure "
                         f"against the mean gap, the mean-plane separation (right), over the {len(done)} computed "
                         f"points of the sweep of {key}; each point a periodic solve of the cell. Dashed: the small-load "
                                 "proportionality of Hyun et al. (2004), with the rms slope of the data grid (a "
                                 "periodic lattice resolves the contact to a few nodes per cut-off wavelength, "
                                 "which puts the computed fraction a little above it; docs/rough.md).")]
