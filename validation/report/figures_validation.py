"""Validation figures: solver profiles against a reference with the error underneath, and the
work-precision plot (error against run time) of a resolution study."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from bem.checks import InputError, check_positive

from .style import SOLVER_COLORS, color_for, new_figure, save_figure

__all__ = ["plot_profile_comparison", "plot_work_precision", "WP_FIELDS", "work_precision_rows", "time_spread"]

#: fields of one row of a resolution study
WP_FIELDS = ("solver", "method", "resolution", "N", "error", "wall_time_s")

_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")


def _radial(r, p):
    r, p = np.asarray(r, dtype=float), np.asarray(p, dtype=float)
    keep = r >= 0
    order = np.argsort(r[keep], kind="stable")
    return r[keep][order], p[keep][order]


def plot_profile_comparison(curves, path, *, p0, a, reference=None, title=None, rmax=None, labels=None,
                            error_scale=None):
    """Radial pressure profiles of several solvers with their error against a reference.

    Upper panel: ``p(r) / p0`` of every curve (and of the reference). Lower panel
    (shared ``r``): ``(p - p_ref) / p0`` at each curve's own nodes, the reference
    evaluated there (closed form, or linear interpolation of reference samples).

    Parameters
    ----------
    curves : sequence of (str, array_like, array_like) or (str, r, p, str)
        ``(label, r, p)`` radial samples [length], [pressure]; only ``r >= 0`` is used.
        An optional 4th item names the solver (``"bem"``, ``"fem"``, ...) for its colour.
    path : path-like
        PNG file to write.
    p0, a : float
        Pressure and length scales (Hertz peak and radius).
    reference : (str, callable) or (str, r, p), optional
        The reference profile ``p_ref(r)``; without it the first curve is the reference.
    title : str, optional
        Upper panel title.
    rmax : float, optional
        Largest ``r / a`` shown (default: the widest loaded zone of the curves plus 25 %).
    labels : dict, optional
        ``{"x", "p", "err", "err_of"}``: axis labels of the abscissa, the pressure and the
        error, and what the error is a fraction of in the legend (default: normalised by
        the Hertz radius and peak, error in units of ``p0``).
    error_scale : float, optional
        Pressure the error is divided by [pressure] (default ``p0``).

    Returns
    -------
    str
        ``path``.
    """
    p0, a = check_positive("p0", p0), check_positive("a", a)
    e0 = p0 if error_scale is None else check_positive("error_scale", error_scale)
    lab = {"x": r"radius $r\,/\,a_H$", "p": r"contact pressure $p\,/\,p_0$",
           "err": r"error $(p - p_{ref})\,/\,p_0$", "err_of": "$p_0$", **(labels or {})}
    if not curves:
        raise InputError("curves = [] is not allowed: give at least one (label, r, p) curve.")
    curves = list(curves)
    if reference is None:
        first = curves.pop(0)
        reference = (first[0], first[1], first[2])
    ref_label = reference[0]
    if rmax is None:
        reach = [float(np.max(np.abs(np.asarray(c[1], dtype=float))[np.asarray(c[2]) > 0], initial=0.0))
                 for c in curves]
        rmax = max(1.25 * max(reach, default=0.0) / a, 1.2)
    if callable(reference[1]):
        ref_fn = reference[1]
        rr = np.linspace(0.0, rmax * a, 800)
        ref_r, ref_p = rr, np.asarray(ref_fn(rr), dtype=float)
    else:
        ref_r, ref_p = _radial(reference[1], reference[2])

        def ref_fn(r):
            return np.interp(r, ref_r, ref_p, right=0.0)

    with new_figure((6.6, 5.4), nrows=2, sharex=True, gridspec_kw={"height_ratios": [3, 2]}) as (fig, (top, bot)):
        top.plot(ref_r / a, ref_p / p0, color=SOLVER_COLORS["analytic"], lw=1.3, ls="--", label=ref_label, zorder=4)
        bot.axhline(0.0, color=SOLVER_COLORS["analytic"], lw=1.0, ls="--")
        worst = 0.0
        for i, item in enumerate(curves):
            label, r, p = item[0], item[1], item[2]
            color = color_for(item[3] if len(item) > 3 else None, i + 1)
            r, p = _radial(r, p)
            err = (p - ref_fn(r)) / e0
            shown = r <= rmax * a
            worst = max(worst, float(np.abs(err[shown]).max(initial=0.0)))
            marker = dict(marker="o", markersize=3) if r.size <= 80 else {}
            top.plot(r / a, p / p0, color=color, label=label, lw=1.5, **marker)
            bot.plot(r[shown] / a, err[shown], color=color, lw=1.2, **marker,
                     label=f"{label}: max |error| {np.abs(err[shown]).max(initial=0.0):.2%} of {lab['err_of']}")
        top.set_xlim(0.0, rmax)
        top.set_ylim(bottom=0.0)
        top.set_ylabel(lab["p"])
        top.set_title(title or f"pressure profiles against {ref_label}")
        top.legend(loc="upper right", frameon=False)
        bot.set_xlabel(lab["x"])
        bot.set_ylabel(lab["err"])
        if worst > 0:
            bot.set_ylim(-1.15 * worst, 1.15 * worst)
        bot.legend(loc="lower left", frameon=False, fontsize=7.5)
        return save_figure(fig, path)


def work_precision_rows(rows):
    """Rows of a resolution study as dicts with the keys :data:`WP_FIELDS`.

    Accepts dicts (extra keys kept, e.g. ``wall_times_s``: the times of every repeat [s])
    or sequences in the order of :data:`WP_FIELDS`. Rows whose error or time is not a
    positive finite number are dropped (they cannot be drawn on log axes).
    """
    out = []
    for row in rows:
        if not isinstance(row, Mapping):
            row = dict(zip(WP_FIELDS, row))
        missing = [k for k in ("solver", "error", "wall_time_s") if k not in row]
        if missing:
            raise InputError(f"a work-precision row {dict(row)!r} is not allowed: it lacks {missing}.")
        err, t = row["error"], row["wall_time_s"]
        if err is None or t is None or not (math.isfinite(err) and math.isfinite(t) and err > 0 and t > 0):
            continue
        out.append({"method": "", "resolution": "", "N": None, **row})
    return out


def time_spread(row):
    """``(median, low, high)`` wall time of a row [s]: the spread of its repeats ``wall_times_s``
    (min and max), or the median alone (``low = high = median``) without repeats."""
    t = float(row["wall_time_s"])
    times = [float(v) for v in (row.get("wall_times_s") or ()) if v is not None and math.isfinite(v) and v > 0]
    if len(times) < 2:
        return t, t, t
    return t, min(min(times), t), max(max(times), t)


def _short_count(n):
    """``12345 -> "12k"``: a compact unknown count for a label."""
    n = int(n)
    for div, suffix in ((1_000_000, "M"), (1_000, "k")):
        if n >= 10 * div:
            return f"{n / div:.0f}{suffix}"
        if n >= div:
            return f"{n / div:.1f}{suffix}"
    return str(n)


def plot_work_precision(rows, path, *, error_label="relative error", title=None, references=(0.01, 0.001)):
    """Error against wall time, log-log, one line per (solver, method), a marker per resolution.

    The marker sits at the median time of the repeats of a run, the horizontal bar spans
    their fastest to slowest (rows with ``wall_times_s``, :func:`time_spread`); each marker
    is labelled with its resolution and unknown count.

    Parameters
    ----------
    rows : iterable of dict or sequence
        ``(solver, method, resolution, N, error, wall_time_s)`` and optionally
        ``wall_times_s`` (:func:`work_precision_rows`).
    path : path-like
        PNG file to write.
    error_label : str
        What the error is (y-axis label).
    title : str, optional
        Axes title.
    references : sequence of float
        Errors drawn as horizontal reference lines (default 1 % and 0.1 %).

    Returns
    -------
    str
        The written file.
    """
    rows = work_precision_rows(rows)
    if not rows:
        raise InputError("rows has no row with a positive error and time: nothing to draw.")
    groups = {}
    for row in rows:
        groups.setdefault((str(row["solver"]), str(row.get("method") or "")), []).append(row)
    by_solver = len({s for s, _ in groups}) == len(groups)  # one line per solver: colour by solver
    spread = any(time_spread(r)[1] < time_spread(r)[2] for r in rows)
    repeats = max((len(r.get("wall_times_s") or ()) for r in rows), default=0)
    with new_figure((7.0, 4.6)) as (fig, ax):
        for i, ((solver, method), grp) in enumerate(groups.items()):
            grp = sorted(grp, key=lambda r: r["wall_time_s"])
            t, lo, hi = np.array([time_spread(r) for r in grp]).T
            e = np.array([r["error"] for r in grp])
            color = color_for(solver.lower() if by_solver else (method or solver.lower()), i)
            label = solver.upper() if solver.lower() in ("bem", "fem") else solver
            label = f"{label} ({method})" if method else label
            ax.plot(t, e, color=color, lw=1.3, label=label, zorder=2)
            ax.errorbar(t, e, xerr=[t - lo, hi - t], fmt="none", ecolor=color, elinewidth=1.0, capsize=3,
                        zorder=3)
            for j, r in enumerate(grp):
                ax.plot(t[j], e[j], marker=_MARKERS[j % len(_MARKERS)], color=color, markersize=6, ls="none",
                        markeredgecolor="white", markeredgewidth=0.6, zorder=4)
                text = str(r.get("resolution") or "")
                if r.get("N"):
                    text = f"{text}\nN = {_short_count(r['N'])}" if text else f"N = {_short_count(r['N'])}"
                if text:
                    ax.annotate(text, (hi[j], e[j]), xytext=(4, 3), textcoords="offset points", fontsize=7,
                                color=color, va="bottom", linespacing=1.0, zorder=5,
                                bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8})
        for ref in references:
            ax.axhline(ref, color="#777777", lw=0.9, ls=":", zorder=1)
            ax.annotate(f"{ref:.1%}".replace(".0%", "%"), (1.0, ref), xycoords=("axes fraction", "data"),
                        xytext=(-3, 2), textcoords="offset points", fontsize=8, color="#555555", ha="right")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.margins(x=0.25, y=0.12)
        ax.set_xlabel("wall-clock time [s]" + (f" (marker: median of up to {repeats} runs; bar: fastest to slowest)"
                                                if spread else ""))
        ax.set_ylabel(error_label)
        ax.set_title(title or "work-precision: error against run time")
        fig.legend(loc="outside lower center", ncols=min(len(groups), 3), frameon=False)
        return save_figure(fig, path)
