"""The periodic cell of the triangular lattice.

A cell of ``n_cols x n_rows`` nodes (``n_rows`` even) and step ``c`` repeats with the
periods ``Lx = n_cols c`` and ``Ly = n_rows c sqrt3/2``. Node ``(q, r)``,
``q = 0 .. n_cols - 1``, ``r = 0 .. n_rows - 1``, sits at

    x = (q + (r mod 2)/2) c,   y = r c sqrt3/2,

and nodal values are stored as brick arrays of shape ``(n_rows, n_cols)`` (row ``r``,
column ``q``), the storage of :class:`bem.lattice.Lattice`. Every node is a candidate: a
periodic cell has no border. A cell is a domain of :func:`bem.solve` (the methods below
"the problem on the cell", as :class:`bem.HalfSpaceRegion` has them). Node ``(q, r)`` is the lattice node ``i e1 + j e2`` with
``j = r``, ``i = q - floor(r/2)``; ``n_rows`` even makes the lattice periodic in ``y``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .. import fft, heap
from ..checks import check_int, check_node_count, check_positive, fail
from .gap import cell_gap, check_cell_gap, coarse_gap
from .influence import PeriodicOperator, forget_symbols
from .passes import MIN_NODES
from .result import PeriodicContactResult
from .step_passes import prolong_kernel

__all__ = ["PeriodicCell"]

_SQRT3 = math.sqrt(3.0)
_COARSEST_NODES = 4096  # nested iteration stops coarsening below this many nodes
# KKT residual to which the coarser cells of nested iteration are solved. The QP's iterations on
# the finest cell do not fall with a tighter coarse solution while the coarse cells' own
# iterations double from 1e-2 to 1e-6; Newton with a root layer takes one step more on the finest
# cell from 1e-3 than from 1e-4 while its coarse cells cost a third less, so it solves them to
# 1e-3; the other solvers keep 1e-6 (benchmarks/periodic_rough.py measures both).
_COARSE_RTOL = {"kalker": 1e-2, "newton": 1e-3}
_COARSE_RTOL_DEFAULT = 1e-6


def rows_for(step, ly):
    """Rows of the cell of step ``step`` closest to the period ``ly`` [length]: the even number
    nearest ``ly / (step sqrt3/2)``, at least 2 (the rule of :meth:`PeriodicCell.from_size`)."""
    return max(2, 2 * int(round(ly / (step * _SQRT3))))


@dataclass(frozen=True)
class PeriodicCell:
    """A periodic cell of the triangular lattice (module docstring).

    Parameters
    ----------
    step : float
        Lattice step ``c`` [length], > 0.
    n_cols : int
        Nodes per row, >= 4.
    n_rows : int
        Rows, even, >= 2; ``n_cols n_rows`` at most :func:`bem.checks.max_nodes` (the memory guard
        of :func:`bem.solve`, as for a half-space region).
    """

    step: float
    n_cols: int
    n_rows: int

    def __post_init__(self):
        object.__setattr__(self, "step", check_positive("step", self.step))
        object.__setattr__(self, "n_cols", check_int("n_cols", self.n_cols, minimum=4))
        n_rows = check_int("n_rows", self.n_rows, minimum=2)
        if n_rows % 2:
            fail("n_rows", n_rows, "even (the triangular lattice repeats every two rows)")
        check_node_count("(n_cols, n_rows)", (self.n_cols, n_rows), self.n_cols * n_rows, what="the periodic cell")
        object.__setattr__(self, "n_rows", n_rows)

    @classmethod
    def from_size(cls, step, size):
        """The cell of step ``step`` closest to the size ``(Lx, Ly)`` [length].

        ``n_cols = round(Lx / c)`` and ``n_rows`` the even number nearest ``Ly / (c sqrt3/2)``;
        :attr:`size` gives the cell's exact size.
        """
        step = check_positive("step", step)
        lx, ly = (check_positive("size", v) for v in (size if np.ndim(size) else (size, size)))
        n_cols, n_rows = max(4, int(round(lx / step))), rows_for(step, ly)
        check_node_count("step", step, n_cols * n_rows, what="the periodic cell")
        return cls(step, n_cols, n_rows)

    result_class = PeriodicContactResult

    # -- the problem on the cell (the domain interface of bem.solve) ----------------------------

    def check_gap(self, gap):
        """Raise unless ``gap`` is a callable ``h(x, y)`` periodic over the cell or a brick array of its shape."""
        check_cell_gap(gap, self)

    def resolved(self, gap, **load):
        """The cell itself (it has no automatic size)."""
        return self

    def lattice(self):
        """The cell is its own lattice."""
        return self

    def nodal_gap(self, gap, cell):
        """The initial gap at the nodes (brick array) [length], a callable checked periodic."""
        return cell_gap(gap, cell)

    def check_approach(self, approach, h, layer):
        """Without a layer the approach must be below the mean gap: a full contact leaves the mean pressure undetermined."""
        if approach is not None and layer is None and not approach < float(h.mean()):
            fail("approach", approach, f"< the mean gap {float(h.mean()):.6g} without a layer (a full contact "
                 "leaves the mean pressure undetermined: give mean_pressure)")

    def levels(self, cell, h, gap, nested):
        """``(cell, gap)`` pairs of nested iteration, from the coarsest cell to ``cell``."""
        levels = [(cell, h)]
        while nested:
            fine, hf = levels[-1]
            coarse = fine.coarsen()
            if coarse is None or coarse.n_nodes < _COARSEST_NODES:
                break
            levels.append((coarse, coarse_gap(gap, fine, hf, coarse)))
        return levels[::-1]

    def coarse_rtol(self, solver, precondition=True):
        """KKT residual to which the coarser cells of nested iteration are solved (the same with or without the
        preconditioner)."""
        return _COARSE_RTOL.get(solver, _COARSE_RTOL_DEFAULT)

    def operator(self, cell, E_star, backend, *, bodies=None):
        """The periodic influence operator on ``cell`` (of coated ``bodies`` where given)."""
        return PeriodicOperator(cell, E_star, device=backend, bodies=bodies)

    def solve_level(self, run, make_op, cell, h, kw, delta, solver, handover=None):
        """One level of nested iteration, on the whole cell (what the coarser level hands over, ``handover``, unused);
        the solution, the operator used and no product."""
        op = make_op(cell)
        return run(op, h, kw), [op], None

    def refine(self, coarse, p, fine):
        """The coarse solution interpolated onto the next finer cell; where a product on it (16 bytes a node) is
        above :data:`bem.heap.RELEASE_ABOVE`, the kept symbols of the coarser cells are let go first."""
        if heap.above(16 * fine.n_nodes):
            forget_symbols(below=fine.n_nodes)
        return fine.prolong(p)

    def check_solution(self, cell, p):
        """A cell has no border: every solution fits."""

    def grown(self, gap, attempt):
        """A cell does not grow."""
        return None

    @property
    def shape(self):
        """Shape ``(n_rows, n_cols)`` of a brick array."""
        return (self.n_rows, self.n_cols)

    @property
    def size(self):
        """Periods ``(Lx, Ly)`` [length]."""
        return (self.n_cols * self.step, self.n_rows * self.step * _SQRT3 / 2)

    @property
    def area(self):
        """Area of the cell ``Lx Ly`` [length^2]."""
        lx, ly = self.size
        return lx * ly

    @property
    def node_area(self):
        """Quadrature weight of a node, the pyramid volume ``sqrt(3)/2 c^2`` [length^2]."""
        return _SQRT3 / 2 * self.step**2

    @property
    def n_nodes(self):
        """Number of nodes."""
        return self.n_rows * self.n_cols

    @cached_property
    def parity(self):
        """``r mod 2`` of each row, shape ``(n_rows,)``."""
        return np.arange(self.n_rows) % 2

    @cached_property
    def x(self):
        """Node abscissae [length], shape :attr:`shape`."""
        return self.step * (np.arange(self.n_cols)[None, :] + 0.5 * self.parity[:, None])

    @cached_property
    def y(self):
        """Node ordinates [length], shape :attr:`shape`."""
        return np.broadcast_to(self.step * _SQRT3 / 2 * np.arange(self.n_rows)[:, None], self.shape).copy()

    @cached_property
    def mask(self):
        """Every node is a candidate: all True, shape :attr:`shape`."""
        return np.ones(self.shape, dtype=bool)

    @cached_property
    def border(self):
        """A periodic cell has no border: all False, shape :attr:`shape`."""
        return np.zeros(self.shape, dtype=bool)

    def coarsen(self):
        """The cell of step ``2c`` whose nodes are every other node of this one, or ``None``.

        Needs ``n_cols`` even and ``n_rows`` a multiple of 4 (and at least 4 x 2 nodes left).
        Coarse node ``(q, r)`` is fine node ``(2q + r mod 2, 2r)``.
        """
        if self.n_cols % 2 or self.n_rows % 4 or self.n_cols < 8:
            return None
        return PeriodicCell(2 * self.step, self.n_cols // 2, self.n_rows // 2)

    def restrict(self, values):
        """The values at the nodes of :meth:`coarsen` (every other node), shape of the coarse cell."""
        values = np.asarray(values)
        rows = values[0::2]
        out = np.empty((self.n_rows // 2, self.n_cols // 2), dtype=values.dtype)
        out[0::2] = rows[0::2, 0::2]
        out[1::2] = rows[1::2, 1::2]
        return out

    def prolong(self, values):
        """The piecewise-linear field of the coarse nodal ``values`` (cell :meth:`coarsen`) at this cell's nodes.

        A fine node is a coarse node or the midpoint of a coarse edge (along ``e1``, ``e2`` or
        ``e2 - e1``): it takes the coarse value or the mean of two. Periodic. On a cell of at least
        :data:`bem.periodic.passes.MIN_NODES` nodes with numba the rows are made by the compiled kernel of
        :func:`bem.periodic.step_passes.prolong_kernel` on the FFT threads (the same numbers).
        """
        coarse = self.coarsen()
        values = np.asarray(values, dtype=float)
        if coarse is None or values.shape != coarse.shape:
            fail("values", f"<array of shape {values.shape}>",
                 f"nodal values of the coarse cell, shape {None if coarse is None else coarse.shape}")
        # by slices: coarse row k lies on fine row 2k at the columns of parity k mod 2, the other
        # columns are midpoints along e1; fine row 2k + 1 holds the midpoints of the edges between
        # coarse rows k and k + 1, the means of neighbouring columns of those rows interleaved
        out = np.empty(self.shape)
        if self.n_nodes >= MIN_NODES and (kernel := prolong_kernel()) is not None:  # the same numbers, in parts
            values = np.ascontiguousarray(values)
            fft.in_parts(lambda part: kernel(values, out, part.start, part.stop), coarse.n_rows, out.size)
            return out
        even, nxt = out[0::2], np.roll(values, -1, axis=0)
        even[0::2, 0::2] = values[0::2]
        even[1::2, 1::2] = values[1::2]
        even[0::2, 1::2] = 0.5 * (values[0::2] + np.roll(values[0::2], -1, axis=1))
        even[1::2, 0::2] = 0.5 * (values[1::2] + np.roll(values[1::2], 1, axis=1))
        both = np.empty_like(even)  # coarse row k at its columns, row k + 1 at the others
        both[:, 0::2] = np.where((np.arange(coarse.n_rows) % 2 == 0)[:, None], values, nxt)
        both[:, 1::2] = np.where((np.arange(coarse.n_rows) % 2 == 1)[:, None], values, nxt)
        out[1::2] = 0.5 * (both + np.roll(both, -1, axis=1))
        return out

    def interpolate(self, values, x, y):
        """The piecewise-linear field ``sum values_n pyr_n`` at the points ``(x, y)`` [length], periodic.

        Parameters
        ----------
        values : ndarray, shape :attr:`shape`
            Nodal values.
        x, y : array_like
            Points, any broadcastable shapes; any point of the plane (the field repeats).

        Returns
        -------
        ndarray
            Linear interpolation on the triangle that holds each point.
        """
        values = np.asarray(values, dtype=float)
        if values.shape != self.shape:
            fail("values", f"<array of shape {values.shape}>", f"nodal values of the cell, shape {self.shape}")
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        t = y / (self.step * _SQRT3 / 2)  # lattice coordinates: point = c (s e1 + t e2)
        s = x / self.step - t / 2
        i0, j0 = np.floor(s), np.floor(t)
        fs, ft = s - i0, t - j0
        upper = fs + ft > 1.0
        i0, j0 = i0.astype(np.int64), j0.astype(np.int64)

        def at(i, j):
            return values[np.mod(j, self.n_rows), np.mod(i + np.floor_divide(j, 2), self.n_cols)]

        corner = np.where(upper, 1, 0)  # the third vertex: (i0, j0) below the diagonal, (i0 + 1, j0 + 1) above
        w_a = np.where(upper, fs + ft - 1.0, 1.0 - fs - ft)
        return (w_a * at(i0 + corner, j0 + corner) + np.where(upper, 1.0 - ft, fs) * at(i0 + 1, j0)
                + np.where(upper, 1.0 - fs, ft) * at(i0, j0 + 1))

