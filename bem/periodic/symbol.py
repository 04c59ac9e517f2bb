"""The 2 x 2 block symbol of the periodic cell's operator (:class:`bem.periodic.PeriodicOperator`), or of its
inverse, made from the packed symbol of ``C`` a block of rows at a time as a product uses it.

A spectrum of the cell has the layout of :meth:`bem.periodic.PeriodicOperator.spectrum`, ``(n_rows/2, 2, n_cols/2 +
1)``: per frequency the two row parities, which ``C`` couples by a 2 x 2 block. ``C`` is symmetric, so the block is
Hermitian: its diagonal entries are real and equal (the kernel of a parity on itself is even, and the same for both
parities), ``S_00 = S_11``, and ``S_10 = conj(S_01)``. The operator keeps ``S_00`` and ``S_01`` once, in double
precision (6 bytes a node); the symbols of ``C + lam I``, of its inverse (the preconditioner) and their single
precision forms are made from them where a product needs them (:func:`bem.periodic.spectra.mixed`, and compiled in
:mod:`bem.periodic.passes`), not held.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Symbol", "inverse_blocks", "mirrored_sum"]


def inverse_blocks(xp, a, b, shift=None):
    """The blocks ``(a / det, b * (-1 / det))``, ``det = a^2 - |b|^2``, of ``(C + lam I)^-1`` from those of
    ``C + lam I`` (``a = S_00 + lam``, real, ``b = S_01``), in the arrays' namespace ``xp``: the one formula of the
    inverse symbol, for :meth:`Symbol.rows` and for a device's operator. ``shift`` (where the arrays start at frequency
    0) is added first to their first entries, the constant mode's (``a`` and ``b`` are then written there: arrays of the
    caller's own)."""
    if shift is not None:
        a[(0,) * a.ndim] += shift
        b[(0,) * b.ndim] += shift
    det = a * a - (xp.real(b) * xp.real(b) + xp.imag(b) * xp.imag(b))
    return a / det, b * (-1.0 / det)


@dataclass(frozen=True, eq=False)  # arrays: compared by identity
class Symbol:
    """The 2 x 2 block symbol of ``C + lam I``, or of its inverse, over the packed symbol ``(S_00, S_01)`` of ``C``.

    Attributes
    ----------
    d : ndarray
        ``S_00`` of ``C``, float64, shape ``(n_rows/2, 1, n_cols/2 + 1)`` (read, never written).
    b : ndarray
        ``S_01`` of ``C``, complex128, the same shape.
    lam : float
        Uniform compliance added on the diagonal [length/pressure].
    inverse : bool
        The symbol of ``(C + lam I)^-1``: ``a / det`` and ``-b / det`` with ``a = S_00 + lam``, ``det = a^2 - |b|^2``,
        where at frequency 0 ``shift`` is added to ``a`` and to ``b`` first (``b`` times ``-1 / det``, as a product
        with the reciprocal).
    shift : float
        See ``inverse``: half the eigenvalue the constant mode takes (where ``C`` vanishes).
    single : bool
        The blocks rounded to single precision (after they are made in double precision), for float32 products.
    """

    d: np.ndarray
    b: np.ndarray
    lam: float = 0.0
    inverse: bool = False
    shift: float = 0.0
    single: bool = False

    def rows(self, lo=0, hi=None):
        """``(D, B)`` of the rows ``lo:hi`` of the spectrum: ``D`` real, shape ``(rows, 1, n_cols/2 + 1)``, ``B``
        complex, ``(rows, 2, n_cols/2 + 1)``, ``B[:, 0] = S_01``, ``B[:, 1] = S_10``; in single precision with
        ``single``. New arrays: the form of reference for the compiled product (:mod:`bem.periodic.passes`)."""
        a, b = self.d[lo:hi] + self.lam, self.b[lo:hi]
        if self.inverse:
            first = lo == 0 and a.size  # frequency 0, the constant mode, in these rows
            a, b = inverse_blocks(np, a, b.copy() if first else b, self.shift if first else None)
        out = np.empty((a.shape[0], 2) + a.shape[2:], dtype=np.complex64 if self.single else np.complex128)
        out[:, :1] = b
        np.conjugate(out[:, :1], out=out[:, 1:])
        return (a.astype(np.float32) if self.single else a), out

    def diagonal(self, n_cols, rows=None):
        """The diagonal entry of the product the symbol makes, the same at every node (of the inverse: the
        preconditioner's ``M_nn``) [length/pressure, or its inverse], in double precision: the mean of the diagonal
        blocks over the cell's whole spectrum, a column of the half spectrum counted with its mirror (``n_cols``, the
        cell's columns, says whether the last one is its own mirror); ``rows`` rows of the spectrum at a time (default
        a sixteenth of them: a few bytes a node at most beside the symbol)."""
        total, n = 0.0, self.d.shape[0]
        rows = max(1, n // 16) if rows is None else rows
        for lo in range(0, n, rows):
            a = self.d[lo:lo + rows] + self.lam
            if self.inverse:
                first = lo == 0
                b = self.b[lo:lo + rows]
                a = inverse_blocks(np, a, b.copy() if first else b, self.shift if first else None)[0]
            total += mirrored_sum(np, a, n_cols)
        return total / (n * n_cols)


def mirrored_sum(xp, a, n_cols):
    """The sum of a real array ``a`` of the layout of a cell's half spectrum (its last axis the columns ``0 ..
    n_cols // 2``) over the whole spectrum, each column counted with its mirror (``n_cols`` even: the last column is
    its own), in the namespace ``xp``; a float."""
    last = a.shape[-1] - 1
    own = xp.sum(a[..., 0]) + (xp.sum(a[..., last]) if n_cols % 2 == 0 else 0.0)
    return 2.0 * float(xp.sum(a)) - float(own)
