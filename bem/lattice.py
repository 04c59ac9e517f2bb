"""The regular equilateral-triangle lattice of the pyramid pressure elements.

Node ``(i, j)`` of the lattice with step ``c`` sits at ``c*(i*e1 + j*e2)``,
``e1 = (1, 0)``, ``e2 = (1/2, sqrt(3)/2)`` (docs/method.md section 2, paper Fig. 2).
The candidate region is the rectangle ``|x| <= ex``, ``|y| <= ey`` centred on the
origin. Its nodes are stored row by row in a 2-D "brick" array of shape
``(n_rows, n_cols)``: row ``r`` holds lattice row ``j = r - J`` at
``y = c*sqrt(3)/2*j``; column ``q`` holds ``x = c*(q - I + (j mod 2)/2)``, so odd
rows are shifted by half a step. The last column of an odd row lies outside the
symmetric rectangle and is masked out. A rectangular candidate region therefore
fills its array with no waste, which keeps the FFT convolution of
:mod:`bem.operator` as small as the problem.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .checks import InputError, check_node_count, check_positive, check_scale

__all__ = ["Lattice", "LatticeWindow", "SQRT3", "node_count", "extent_pair"]

SQRT3 = math.sqrt(3.0)


def extent_pair(name, extent):
    """``(ex, ey)`` [length] of a half-width given as one number or a pair; InputError naming ``name``."""
    if np.ndim(extent) == 0:
        ex = ey = extent
    else:
        try:
            ex, ey = extent
        except (TypeError, ValueError):
            raise InputError(f"{name} = {extent!r} is not allowed: it must be a number or a pair (ex, ey).") from None
    return check_positive(name, ex), check_positive(name, ey)


def _half_counts(step, ex, ey):
    """``(I, J)``: half the columns and rows of the region ``|x| <= ex``, ``|y| <= ey`` (floats, may be huge)."""
    return (math.floor(min(ex / step, 1e300) + 1e-9), math.floor(min(ey / (step * SQRT3 / 2), 1e300) + 1e-9))


def node_count(step, extent):
    """Number of nodes of the brick array of ``step`` on the candidate region ``extent`` [length]
    (:meth:`Lattice.from_extent`: the candidate nodes and the masked ends of odd rows), computed
    without building it."""
    half_cols, half_rows = _half_counts(step, *extent_pair("extent", extent))
    return (2 * half_cols + 1) * (2 * half_rows + 1)


@dataclass(frozen=True)
class Lattice:
    """Brick-stored triangular lattice covering a rectangular candidate region.

    Parameters
    ----------
    step : float
        Lattice step ``c`` [length].
    half_cols : int
        ``I``: even rows hold ``x = c*i`` for ``i = -I..I``.
    half_rows : int
        ``J``: rows ``j = -J..J``.
    """

    step: float
    half_cols: int
    half_rows: int

    @classmethod
    def from_extent(cls, step, extent):
        """Lattice of step ``step`` covering ``|x| <= ex``, ``|y| <= ey``.

        Parameters
        ----------
        step : float
            Lattice step ``c`` [length], a physical scale (:data:`bem.checks.SCALE_RANGE`).
        extent : float or (float, float)
            Half-width of the candidate region [length]: one number for a square,
            ``(ex, ey)`` for a rectangle. At least two steps each way, and at most
            :func:`bem.checks.max_nodes` nodes in all.
        """
        step = check_scale("step", step)
        ex, ey = extent_pair("extent", extent)
        half_cols, half_rows = _half_counts(step, ex, ey)
        if half_cols < 2 or half_rows < 2:
            raise InputError(
                f"extent = {extent!r} is not allowed with step = {step!r}: "
                "it must span at least 2 steps each way (make extent larger or step smaller)."
            )
        check_node_count("step", step, node_count(step, (ex, ey)))
        return cls(step, int(half_cols), int(half_rows))

    @property
    def shape(self):
        """Shape ``(n_rows, n_cols)`` of the brick array."""
        return (2 * self.half_rows + 1, 2 * self.half_cols + 1)

    @property
    def node_area(self):
        """Quadrature weight of a node, the pyramid volume ``sqrt(3)/2 c^2`` (eq. 9, 11)."""
        return SQRT3 / 2 * self.step**2

    @cached_property
    def j(self):
        """Lattice row index ``j`` of each brick row, shape ``(n_rows,)``."""
        return np.arange(-self.half_rows, self.half_rows + 1)

    @cached_property
    def parity(self):
        """``j mod 2`` of each brick row, shape ``(n_rows,)``."""
        return np.mod(self.j, 2)

    @cached_property
    def x(self):
        """Node abscissae [length], shape :attr:`shape`."""
        q = np.arange(-self.half_cols, self.half_cols + 1)
        return self.step * (q[None, :] + 0.5 * self.parity[:, None])

    @cached_property
    def y(self):
        """Node ordinates [length], shape :attr:`shape`."""
        row = self.step * SQRT3 / 2 * self.j
        return np.broadcast_to(row[:, None], self.shape).copy()

    def release_coordinates(self):
        """Drop the cached :attr:`x` and :attr:`y` (16 bytes a node); they are made again when asked for."""
        for name in ("x", "y"):
            self.__dict__.pop(name, None)

    @cached_property
    def mask(self):
        """Candidate nodes (inside the symmetric rectangle), shape :attr:`shape`."""
        m = np.ones(self.shape, dtype=bool)
        m[self.parity == 1, -1] = False
        return m

    @cached_property
    def border(self):
        """Candidate nodes on the border of the region, shape :attr:`shape`."""
        b = np.zeros(self.shape, dtype=bool)
        b[0, :] = b[-1, :] = True
        b[:, 0] = True
        b[self.parity == 0, -1] = True
        b[self.parity == 1, -2] = True
        return b & self.mask

    @property
    def n_nodes(self):
        """Number of candidate nodes."""
        return int(self.mask.sum())

    def window(self, rows, cols):
        """The block ``rows x cols`` (two ``(start, stop)`` ranges) of the brick array: a :class:`LatticeWindow`.

        At least two rows, so that both row parities are present.
        """
        (r0, r1), (c0, c1) = rows, cols
        n_rows, n_cols = self.shape
        if not (0 <= r0 and r0 + 2 <= r1 <= n_rows and 0 <= c0 < c1 <= n_cols):
            raise InputError(f"rows = {rows!r}, cols = {cols!r} is not allowed: they must be ranges within the "
                             f"brick array of shape {self.shape}, at least 2 rows (one of each parity).")
        return LatticeWindow(self, (int(r0), int(r1)), (int(c0), int(c1)))

    def coarsen(self):
        """The lattice of step ``2c`` whose nodes are every other node of this one.

        Returns ``None`` when the coarse lattice would have fewer than 2 steps
        each way.
        """
        hc, hr = self.half_cols // 2, self.half_rows // 2
        if hc < 2 or hr < 2:
            return None
        return Lattice(2 * self.step, hc, hr)

    def prolong(self, values, fine):
        """The piecewise-linear field of ``values`` at the nodes of ``fine``, with ``fine.coarsen() == self``.

        Equal to ``self.interpolate(values, fine.x, fine.y) * fine.mask`` (to round-off), but
        built row by row from the structure: a fine node is a coarse node or the midpoint of a
        coarse edge, so it takes a coarse value or the mean of two (0 outside this lattice);
        several times faster than :meth:`interpolate` (``docs/performance.md``).

        Parameters
        ----------
        values : ndarray, shape :attr:`shape`
            Nodal values of this (coarse) lattice.
        fine : Lattice
            The lattice of half the step whose :meth:`coarsen` is this one.

        Returns
        -------
        ndarray, shape ``fine.shape``
        """
        values = np.asarray(values, dtype=float)
        if values.shape != self.shape:
            raise InputError(f"values has shape {values.shape} which is not allowed: it must be {self.shape}.")
        if fine.coarsen() != self:
            raise InputError(f"fine = {fine!r} is not allowed: its coarsen() must be this lattice ({self!r}).")
        out = np.empty(fine.shape)
        n_fine = fine.shape[1]
        for r, j_f in enumerate(fine.j):
            j_f = int(j_f)
            i_f0 = -fine.half_cols - (j_f >> 1)  # lattice column of brick column 0 of this fine row
            i0 = (i_f0 >> 1) - 1  # coarse columns i0 .. i0 + n cover the row and one neighbour each side
            n = n_fine // 2 + 3
            doubled = np.empty(2 * n)  # field at i_f = 2 i0 + k, k = 0 .. 2n-1
            if j_f % 2 == 0:  # on coarse row j: nodes, and midpoints of horizontal edges
                a = self._row(values, j_f >> 1, i0, n + 1)
                doubled[0::2] = a[:-1]
                doubled[1::2] = 0.5 * (a[:-1] + a[1:])
            else:  # between coarse rows j and j + 1: midpoints of the e2 edges and of the diagonals
                a = self._row(values, j_f >> 1, i0, n + 1)
                b = self._row(values, (j_f >> 1) + 1, i0, n + 1)
                doubled[0::2] = 0.5 * (a[:-1] + b[:-1])  # (i, j) - (i, j + 1)
                doubled[1::2] = 0.5 * (a[1:] + b[:-1])  # (i + 1, j) - (i, j + 1)
            out[r] = doubled[i_f0 - 2 * i0 : i_f0 - 2 * i0 + n_fine]
        out[~fine.mask] = 0.0
        return out

    def _row(self, values, j, i0, n):
        """Values of lattice row ``j`` at lattice columns ``i0 .. i0 + n - 1``; 0 off this lattice."""
        row = np.zeros(n)
        if -self.half_rows <= j <= self.half_rows:
            q0 = i0 + self.half_cols + (j >> 1)  # brick column of lattice column i0
            lo, hi = max(q0, 0), min(q0 + n, self.shape[1])
            if lo < hi:
                row[lo - q0 : hi - q0] = values[j + self.half_rows, lo:hi]
        return row

    def interpolate(self, values, x, y):
        """Evaluate the piecewise-linear field ``sum values_n * pyramid_n`` at points.

        Parameters
        ----------
        values : ndarray, shape :attr:`shape`
            Nodal values (masked nodes are read as they are; keep them 0).
        x, y : array_like
            Points [length], any broadcastable shapes. Points outside the lattice
            get 0 (the field vanishes outside the candidate region).

        Returns
        -------
        ndarray
            The field at the points (linear interpolation on the triangles).
        """
        values = np.asarray(values, dtype=float)
        if values.shape != self.shape:
            raise InputError(f"values has shape {values.shape} which is not allowed: it must be {self.shape}.")
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        c = self.step
        # sheared (lattice) coordinates: point = c*(s*e1 + t*e2); cell corner (i0, j0), fractions (fs, ft)
        t = y / (c * SQRT3 / 2)
        s = x / c - t / 2
        i0, j0 = np.floor(s), np.floor(t)
        fs, ft = s - i0, t - j0
        upper = fs + ft > 1.0
        # barycentric weights of B = (i0+1, j0) and C = (i0, j0+1); A is (i0, j0), or (i0+1, j0+1) if upper
        w_b = np.where(upper, 1.0 - ft, fs)
        w_c = np.where(upper, 1.0 - fs, ft)
        w_a = np.where(upper, fs + ft - 1.0, 1.0 - fs - ft)
        # Gather from a copy with a border of zeros: an index clipped onto the border reads 0, so
        # points outside the lattice need no mask. Index arithmetic in float64 (exact for these
        # integers; numpy's integer clip is 10x slower than its float clip); measured 2.7e6
        # points, same process, alternating: 0.17 s against 0.22-0.34 s with boolean-mask
        # sampling. Lattice nodes of half the step go faster through :meth:`prolong`.
        n_rows, n_cols = self.shape
        padded = np.zeros((n_rows + 2, n_cols + 2))
        padded[1:-1, 1:-1] = values
        flat = padded.ravel()
        row_b = np.clip(j0 + (self.half_rows + 1), 0, n_rows + 1)  # padded row of B, and of A when lower
        row_c = np.clip(j0 + (self.half_rows + 2), 0, n_rows + 1)  # padded row of C, and of A when upper
        half = np.floor(j0 * 0.5)  # floor(j0 / 2): brick column of lattice column i is i + I + floor(j/2)
        col_a = i0 + half + (self.half_cols + 1)  # padded column of A when lower
        col_c = col_a + (j0 - 2 * half)  # floor((j0 + 1) / 2) = floor(j0 / 2) + (j0 mod 2)
        stride = float(n_cols + 2)
        out = np.zeros(w_a.shape)
        for w, row, col in ((w_a, np.where(upper, row_c, row_b), np.where(upper, col_c + 1, col_a)),
                            (w_b, row_b, col_a + 1), (w_c, row_c, col_c)):
            np.clip(col, 0, n_cols + 1, out=col)
            idx = row * stride + col
            out += w * flat.take(idx.astype(np.int64))
        return out


@dataclass(frozen=True)
class LatticeWindow:
    """A rectangular block of rows and columns of a :class:`Lattice`'s brick array.

    ``C`` depends only on the offset between two nodes, so the influence operator of the
    nodes in a window is the operator of a lattice of the window's shape whose first row
    has the window's parity: :class:`bem.operator.InfluenceOperator` takes a window
    wherever it takes a lattice, and so do the solvers. :func:`bem.solve` runs them on the
    window of the nodes whose gap can close (see there); arrays of the window are
    brick arrays of :attr:`shape`, :meth:`embed` puts them back on the parent.

    Parameters
    ----------
    parent : Lattice
        The full lattice.
    rows, cols : (int, int)
        Brick rows ``start .. stop - 1`` and columns ``start .. stop - 1`` of the parent.
    """

    parent: Lattice
    rows: tuple
    cols: tuple

    @property
    def index(self):
        """The window as an index into a parent brick array."""
        return slice(*self.rows), slice(*self.cols)

    @property
    def step(self):
        return self.parent.step

    @property
    def shape(self):
        return (self.rows[1] - self.rows[0], self.cols[1] - self.cols[0])

    @property
    def node_area(self):
        return self.parent.node_area

    @cached_property
    def j(self):
        return self.parent.j[slice(*self.rows)]

    @cached_property
    def parity(self):
        return self.parent.parity[slice(*self.rows)]

    @cached_property
    def x(self):
        return self.parent.x[self.index].copy()

    @cached_property
    def y(self):
        return self.parent.y[self.index].copy()

    @cached_property
    def mask(self):
        return self.parent.mask[self.index].copy()

    @cached_property
    def border(self):
        """Nodes of the parent's border inside the window (not the window's own edge)."""
        return self.parent.border[self.index].copy()

    @property
    def n_nodes(self):
        return int(self.mask.sum())

    def embed(self, values):
        """A parent brick array holding ``values`` (shape :attr:`shape`) in the window, 0 elsewhere."""
        from .backend import backend_of

        bk = backend_of(values)  # a device array stays on its device
        out = bk.xp.zeros(self.parent.shape, dtype=bk.float64)
        out[self.index] = values
        return out
