"""The 2 x 2 block convolution of :class:`bem.InfluenceOperator` on NumPy, by bands of spectrum columns.

The convolution of a pair of parity lattices, ``out_a = crop(F^-1 sum_b S_ab F pad(v_b))``
(:mod:`bem.block_symbol`), transforms the rows of ``v_b`` (real to complex), then the columns of the
padded array, multiplies by the symbol, and inverts in the reverse order. Every column of the half spectrum
is independent of the others between the two row transforms: here the columns are taken a band of
:func:`band_columns` at a time, each band zero-padded to ``Lk`` rows, transformed, multiplied and inverted while it
sits in the cache, and only the rows that are read (``max(rows in, rows out)``, not ``Lk``) are held for the
whole spectrum. The numbers are those of the whole-array path, operation for operation
(``tests/bem/test_column_bands.py``); on the benchmark sphere of ``benchmarks/cases.py`` the product of
``C`` with a direction takes less time from about 1M nodes and holds a spectrum of about half the rows
(``docs/performance.md``, "The products by bands of columns"). Up to :data:`BANDS_ABOVE` bytes of the whole
spectrum pair (which the caches of the machine measured there hold) the operator keeps the whole-array path, which
was faster there.
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft

from . import fft

__all__ = ["BANDS_ABOVE", "band_columns", "convolve_by_bands"]

#: bytes of the whole padded spectrum pair above which :class:`bem.InfluenceOperator` convolves by bands
BANDS_ABOVE = 16 << 20
_BAND_BYTES = 1 << 20  # bytes of a band of the padded pair: it and its product stay in the cache
_ROW_BAND = 1 << 19  # entries of the bands of rows transformed at once


def band_columns(lk, itemsize):
    """Columns of a band: a pair of ``lk``-row complex columns of ``itemsize`` bytes, about ``_BAND_BYTES``,
    at least 4."""
    return max(4, _BAND_BYTES // (2 * lk * itemsize))


def convolve_by_bands(S, shape, parts, dests, dtype=np.float64):
    """``dests[a] = crop(sum_b S_ab v_b)`` for the pair of parity arrays ``parts``, by bands of columns.

    Parameters
    ----------
    S : tuple or ndarray
        The symbol: ``((S_00, S_01), (S_10, S_11))`` or an array ``S[a, b]`` of :func:`bem.block_symbol.kernel_spectra`,
        or a Hermitian one ``((S_00, S_01), (None, S_11))`` (``S_10 = conj(S_01)``), each ``(Lk, Lq // 2 + 1)``.
    shape : (int, int)
        The padded size ``(Lk, Lq)``.
    parts : sequence of two ndarray
        The real input of each parity, ``(rows_b, cols_b)`` (views allowed; not modified), ``rows_b <= Lk``.
    dests : sequence of two ndarray
        The output of each parity, ``(rows_a, cols_a)`` views, written with the rows and columns from the origin of
        the inverse transform, without its ``1 / (Lk Lq)`` (the symbol carries it).
    dtype : numpy dtype
        ``float64``, or ``float32``: the transforms in single precision (the symbol then single precision too).
    """
    lk, lq = shape
    n_half = lq // 2 + 1
    if not isinstance(S, tuple):
        S = ((S[0, 0], S[0, 1]), (S[1, 0], S[1, 1]))
    conj = S[1][0] is None
    rows_in = [x.shape[0] for x in parts]
    rows_out = [d.shape[0] for d in dests]
    cdtype = np.result_type(dtype, np.complex64)
    half = np.empty((2, max(rows_in + rows_out), n_half), dtype=cdtype)  # the row spectra, then the products
    for b, x in enumerate(parts):
        _rows(lambda y: sfft.rfft(y.astype(dtype, copy=False), n=lq, axis=-1, workers=1), x, half[b, : rows_in[b]])
    width = band_columns(lk, np.dtype(cdtype).itemsize)

    def bands(part):  # the bands of columns of a part, on the threads of bem.fft.in_parts
        pair = np.empty((2, lk, width), dtype=cdtype)
        t, w = np.empty((lk, width), dtype=cdtype), np.empty((lk, width), dtype=cdtype)
        for band in range(part.start, part.stop):
            c = slice(band * width, min(n_half, band * width + width))
            n = c.stop - c.start
            x = pair[:, :, :n]
            for b in range(2):
                x[b, : rows_in[b]] = half[b, : rows_in[b], c]
                x[b, rows_in[b] :] = 0.0
            fft.cfft_in_place(x, 1, None)
            v0, v1 = x[0], x[1]
            np.multiply(S[0][1][:, c], v1, out=t[:, :n])
            v1 *= S[1][1][:, c]
            if conj:
                np.conjugate(S[0][1][:, c], out=w[:, :n])
                w[:, :n] *= v0
            else:
                np.multiply(S[1][0][:, c], v0, out=w[:, :n])
            v1 += w[:, :n]
            v0 *= S[0][0][:, c]
            v0 += t[:, :n]
            fft.cfft_in_place(x, 1, None, inverse=True, normalise=False)
            for a in range(2):
                half[a, : rows_out[a], c] = x[a, : rows_out[a]]

    fft.in_parts(bands, -(-n_half // width), half.size)
    for a, dest in enumerate(dests):
        cols = dest.shape[1]
        _rows(lambda y: sfft.irfft(y, n=lq, axis=-1, norm="forward", workers=1)[:, :cols], half[a, : rows_out[a]],
              dest)


def _rows(transform, src, dest):
    """``dest[i] = transform(src[i])`` for contiguous parts ``i`` of the rows, on the threads of
    :func:`bem.fft.in_parts`, by bands of about ``_ROW_BAND`` entries (the temporaries are a band's)."""
    band = max(1, _ROW_BAND // max(1, dest.shape[1]))
    for lo in range(0, dest.shape[0], band):
        s, d = src[lo : lo + band], dest[lo : lo + band]
        fft.in_parts(lambda i: d.__setitem__(i, transform(s[i])), d.shape[0], d.size)
