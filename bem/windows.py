"""Candidate windows of nested iteration on a half-space region.

``C p >= 0`` and ``w(p) >= 0`` for ``p >= 0``, so the deformed gap of a node is
``g_n >= h_n - delta``: a node with ``h_n >= delta`` carries no pressure at the solution, whatever
the others do. Nested iteration knows ``delta`` (the approach, or under force control its value
on the coarser level), and each finer level is solved on the window of the brick array that
holds the nodes with ``h_n < delta + _WINDOW_MARGIN (delta - min h)``, padded by ``_WINDOW_PAD``
nodes; the window's solution is the full one when every node outside it has ``h_n >= delta`` of
that solution, which is checked (otherwise the level is solved again on the full lattice from
the window's solution). The full lattice still gets one product, for the result.

Where the start of a level (the coarser level's solution, prolonged) touches a smaller block than
that, the level is solved on the bounding box of the start's contact, padded by ``_START_PAD``
nodes (:func:`start_window`); on a rough surface, whose gap ``h`` dips below the approach far from
the contact, it is the only window. Where the coarser level made its product ``C p`` (its own window
checked), that product prolonged estimates the finer gap, and the box takes in the nodes it closes,
``h + u < delta``: asperities the finer ``h`` raises where the coarser lattice did not see them.
Nothing guarantees the window, so the full lattice's product ``u = C p`` of its solution checks it:
the solution is accepted where every node outside the window is open,
``-(u + h - delta) <= rtol max |u|`` (the rule of :func:`bem.kkt.kkt_residual` for the nodes out of
contact), and is then the full lattice's solution within ``rtol``, that product the result's;
otherwise the level is solved again from it on the window grown over the nodes it missed (padded
by ``_START_PAD``; on a rough surface its contact's edge at the finer level reaches asperities the
coarser one did not see), at most ``_START_TRIES`` windows, then on the full lattice. The gains are
measured by ``benchmarks/side_by_side.py``, ``benchmarks/peers.py`` and ``benchmarks/two_scale.py``
(docs/performance.md).
"""

from __future__ import annotations

import logging

import numpy as np

from .backend import to_host
from .cg_rules import QPSolution

__all__ = ["candidate_window", "start_window", "solve_in_window"]

log = logging.getLogger(__name__)

_WINDOW_MARGIN = 0.25
_WINDOW_PAD = 2
_WINDOW_UP_TO = 0.6  # a window with more than this fraction of the brick array is not worth it
_START_PAD = 2  # nodes around the bounding box of the start's contact, and around the nodes a window missed
_START_TRIES = 3  # windows of the start's contact tried, each grown over the nodes the last one missed
_CHECK_ROWS = 256  # rows of a block of the check outside a window


def candidate_window(lat, h, delta):
    """The window of ``lat`` holding the nodes whose gap may close near the approach ``delta``, or None."""
    if delta is None or not np.isfinite(delta):
        return None
    mask = lat.mask
    h_min = float(np.min(h, where=mask, initial=np.inf))
    if not delta > h_min:
        return None
    top = delta + _WINDOW_MARGIN * (delta - h_min)
    return _box_window(lat, _box(lat, lambda lo, hi: mask[lo:hi] & (h[lo:hi] < top)), _WINDOW_PAD)


def start_window(lat, x0, h=None, u=None, delta=None):
    """The window of ``lat`` around the contact of the start ``x0`` (its nodes of positive pressure, a brick array),
    padded by ``_START_PAD`` nodes, or None (no start, no contact, or a window not worth it). With the coarser
    level's product ``u = C p`` prolonged onto ``lat``, the gap ``h`` and the approach ``delta``, also around the
    nodes that estimate closes, ``h + u < delta``: asperities that the finer gap ``h`` raises where the coarser one
    did not."""
    if x0 is None:
        return None
    x0 = np.asarray(x0)

    def near(lo, hi):
        on = x0[lo:hi] > 0
        return on if u is None else on | (lat.mask[lo:hi] & (h[lo:hi] + u[lo:hi] < delta))

    return _box_window(lat, _box(lat, near), _START_PAD)


def _box(lat, near, outside=None):
    """The bounding box ``((r0, r1), (c0, c1))`` of the nodes where ``near(lo, hi)``, a boolean block of the brick
    rows ``lo:hi``, is true (outside the window ``outside`` where given); None where there are none. By blocks of
    :data:`_CHECK_ROWS` rows: no array of the lattice made."""
    rows, cols = [], []
    for lo in range(0, lat.shape[0], _CHECK_ROWS):
        hi = min(lo + _CHECK_ROWS, lat.shape[0])
        block = near(lo, hi)
        if outside is not None:
            (r0, r1), (c0, c1) = outside.rows, outside.cols
            block[max(r0 - lo, 0) : max(min(r1, hi) - lo, 0), c0:c1] = False
        if block.any():
            r, c = np.flatnonzero(block.any(axis=1)), np.flatnonzero(block.any(axis=0))
            rows += [lo + int(r[0]), lo + int(r[-1]) + 1]
            cols += [int(c[0]), int(c[-1]) + 1]
    return ((min(rows), max(rows)), (min(cols), max(cols))) if rows else None


