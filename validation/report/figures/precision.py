"""The work-precision plot of a resolution study: error against run time, one line per solver and
method (conventions: :mod:`validation.report.figures`)."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from bem.checks import InputError

from ..render.style import color_for, new_figure, save_figure

__all__ = ["plot_work_precision", "WP_FIELDS", "work_precision_rows", "time_spread"]

#: fields of one row of a resolution study
WP_FIELDS = ("solver", "method", "resolution", "N", "error", "wall_time_s")

_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")


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
    error_label : str
        What the error is (y-axis label).
    references : sequence of float
        Errors drawn as horizontal reference lines (default 1 % and 0.1 %).
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
    with new_figure((7.0, 4.6), title=title or "work-precision: error against run time") as (fig, ax):
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
        fig.legend(loc="outside lower center", ncols=min(len(groups), 3), frameon=False)
        return save_figure(fig, path)
