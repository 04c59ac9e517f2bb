"""The initial gap of a periodic cell: a brick array of the cell's shape, or a periodic callable."""

from __future__ import annotations

import numpy as np

from ..checks import check_gap_values, fail
from ..errors import InputError

__all__ = ["cell_gap", "coarse_gap", "check_cell_gap"]

_PERIODIC_RTOL = 1e-8  # gap(x + L) = gap(x) to this fraction of the gap's range


def check_cell_gap(gap, cell):
    """Raise unless ``gap`` is a callable or an array of the shape of ``cell``."""
    if callable(gap):
        return
    shape = np.shape(gap)
    if shape != cell.shape:
        fail("gap", f"<array of shape {shape}>", f"a brick array of the cell's shape {cell.shape} or a callable")


def _evaluate(gap, cell, sx, sy):
    x, y = cell.x + sx, cell.y + sy
    return check_gap_values(gap(x, y), {"x": x, "y": y}, region="over the cell")


def cell_gap(gap, cell):
    """The nodal gap (brick array) [length]: the array, or the callable at the nodes, checked periodic."""
    if callable(gap):
        h = _evaluate(gap, cell, 0.0, 0.0)
        lx, ly = cell.size
        scale = float(np.ptp(h)) or max(float(np.abs(h).max()), 1.0)
        for name, sx, sy in (("Lx", lx, 0.0), ("Ly", 0.0, ly)):
            shifted = _evaluate(gap, cell, sx, sy)
            worst = float(np.abs(shifted - h).max())
            if worst > _PERIODIC_RTOL * scale:
                raise InputError(f"gap = {gap!r} is not allowed: it must be periodic over the cell "
                                 f"({cell.n_cols} x {cell.n_rows} nodes of step {cell.step:.6g}, Lx = {lx:.6g}, "
                                 f"Ly = {ly:.6g}); gap(x + {name}) differs from gap(x) by {worst:.3g}.")
        return h
    h = np.asarray(gap, dtype=float) if not isinstance(gap, np.ndarray) else gap.astype(float, copy=False)
    if not np.all(np.isfinite(h)):
        r, q = np.argwhere(~np.isfinite(h))[0]
        fail("gap", f"<array with {h[r, q]!r} at row {r}, column {q}>", "finite")
    return h


def coarse_gap(gap, fine, h_fine, coarse):
    """The nodal gap on the coarser cell of nested iteration: the callable there, or the array restricted."""
    return _evaluate(gap, coarse, 0.0, 0.0) if callable(gap) else fine.restrict(h_fine)
