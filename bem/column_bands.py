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

A product with input on a window and output on the whole region has a symbol of four complex blocks. Where the
window holds the same rows of both parities the kernel between the parities is one kernel shifted by a row and a
column, and that within a parity is the same for both: :func:`paired_spectra` keeps two blocks and the phase of the
shift (:class:`PairedSymbol`), half the memory and half the bytes a product reads, at the same padding.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import fft, heap, pruned_fft
from .block_symbol import padded_kernel

__all__ = ["BANDS_ABOVE", "PairedSymbol", "band_columns", "convolve_by_bands", "paired_spectra"]

#: bytes of the whole padded spectrum pair above which :class:`bem.InfluenceOperator` convolves by bands
BANDS_ABOVE = 16 << 20
_BAND_BYTES = 1 << 20  # bytes of a band of the padded pair: it and its product stay in the cache


def band_columns(lk, itemsize):
    """Columns of a band: a pair of ``lk``-row complex columns of ``itemsize`` bytes, about ``_BAND_BYTES``,
    at least 4."""
    return max(4, _BAND_BYTES // (2 * lk * itemsize))


@dataclass(frozen=True)
class PairedSymbol:
    """The symbol of a window onto the whole region as two blocks: ``S_00 = S_11`` (``same``), ``S_01`` (``cross``)
    and ``S_10 = S_01 exp(2 pi i (sigma k / Lk + q / Lq))`` (``row_phase[k] col_phase[q]``, ``sigma`` the first brick
    row of the odd parity less that of the even one), each ``(Lk, Lq // 2 + 1)`` [the units of the coefficient table,
    divided by ``Lk Lq``]."""

    same: np.ndarray
    cross: np.ndarray
    row_phase: np.ndarray
    col_phase: np.ndarray


def paired_spectra(table, start, n_rows, n_cols, box):
    """``(shape, PairedSymbol)`` for input on ``box``, whose parities hold the same rows, and output on the whole
    region.

    With the input rows ``ib .. ib + nb - 1`` of both parities and the output on every row (``n_rows[a]`` of parity
    ``a``), the kernel within a parity is the same for both, at brick-row offset ``2 (e - ib)`` for the parity-row
    offset ``e``; between them it is at ``-sigma + 2 (e - ib)`` from parity 0 to 1 and ``sigma + 2 (e - ib)`` from 1
    to 0 (``sigma = start[1] - start[0]``), and at the table column ``(|2 dq -+ 1| - 1) // 2``: the kernel from 1 to 0
    is that from 0 to 1 shifted by ``sigma`` rows and one column. Both are stored over the offsets of either (rows
    ``-(nb - 1) .. max(n_rows) - 1`` widened by one on the side of ``sigma``, columns ``-(cols - 1) .. n_cols``:
    padding ``max(n_rows) + nb`` by ``n_cols + cols``, so that no offset wraps onto another); offsets that no product
    meets take the table's last entries.

    Parameters
    ----------
    table : ndarray
        The influence coefficients at every lattice offset (:class:`bem.InfluenceOperator`).
    start : (int, int)
        The first brick row of each parity.
    n_rows : (int, int)
        Rows of each parity of the region.
    n_cols : int
        Columns of the region.
    box : tuple
        The input's box ``(((k0_even, rows_even), (k0_odd, rows_odd)), (q0, cols))`` in parity rows and columns.
    """
    (first, second), (iq, bq) = box
    if first != second:
        raise ValueError(f"box = {box!r}: both parities must hold the same rows")
    ib, nb = first
    sigma = start[1] - start[0]
    na = max(n_rows)
    lk, lq = fft.fast_length(na + nb, real=False), fft.fast_length(n_cols + bq, real=True)
    rows, cols = (na + (sigma > 0), nb - 1 + (sigma < 0)), (n_cols + 1, bq - 1)
    blocks = []
    for a, b in ((0, 0), (0, 1)):
        kernel = padded_kernel(table, start, a, b, rows, cols, (-ib, -iq), (lk, lq), clip=True)
        kernel /= lk * lq
        blocks.append(pruned_fft.forward(kernel, (lk, lq)))
        del kernel
    k, q = np.arange(lk), np.arange(lq // 2 + 1)
    row_phase = np.exp(2j * np.pi * (k * sigma % lk) / lk)
    col_phase = np.exp(2j * np.pi * q / lq)
    return (lk, lq), PairedSymbol(blocks[0], blocks[1], row_phase, col_phase)


def convolve_by_bands(S, shape, parts, dests, dtype=np.float64):
    """``dests[a] = crop(sum_b S_ab v_b)`` for the pair of parity arrays ``parts``, by bands of columns.

    Parameters
    ----------
    S : tuple, ndarray or PairedSymbol
        The symbol: ``((S_00, S_01), (S_10, S_11))`` or an array ``S[a, b]`` of :func:`bem.block_symbol.kernel_spectra`,
        a Hermitian one ``((S_00, S_01), (None, S_11))`` (``S_10 = conj(S_01)``), each ``(Lk, Lq // 2 + 1)``, or the
        two blocks and the phase of :func:`paired_spectra`.
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
    paired = isinstance(S, PairedSymbol)
    if not (paired or isinstance(S, tuple)):
        S = ((S[0, 0], S[0, 1]), (S[1, 0], S[1, 1]))
    conj = not paired and S[1][0] is None
    rows_in = [x.shape[0] for x in parts]
    rows_out = [d.shape[0] for d in dests]
    cdtype = np.result_type(dtype, np.complex64)
    shape_half = (2, max(rows_in + rows_out), n_half)
    heap.release(np.dtype(cdtype).itemsize * int(np.prod(shape_half)))  # no freed blocks of the heap beside it
    half = np.empty(shape_half, dtype=cdtype)  # the row spectra, then the products
    for b, x in enumerate(parts):
        pruned_fft.rfft_rows(x, half[b, : rows_in[b]], lq, dtype)
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
            cross = S.cross[:, c] if paired else S[0][1][:, c]
            np.multiply(cross, v1, out=t[:, :n])
            if paired:  # S_10 = S_01 times the phase of the shift
                np.multiply(cross, v0, out=w[:, :n])
                w[:, :n] *= S.row_phase[:, None]
                w[:, :n] *= S.col_phase[c]
            elif conj:
                np.conjugate(cross, out=w[:, :n])
                w[:, :n] *= v0
            else:
                np.multiply(S[1][0][:, c], v0, out=w[:, :n])
            v1 *= S.same[:, c] if paired else S[1][1][:, c]
            v1 += w[:, :n]
            v0 *= S.same[:, c] if paired else S[0][0][:, c]
            v0 += t[:, :n]
            fft.cfft_in_place(x, 1, None, inverse=True, normalise=False)
            for a in range(2):
                half[a, : rows_out[a], c] = x[a, : rows_out[a]]

    fft.in_parts(bands, -(-n_half // width), half.size)
    for a, dest in enumerate(dests):
        pruned_fft.irfft_rows(half[a, : rows_out[a]], dest, lq)