def _box_window(lat, box, pad):
    """The block ``box = ((r0, r1), (c0, c1))`` padded by ``pad`` nodes, as a window of ``lat``; None where ``box`` is
    None or the window has more than ``_WINDOW_UP_TO`` of the brick array."""
    if box is None:
        return None
    n_rows, n_cols = lat.shape
    (r0, r1), (c0, c1) = box
    r0, r1 = max(r0 - pad, 0), min(r1 + pad, n_rows)
    c0, c1 = max(c0 - pad, 0), min(c1 + pad, n_cols)
    if r1 - r0 < 4 or (r1 - r0) * (c1 - c0) > _WINDOW_UP_TO * n_rows * n_cols:
        return None
    return lat.window((r0, r1), (c0, c1))


def _closing_outside(lat, window, h, delta, u=None, rtol=0.0):
    """The bounding box of the nodes of ``lat`` outside ``window`` that are not open within ``rtol``: ``h + u - delta
    < -rtol max |u|`` (``u = C p`` on ``lat``, ``p = 0`` outside, ``w(0) = 0``; without ``u``: ``h < delta``, the
    nodes whose gap can close); None where every one is open."""
    mask = lat.mask
    if u is None:
        return _box(lat, lambda lo, hi: mask[lo:hi] & (h[lo:hi] < delta), window)
    below = delta - rtol * max(float(np.max(u)), -float(np.min(u)))
    return _box(lat, lambda lo, hi: mask[lo:hi] & (u[lo:hi] + h[lo:hi] < below), window)


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


class _Spent:
    """The record of an operator let go: its lattice and the products and transforms it made (what nested iteration
    reads)."""

    def __init__(self, op):
        self.lattice, self.n_matvec, self.n_transforms = op.lattice, op.n_matvec, op.n_transforms


def _window_kw(kw, window, lat, solver):
    """The keyword arguments of a solve on ``window``: its part of the start, the callback on the full lattice, and
    the QP's default iteration limit of the full lattice."""
    kw_w = dict(kw, x0=None if kw["x0"] is None else kw["x0"][window.index])
    if kw["callback"] is not None:
        kw_w["callback"] = lambda k, p, cb=kw["callback"]: cb(k, window.embed(p))
    if solver == "kalker" and "maxiter" not in kw:
        kw_w["maxiter"] = max(200, int(10 * np.sqrt(lat.n_nodes)))
    return kw_w


def solve_in_window(run, make_op, lat, h, kw, delta, solver, handover=None):
    """Solve one lattice level, on a window of it where there is one (the module docstring).

    ``run(op, h, kw)`` runs ``solver`` with the keyword arguments ``kw`` on the operator ``op =
    make_op(lattice)``. ``delta`` is the approach the level is solved near (the given one, or the coarser level's;
    None outside nested iteration: no window); ``handover``: a dict that may hold under ``"u"`` the coarser level's
    product ``C p`` prolonged onto ``lat`` (taken out of it, and let go once the window is chosen). Returns the
    solution, the operators used (or the records of those let go), and the product ``C p`` of the solution on ``lat``
    where the level made it (a window checked on the full lattice; None otherwise).
    """
    window = candidate_window(lat, h, delta)
    u = (handover or {}).pop("u", None)
    start = start_window(lat, kw["x0"], h, u, delta) if delta is not None else None
    u = None
    if start is not None and (window is None or start.n_nodes < window.n_nodes):
        return _solve_checked(run, make_op, lat, h, kw, solver, start)
    ops = []
    if window is not None:
        op = make_op(window)
        ops.append(op)
        sol = _embedded(run(op, h[window.index], _window_kw(kw, window, lat, solver)), window)
        if np.isfinite(sol.approach) and _closing_outside(lat, window, h, sol.approach) is None:
            return sol, ops, None
        # rare: the approach grew past the margin. The full lattice starts from the window's
        # solution; the result reports that solve's iterations.
        log.debug("candidate window too small (approach %.6g): solving on the full lattice", sol.approach)
        kw = dict(kw, x0=sol.p)
    op = make_op(lat)
    ops.append(op)
    return run(op, h, kw), ops, None


def _solve_checked(run, make_op, lat, h, kw, solver, window):
    """:func:`solve_in_window` on the window of the start's contact, checked by the full lattice's product; a window
    that misses nodes of the contact is grown over them (at most ``_START_TRIES`` windows). Each operator, of a
    window or of the full lattice, is let go before the next is made (its counts kept)."""
    ops = []
    for _ in range(_START_TRIES):
        op = make_op(window)
        sol = _embedded(run(op, h[window.index], _window_kw(kw, window, lat, solver)), window)
        ops.append(_Spent(op))
        op = make_op(lat)  # the window's operator (its kernel spectra) goes before the full lattice's product
        u = to_host(op.matvec(sol.p))
        closing = _closing_outside(lat, window, h, sol.approach, u, kw["rtol"]) if sol.converged else None
        if closing is None:
            return sol, ops + [op], u
        ops.append(_Spent(op))
        op = u = None
        kw = dict(kw, x0=sol.p)  # the next solve starts from this one
        (r0, r1), (c0, c1) = window.rows, window.cols
        window = _box_window(lat, ((min(r0, closing[0][0]), max(r1, closing[0][1])),
                                   (min(c0, closing[1][0]), max(c1, closing[1][1]))), _START_PAD)
        log.debug("the window of the start's contact misses nodes of the contact: %s", "grown" if window else "none")
        if window is None:
            break
    op = make_op(lat)
    return run(op, h, kw), ops + [op], None
