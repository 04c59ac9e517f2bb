"""Products of the periodic cell's spectra on NumPy: the 2 x 2 block product of
:meth:`bem.periodic.PeriodicOperator.mix` by a :class:`bem.periodic.symbol.Symbol` and the inner product of two brick
arrays from their half spectra.

A spectrum has the layout of :meth:`bem.periodic.PeriodicOperator.spectrum`: ``(n_rows/2, 2, n_cols/2 + 1)``,
the real FFT along the rows of each row parity, then the FFT along the columns.
"""

from __future__ import annotations

import numpy as np

from .. import fft
from .passes import kernels

__all__ = ["mixed", "numpy_mixed", "weighted_dot"]


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
    """:meth:`bem.periodic.PeriodicOperator.mix` of ``spectrum`` by a :class:`bem.periodic.symbol.Symbol` into
    ``out``, block by block on threads (the symbol's blocks made as they are used, in the spectrum's precision); with
    ``even`` not None also the :func:`weighted_dot` of ``spectrum`` and ``out`` of each block of rows as it is made
    (``out`` must then not be ``spectrum``). Returns ``(out, sums)``, ``sums`` the blocks' sums in the order of the
    blocks (empty with ``even`` None).

    On a cell that takes the compiled passes (:mod:`bem.periodic.passes`) one compiled loop over each block makes
    the product and its sum, else :func:`numpy_mixed`. The compiled products round as NumPy's do without fused
    multiply-adds (NumPy's loops may fuse them: the two may differ in the last bit of single or double precision),
    and the sum of a block is taken in the order of its entries.
    """
    rows = max(1, fft.BLOCK // (spectrum.size // max(spectrum.shape[0], 1) or 1))
    compiled = kernels(2 * spectrum.size)  # a spectrum has about half as many entries as the cell has nodes
    return (compiled.mix if compiled.compiled else numpy_mixed)(spectrum, symbol, out, even, rows)


def numpy_mixed(spectrum, symbol, out, even, rows):
    """:func:`mixed` in NumPy, over blocks of ``rows`` rows: the block's symbol
    (:meth:`bem.periodic.symbol.Symbol.rows`), then three passes over the block (the product ``B X'`` in a buffer of
    one block), the sum by :func:`weighted_dot`."""
    sums = {}

    def part(s):  # rows s of every array: the parity swap stays inside a row
        work = np.empty((min(rows, s.stop - s.start),) + spectrum.shape[1:], dtype=spectrum.dtype)
        for lo in range(s.start, s.stop, rows):
            r = slice(lo, min(lo + rows, s.stop))
            w = work[:r.stop - lo]
            d, b = symbol.rows(r.start, r.stop)
            np.multiply(b, spectrum[r, ::-1, :], out=w)
            np.multiply(d, spectrum[r], out=out[r])
            np.add(out[r], w, out=out[r])
            if even is not None:
                sums[lo] = weighted_dot(spectrum[r], out[r], even)

    fft.in_parts(part, spectrum.shape[0], spectrum.size)
    return out, [sums[k] for k in sorted(sums)]
