"""Pruned padded transforms: the two halves of the half-space's zero-padded convolutions.

:func:`forward` and :func:`inverse` are the two halves of a zero-padded (non-periodic) convolution of a batch
of real 2-D arrays. The real FFT along the last axis runs only over the rows that hold data (forward) or are
kept (inverse); the complex FFT along the first data axis does the zero padding. Against a plain
``rfft2``/``irfft2`` pair of the padded size this skips the transforms of the zero rows (about 25 % of the
work when the data fill half the padded rows). The real transforms run in bands of rows (:data:`_BAND`
entries), written into the padded spectrum or the output as they are made, so that no whole unpadded spectrum
or padded input is held beside them; :func:`forward_parts` and :func:`inverse_into` take the batch as its
entries (strided views of a brick array's row parities) and write the product where it goes (no gathered
copy). Banded or not, the numbers are the same (``tests/bem/test_pruned_fft.py``).

Every transform runs on the threads of :func:`bem.fft.in_parts`, one single-threaded call of the transform's library
per band (:func:`bem.fft.rfft_into`, :func:`bem.fft.cfft_in_place`, :func:`bem.fft.irfft_into`). Each thread takes its
part of the rows a band after another through one buffer of its own, made once per transform: the band's rows
zero-padded in it (forward) or its whole inverse rows (inverse), the transform written from or into it where the
data lie (no padded copy and no output array a band).
"""

from __future__ import annotations

import numpy as np

from .checks import fail
from .fft import LINES, cfft_in_place, in_parts, irfft_into, rfft_into

__all__ = ["forward", "forward_parts", "inverse", "inverse_into", "rfft_rows", "irfft_rows"]

_BAND = 1 << 19  # entries of the bands of rows :func:`forward` and :func:`inverse` transform one after the other:
# their temporaries are a band's, not the whole array's (bands of fewer entries cost more calls than they save)


def forward(x, shape):
    """Spectrum of a batch of real arrays zero-padded to ``shape``.

    Parameters
    ----------
    x : ndarray, shape ``(..., rows, cols)``, float64
        Data; ``rows <= shape[0]``, ``cols <= shape[1]``. Not modified.
    shape : (int, int)
        Padded size ``(Lk, Lq)``.

    Returns
    -------
    ndarray, shape ``(..., Lk, Lq // 2 + 1)``, complex128
        Unnormalised 2-D DFT of the padded arrays.
    """
    lead = x.shape[:-2]
    spectra = forward_parts(x.reshape((-1,) + x.shape[-2:]), shape, x.dtype)
    return spectra.reshape(lead + spectra.shape[1:])


