"""How the iterations of a method approach the solution (the paper's Fig. 6, 8 and 10).

The curves come from ``result.history``: ``"p"`` (every iterate as nodal values on
``result.x, result.y``, kept by ``bem.solve(..., record=True)``), ``"p_max"`` and
``"residual"`` (the KKT residual of each iterate, :func:`bem.kkt.kkt_residual`).
Conventions: :mod:`validation.report.figures`.
"""

from __future__ import annotations

import numpy as np

from bem.checks import InputError, check_positive

from ..render.style import color_for, method_label, new_figure, save_figure
from .profiles import section_of
from .sweeps import plot_sweep

__all__ = ["pick_iterations", "plot_iteration_profiles", "plot_convergence"]


def pick_iterations(n, most=10):
    """At most ``most`` iteration numbers out of ``1..n`` (sorted ints): all when few, else
    log-spaced; always 1 and ``n``."""
    if n < 1:
        return np.zeros(0, dtype=int)
    return np.arange(1, n + 1) if n <= most else np.unique(np.round(np.geomspace(1, n, most)).astype(int))


def plot_iteration_profiles(result, path, *, p0, a, iterations=None, title=None, xlim=None):
    """Axial-section pressure of the iterates ``k = 1..K``, coloured by ``k``, and the final state (Fig. 6, 10).

    Parameters
    ----------
    result : bem.ContactResult
        Solved with ``record=True``: ``result.history["p"][k-1]`` is iterate ``k``.
    iterations : sequence of int, optional
        Iterates to draw (1-based); default :func:`pick_iterations`.
    xlim : (float, float), optional
        Range of ``x / a`` (default: the widest iterate with a margin).
    """
    iterates = result.history.get("p") if isinstance(result.history, dict) else None
    if not iterates:
        raise InputError("result.history['p'] is missing or empty: solve with bem.solve(..., record=True).")
    n = len(iterates)
    ks = pick_iterations(n) if iterations is None else np.asarray(sorted(set(iterations)), dtype=int)
    if ks.size == 0 or ks.min() < 1 or ks.max() > n:
        raise InputError(f"iterations = {list(ks)} is not allowed: they must lie in 1..{n}.")
    final = (f"final ({'converged' if result.converged else 'NOT converged'}, k = {result.iterations})",
             *section_of(result), {"color": "black", "lw": 1.0, "ls": "--"})
    return plot_sweep([(k, *section_of(result, iterates[k - 1])) for k in ks], path, p0=p0, a=a,
                      name="iteration $k$", cmap="viridis", log=n > 20, xlim=xlim, extra=[final],
                      title=title or f"iterates of the {method_label(result.method)}")


def _integer_ticks(axis):
    """Iteration numbers on a log axis as plain integers (1, 2, 5, 10, 20, ...), no minor labels."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(lambda v, _pos: f"{v:.0f}" if v >= 1 else ""))
    axis.set_minor_formatter(NullFormatter())


def plot_convergence(runs, path, *, p0, title=None, tol=None, p_label=None):
    """Maximum pressure and KKT residual against the iteration, one line per run (Fig. 8).

    Parameters
    ----------
    runs : sequence of (str, bem.ContactResult or dict)
        Label and a result (or its ``history`` dict with ``p_max`` and ``residual``).
    p0 : float
        Scale of the maximum pressure [pressure].
    tol : float, optional
        Tolerance drawn as a line on the residual panel.
    p_label : str, optional
        Label of the maximum-pressure axis (default: normalised by the Hertz peak ``p0``).
    """
    p0 = check_positive("p0", p0)
    if not runs:
        raise InputError("runs = [] is not allowed: give at least one (label, result) pair.")
    with new_figure((6.6, 5.2), title=title or "maximum contact pressure during the iterations", nrows=2,
                    sharex=True, gridspec_kw={"height_ratios": [3, 2]}) as (fig, (top, bot)):
        for i, (label, run) in enumerate(runs):
            hist = run.history if hasattr(run, "history") else run
            if not isinstance(hist, dict) or not hist.get("p_max"):
                raise InputError("a run without history['p_max'] is not allowed: every run needs its iteration "
                                 "history.")
            pm, res = np.asarray(hist["p_max"], dtype=float), np.asarray(hist.get("residual", []), dtype=float)
            every = None if pm.size <= 30 else (pick_iterations(pm.size, 30) - 1).tolist()  # log-spaced markers
            style = dict(color=color_for(getattr(run, "method", None), i), marker="o", markersize=3, markevery=every)
            late = " - not converged" if getattr(run, "converged", True) is False else ""
            top.plot(np.arange(1, pm.size + 1), pm / p0, label=label + late, **style)
            good = np.isfinite(res) & (res > 0)
            if good.any():
                bot.semilogy(np.arange(1, res.size + 1)[good], res[good], **style)
        if tol is not None:
            bot.axhline(tol, color="#666666", ls=":", lw=1.0)
            bot.annotate(f"tolerance {tol:.0e}", (0.0, tol), xycoords=("axes fraction", "data"),
                         xytext=(4, 3), textcoords="offset points", ha="left", fontsize=8, color="#444444")
        top.set_ylabel(p_label or r"max. pressure $p_{max}\,/\,p_0$")
        top.legend(frameon=False, loc="best")
        bot.set_xscale("log")
        _integer_ticks(bot.xaxis)
        bot.set_xlabel("iteration $k$")
        bot.set_ylabel("KKT residual")
        return save_figure(fig, path)
