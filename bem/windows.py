"""Candidate windows of nested iteration on a half-space region.

``C p >= 0`` and ``w(p) >= 0`` for ``p >= 0``, so the deformed gap of a node is
``g_n >= h_n - delta``: a node with ``h_n >= delta`` carries no pressure at the solution, whatever
the others do. Nested iteration knows ``delta`` (the approach, or under force control its value
on the coarser level), and each finer level is solved on the window of the brick array that
holds the nodes with ``h_n < delta + _WINDOW_MARGIN (delta - min h)``, padded by ``_WINDOW_PAD``
nodes; the window's solution is the full one when every node outside it has ``h_n >= delta`` of
that solution, which is checked (otherwise the level is solved again on the full lattice from
the window's solution). The full lattice still gets one product, for the result. The gain is
measured by ``benchmarks/side_by_side.py`` (docs/performance.md).
"""

from __future__ import annotations

import logging

import numpy as np

from .cg_rules import QPSolution

__all__ = ["candidate_window", "solve_in_window"]

log = logging.getLogger(__name__)

_WINDOW_MARGIN = 0.25
_WINDOW_PAD = 2
_WINDOW_UP_TO = 0.6  # a window with more than this fraction of the brick array is not worth it


def candidate_window(lat, h, delta):
    """The window of ``lat`` holding the nodes whose gap may close near the approach ``delta``, or None."""
    if delta is None or not np.isfinite(delta):
        return None
    mask = lat.mask
    h_min = float(np.min(h, where=mask, initial=np.inf))
    if not delta > h_min:
        return None
    near = mask & (h < delta + _WINDOW_MARGIN * (delta - h_min))
    rows, cols = np.flatnonzero(near.any(axis=1)), np.flatnonzero(near.any(axis=0))
    (n_rows, n_cols), pad = lat.shape, _WINDOW_PAD
    r0, r1 = max(int(rows[0]) - pad, 0), min(int(rows[-1]) + 1 + pad, n_rows)
    c0, c1 = max(int(cols[0]) - pad, 0), min(int(cols[-1]) + 1 + pad, n_cols)
    if r1 - r0 < 4 or (r1 - r0) * (c1 - c0) > _WINDOW_UP_TO * n_rows * n_cols:
        return None
    return lat.window((r0, r1), (c0, c1))


def _clear_outside(lat, window, h, delta):
    """Whether every node of ``lat`` outside ``window`` has ``h >= delta`` (then ``g >= 0`` there at ``p = 0``)."""
    outside = lat.mask.copy()
    outside[window.index] = False
    return bool(np.isfinite(delta)) and float(np.min(h, where=outside, initial=np.inf)) >= delta


def _embedded(sol, window):
    """A window's solution as one of its parent lattice (``displacement`` is not carried over)."""
    hist = dict(sol.history)
    if "p" in hist:  # recorded iterates: candidate nodes of the window -> of the parent
        full = np.zeros(window.shape)
        parent = window.parent

        def lift(v):
            full[window.mask] = v
            return window.embed(full)[parent.mask]

        hist["p"] = [lift(v) for v in hist["p"]]
    return QPSolution(p=window.embed(sol.p), approach=sol.approach, iterations=sol.iterations,
                      converged=sol.converged, message=sol.message, status=sol.status, kkt_residual=sol.kkt_residual,
                      displacement=None, history=hist)


def solve_in_window(run, make_op, lat, h, kw, delta, solver):
    """Solve one lattice level, on the candidate window of the approach ``delta`` where there is one.

    ``run(op, h, kw)`` runs ``solver`` with the keyword arguments ``kw`` on the operator ``op =
    make_op(lattice)``; returns the solution and the operators used.
    """
    window = candidate_window(lat, h, delta)
    ops = []
    if window is not None:
        op = make_op(window)
        ops.append(op)
        kw_w = dict(kw, x0=None if kw["x0"] is None else kw["x0"][window.index])
        if kw["callback"] is not None:
            kw_w["callback"] = lambda k, p, cb=kw["callback"]: cb(k, window.embed(p))
        if solver == "kalker" and "maxiter" not in kw:  # the QP's default limit of the full lattice
            kw_w["maxiter"] = max(200, int(10 * np.sqrt(lat.n_nodes)))
        sol = _embedded(run(op, h[window.index], kw_w), window)
        if _clear_outside(lat, window, h, sol.approach):
            return sol, ops
        # rare: the approach grew past the margin. The full lattice starts from the window's
        # solution; the result reports that solve's iterations.
        log.debug("candidate window too small (approach %.6g): solving on the full lattice", sol.approach)
        kw = dict(kw, x0=sol.p)
    op = make_op(lat)
    ops.append(op)
    return run(op, h, kw), ops