def _band(rows, size):
    """Rows of an array of ``size`` entries that a banded transform takes at once: all of them up to twice
    :data:`_BAND` entries, else bands of about :data:`_BAND` entries, a multiple of :data:`bem.fft.LINES` rows (at
    least that many: the bands begin where a transform's parts may)."""
    if size <= 2 * _BAND:
        return rows
    return min(rows, max(LINES, rows * _BAND // size // LINES * LINES))


def forward_parts(parts, shape, dtype=np.float64, scale=None, out=None):
    """:func:`forward` of a batch given as its entries: 2-D real arrays (views allowed, not modified), each
    zero-padded to ``shape`` and rounded to ``dtype`` band by band (no gathered copy of the batch).

    Parameters
    ----------
    parts : sequence of ndarray, shapes ``(rows_b, cols_b)``
        ``rows_b <= Lk``, ``cols_b <= Lq``.
    shape : (int, int)
        Padded size ``(Lk, Lq)``.
    dtype : numpy dtype
        ``float64``, or ``float32`` for a single-precision spectrum.
    scale : float, optional
        A factor applied to the data before it is rounded to ``dtype`` (band by band: no scaled copy of a part).
    out : ndarray, optional
        The array the spectra are written into (C-contiguous, of the returned shape and dtype); default: a new one.

    Returns
    -------
    ndarray, shape ``(len(parts), Lk, Lq // 2 + 1)``
        The spectra, complex128 (complex64 for ``float32``): ``out`` where given.
    """
    lk, lq = shape
    spectra = (len(parts), lk, lq // 2 + 1), np.result_type(dtype, np.complex64)
    if out is None:
        out = np.empty(*spectra)
    elif not (out.shape == spectra[0] and out.dtype == spectra[1] and out.flags.c_contiguous):
        fail("out", f"<array of shape {out.shape}, {out.dtype}>", f"a C-contiguous {spectra[1]} array of shape "
             f"{spectra[0]}")
    for b, x in enumerate(parts):
        out[b, x.shape[0] :, :] = 0.0  # the padding rows
        rfft_rows(x, out[b, : x.shape[0]], lq, dtype, scale, size=out[b].size)
    return cfft_in_place(out, 1, 2)


def rfft_rows(x, dest, n, dtype=np.float64, scale=None, size=None):
    """``dest`` = the real FFT of the rows of ``x`` (times ``scale``, rounded to ``dtype``) zero-padded to ``n``
    points, a band of rows after another (:func:`_band` of ``size`` entries, default ``dest.size``), in parts."""
    cols = x.shape[1]

    def band(buf, lo, hi):  # the rows lo:hi rounded into the zero-padded buf, transformed into dest
        if scale is None:
            buf[:, :cols] = x[lo:hi]
        else:
            np.multiply(x[lo:hi], scale, out=buf[:, :cols], casting="unsafe")
        rfft_into(buf, dest[lo:hi], 1, split=None)

    _in_bands(band, dest.shape[0], dest.size if size is None else size, n, dtype, zeroed=True)


def irfft_rows(x, dest, n):
    """``dest`` = the first ``dest.shape[1]`` points of the unnormalised inverse real FFT (``n`` points) of the rows
    of the half spectra ``x``, a band of rows after another, in parts."""

    def band(buf, lo, hi):
        irfft_into(x[lo:hi], buf, n, 1, split=None, normalise=False)
        dest[lo:hi] = buf[:, : dest.shape[1]]

    _in_bands(band, dest.shape[0], dest.size, n, x.real.dtype)


def _in_bands(band, rows, size, columns, dtype, zeroed=False):
    """``band(buf, lo, hi)`` on the bands ``lo:hi`` of :func:`_band` rows of an array of ``rows`` rows and ``size``
    entries: in parts of the rows (:func:`in_parts`), each part a band after another into one buffer ``buf`` of its
    own, ``columns`` wide, of ``dtype`` (``zeroed``: made of zeros), made once."""
    step = _band(rows, size)
    make = np.zeros if zeroed else np.empty

    def part(rows_part):
        buf = make((min(step, rows_part.stop - rows_part.start), columns), dtype=dtype)
        for lo in range(rows_part.start, rows_part.stop, step):
            hi = min(lo + step, rows_part.stop)
            band(buf[: hi - lo], lo, hi)

    in_parts(part, rows, size, align=LINES)


def inverse_into(spectrum, shape, dest):
    """:func:`inverse` of one spectrum written into ``dest`` (a view allowed; values cast to its dtype).

    Parameters
    ----------
    spectrum : ndarray, shape ``(Lk, Lq // 2 + 1)``
        Overwritten.
    shape : (int, int)
        Padded size ``(Lk, Lq)``.
    dest : ndarray, shape ``(rows, cols)``
        Receives the rows and columns kept from the origin, without the ``1 / (Lk Lq)`` factor.
    """
    cols = cfft_in_place(spectrum, 0, 1, inverse=True, normalise=False)
    irfft_rows(cols[: dest.shape[0]], dest, shape[1])


def inverse(spectrum, shape, keep):
    """Inverse of :func:`forward`, without the ``1 / (Lk Lq)`` factor, cropped.

    Parameters
    ----------
    spectrum : ndarray, shape ``(..., Lk, Lq // 2 + 1)``, complex128
        Overwritten.
    shape : (int, int)
        Padded size ``(Lk, Lq)``.
    keep : (int, int)
        Rows and columns kept from the origin.

    Returns
    -------
    ndarray, shape ``(..., keep[0], keep[1])``
        A fresh array; the caller scales it.
    """
    out = np.empty(spectrum.shape[:-2] + tuple(keep), dtype=spectrum.real.dtype)
    for entry, dest in zip(spectrum.reshape((-1,) + spectrum.shape[-2:]), out.reshape((-1,) + tuple(keep))):
        inverse_into(entry, shape, dest)
    return out
