"""A periodic height grid resampled onto the periodic triangular lattice.

The periodic lattice cell holds ``n_cols x n_rows`` nodes (``n_rows`` even) of step ``c``; its
size is ``Lx = n_cols c``, ``Ly = n_rows c sqrt(3)/2``; node ``(q, r)`` sits at

    x = (q + (r mod 2)/2) c,        y = r c sqrt(3)/2,

and the heights are stored in an array of shape ``(n_rows, n_cols)`` (row ``r``, column ``q``).

The data is one period ``(Lx_d, Ly_d)`` of a surface on a regular rectangular grid,
``z[i, j]`` at ``(i Lx_d/nx, j Ly_d/ny)``. Its trigonometric interpolant is

    p(x, y) = 1/(nx ny) sum_k w_k Z_k exp(2 pi i (kx x/Lx_d + ky y/Ly_d)),

``Z = fft2(z)``, ``kx`` in ``-nx/2..nx/2`` (``ky`` alike), with the Nyquist coefficient of an
even length split in two halves ``w = 1/2`` at ``+n/2`` and ``-n/2`` (the interpolant of least
oscillation). The lattice heights are the values of ``p`` limited to the wave numbers the
lattice carries, ``|kx| <= n_cols/2`` and ``|ky| <= n_rows/2``: on a finer lattice exactly the
interpolant, on a coarser one the interpolant without its shorter wavelengths (a band-limited,
not an aliased, sample). A sinusoid of integer wave numbers within both bands is reproduced
exactly. Each axis costs one FFT and one inverse FFT of the target length; the half step of
the odd rows is a phase factor ``exp(i pi kx/n_cols)``.

An equilateral lattice cannot take every aspect ratio: ``c = Lx_d/n_cols``, and ``n_rows`` is
the even integer nearest to ``Ly_d/(c sqrt(3)/2)`` (at least 2). The data's period ``Ly_d``
is mapped onto ``Ly``: lattice row ``r`` takes the data at ``y_d = r Ly_d/n_rows``, a stretch
of ``y`` by ``stretch_y = Ly/Ly_d`` (slopes along ``y`` divide by it, heights do not change).
A stretch beyond :data:`MAX_STRETCH` (``|stretch_y - 1| > 0.01``) is logged as a warning
and flagged in the result. The nearest even ``n_rows`` bounds it,
``|stretch_y - 1| <= sqrt(3) Lx_d/(2 n_cols Ly_d)``; an ``n_cols`` for which
``2 n_cols Ly_d/(sqrt(3) Lx_d)`` is close to an even integer makes it small.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_finite_array, check_int, check_node_count, check_positive, fail
from ..periodic.cell import rows_for

__all__ = ["LatticeHeights", "to_lattice", "cell_shape", "MAX_STRETCH"]

log = logging.getLogger(__name__)

#: largest ``|stretch_y - 1|`` accepted without a warning (1 % along y)
MAX_STRETCH = 0.01
_SQRT3 = math.sqrt(3.0)


@dataclass(frozen=True)
class LatticeHeights:
    """Heights on one periodic cell of the triangular lattice (module docstring).

    Attributes
    ----------
    heights : ndarray
        Shape ``(n_rows, n_cols)``: the height at node ``(q, r)`` in ``heights[r, q]`` [length].
    step : float
        Lattice step ``c`` [length].
    n_rows, n_cols : int
        Nodes of the cell along y (even) and x.
    size : (float, float)
        The cell ``(Lx, Ly) = (n_cols c, n_rows c sqrt(3)/2)`` [length].
    data_size : (float, float)
        The data's period ``(Lx_d, Ly_d)`` [length].
    stretch_y : float
        ``Ly/Ly_d`` [-]: the data is stretched by this factor along y.
    stretch_large : bool
        ``|stretch_y - 1| > MAX_STRETCH`` (logged as a warning).
    """

    heights: np.ndarray
    step: float
    n_rows: int
    n_cols: int
    size: tuple
    data_size: tuple
    stretch_y: float
    stretch_large: bool

    def gap(self):
        """The initial gap ``h = max z - z`` against a flat [length], shape ``(n_rows, n_cols)``.

        The heights are those of a surface measured outwards (summits positive); the highest
        node touches first (``h = 0`` there), as for a measured topography over a region
        (:class:`bem.gaps.Measured`).
        """
        return self.heights.max() - self.heights

    def positions(self):
        """Node coordinates ``(x, y)`` [length], each of shape ``(n_rows, n_cols)``."""
        r, q = np.mgrid[0:self.n_rows, 0:self.n_cols]
        return (q + 0.5 * (r % 2)) * self.step, r * self.step * _SQRT3 / 2


def _resample_axis(values, target, shift=0.0):
    """Band-limited values of the periodic samples ``values`` (along axis 0) at ``target`` points.

    The points are ``t_m = (m + shift) n/target`` in units of the source spacing,
    ``m = 0..target-1``; wave numbers ``|k| <= target/2`` are kept (module docstring).
    """
    n = values.shape[0]
    spectrum = np.fft.fft(values, axis=0)
    k = np.rint(np.fft.fftfreq(n, 1.0 / n)).astype(int)
    source = np.arange(n)
    weight = np.ones(n)
    if n % 2 == 0:  # the Nyquist coefficient, split between +n/2 and -n/2
        k, source, weight = np.append(k, n // 2), np.append(source, n // 2), np.append(weight, 0.5)
        weight[n // 2] = 0.5
    keep = np.abs(k) <= target / 2
    factor = (target / n) * weight[keep] * np.exp(2j * np.pi * k[keep] * shift / target)
    out = np.zeros((target,) + values.shape[1:], dtype=complex)
    np.add.at(out, k[keep] % target, spectrum[source[keep]] * factor.reshape((-1,) + (1,) * (values.ndim - 1)))
    return np.fft.ifft(out, axis=0).real


def _size(size):
    if not isinstance(size, (list, tuple, np.ndarray)) or len(size) != 2:
        fail("size", size, "a pair (Lx, Ly) of lengths")
    return check_positive("size[0]", size[0]), check_positive("size[1]", size[1])


def cell_shape(size, n_cols):
    """The shape ``(n_rows, n_cols)`` of the cell of :func:`to_lattice`, counted without building it.

    Parameters
    ----------
    size : (float, float)
        The period ``(Lx_d, Ly_d)`` of the height grid [length], each ``> 0``.
    n_cols : int
        Nodes of the cell along x, ``>= 2``.
    """
    lx, ly = _size(size)
    n_cols = check_int("n_cols", n_cols, minimum=2)
    return rows_for(lx / n_cols, ly), n_cols


def to_lattice(heights, size, n_cols):
    """Resample one period of a height grid onto the periodic triangular lattice.

    Parameters
    ----------
    heights : array_like
        ``z[i, j]`` at ``(x, y) = (i Lx_d/nx, j Ly_d/ny)`` [length], shape ``(nx, ny)``, at
        least ``2 x 2``, finite; one period of a periodic surface. Not modified.
    size : (float, float)
        The period ``(Lx_d, Ly_d)`` [length], each ``> 0``.
    n_cols : int
        Nodes of the cell along x, ``>= 2``; the step is ``c = Lx_d/n_cols``. The cell holds at
        most :func:`bem.checks.max_nodes` nodes (checked before it is built).

    Returns
    -------
    LatticeHeights
        The ``(n_rows, n_cols)`` heights, the step, the cell and the stretch along y
        (module docstring).

    Raises
    ------
    bem.InputError
        A bad argument; the message starts with its name.
    """
    z = check_finite_array("heights", heights, ndim=2)
    if min(z.shape) < 2:
        fail("heights.shape", z.shape, "at least (2, 2)")
    lx, ly = _size(size)
    n_rows, n_cols = cell_shape((lx, ly), n_cols)
    check_node_count("n_cols", n_cols, n_rows * n_cols, what="the periodic cell")
    step = lx / n_cols
    cell = (n_cols * step, n_rows * step * _SQRT3 / 2)
    stretch = cell[1] / ly
    large = abs(stretch - 1.0) > MAX_STRETCH
    if large:
        log.warning("the lattice cell stretches the data along y by %.4f (|stretch - 1| > %g): n_cols = %d gives "
                    "n_rows = %d for Ly/Lx = %.6g; an n_cols for which 2 n_cols Ly/(sqrt(3) Lx) is close to an even "
                    "integer stretches less", stretch, MAX_STRETCH, n_cols, n_rows, ly / lx)
    rows = _resample_axis(z.T, n_rows)  # (n_rows, nx): y first
    out = np.empty((n_rows, n_cols))
    out[0::2] = _resample_axis(rows[0::2].T, n_cols).T
    out[1::2] = _resample_axis(rows[1::2].T, n_cols, shift=0.5).T
    return LatticeHeights(out, step, n_rows, n_cols, cell, (lx, ly), stretch, large)
