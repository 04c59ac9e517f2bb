"""Products of the periodic cell's spectra on NumPy: the 2 x 2 block product of
:meth:`bem.periodic.PeriodicOperator.mix` and the inner product of two brick arrays from their half spectra.

A spectrum has the layout of :meth:`bem.periodic.PeriodicOperator.spectrum`: ``(n_rows/2, 2, n_cols/2 + 1)``,
the real FFT along the rows of each row parity, then the FFT along the columns.
"""

from __future__ import annotations

import numpy as np

from .. import fft

__all__ = ["mixed", "weighted_dot"]


def weighted_dot(x, y, even):
    """``sum Re conj(x) y`` over the full spectrum from the half spectra ``x``, ``y`` of real FFTs along the rows.

    The columns weigh as :func:`bem.fft.half_spectrum_weights` (``even``: ``n_cols`` even), here as twice the sum
    less the first and the Nyquist column (one ``einsum`` over the spectra, no weighted copy). Summed in double
    precision; times ``1 / (n_rows/2 n_cols)`` it is ``sum x y`` over the cell of the two brick arrays.
    """

    def dot(a, b):  # Re sum conj(a) b of two small arrays
        return float(np.sum(a.real * b.real + a.imag * b.imag, dtype=np.float64))

    real = x.real.dtype  # float32 for complex64 spectra, summed in double precision
    total = 2.0 * float(np.einsum("i,i->", x.view(real).reshape(-1), y.view(real).reshape(-1), dtype=np.float64))
    total -= dot(x[..., 0], y[..., 0])
    if even:
        total -= dot(x[..., -1], y[..., -1])
    return total


def mixed(spectrum, symbol, out, even):
    """:meth:`bem.periodic.PeriodicOperator.mix` of ``spectrum`` into ``out``, block by block on threads; with
    ``even`` not None also the :func:`weighted_dot` of ``spectrum`` and ``out`` of each block of rows as it is made
    (a dict by the block's first row; ``out`` must then not be ``spectrum``). Returns ``(out, sums)``."""
    d, b = symbol
    rows = max(1, fft.BLOCK // (spectrum.size // max(spectrum.shape[0], 1) or 1))
    sums = {}

    def part(s):  # rows s of every array: the parity swap stays inside a row
        work = np.empty((min(rows, s.stop - s.start),) + spectrum.shape[1:], dtype=spectrum.dtype)
        for lo in range(s.start, s.stop, rows):
            r = slice(lo, min(lo + rows, s.stop))
            w = work[:r.stop - lo]
            np.multiply(b[r], spectrum[r, ::-1, :], out=w)
            np.multiply(d[r], spectrum[r], out=out[r])
            np.add(out[r], w, out=out[r])
            if even is not None:
                sums[lo] = weighted_dot(spectrum[r], out[r], even)

    fft.in_parts(part, spectrum.shape[0], spectrum.size)
    return out, sums
