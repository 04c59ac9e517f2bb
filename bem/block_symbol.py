"""The 2 x 2 block symbols of the half-space operator (:class:`bem.InfluenceOperator`): their product with
a pair of spectra, and the inverse symbol of its FFT preconditioner.

The rows of a lattice split by parity into two rectangular lattices, and a convolution of the
lattice is a 2 x 2 block convolution of theirs: in the Fourier basis ``V_a <- sum_b S_ab V_b``
(:func:`block_product`). The preconditioner inverts the symmetric symbol of a zero-padded box
frequency by frequency (:func:`inverse_symbol`); its symbol is Hermitian, so ``S_10 = conj(S_01)``
is not stored. On NumPy both run in place with temporaries of a block of :data:`bem.fft.BLOCK`
entries or of one block of the symbol, the same operations as the whole-array formulas
(``tests/bem/test_memory.py``).
"""

from __future__ import annotations

import numpy as np

from . import fft

__all__ = ["block_product", "inverse_symbol"]


def _conj(x):
    """``conj(x)`` in the array's own namespace (a strict array API namespace has no ``x.conj()``)."""
    space = getattr(x, "__array_namespace__", None)
    return space().conj(x) if space is not None else x.conj()


def block_product(S, V):
    """``V_a <- sum_b S_ab V_b`` in place on a pair of spectra (``V`` of shape ``(2, rows, cols)``).

    Two temporaries: on NumPy of the rows of :data:`bem.fft.BLOCK` entries each (the rows one after the other, the
    same numbers), elsewhere of a whole spectrum each."""
    if not isinstance(S, tuple):  # the kernel spectra of a window, one array S[a, b, ...]
        S = ((S[0, 0, ...], S[0, 1, ...]), (S[1, 0, ...], S[1, 1, ...]))
    conj = S[1][0] is None  # a Hermitian symbol: S_10 = conj(S_01), not stored
    if not isinstance(V, np.ndarray):
        t = S[0][1] * V[1, ...]
        V[1, ...] *= S[1][1]
        V[1, ...] += (_conj(S[0][1]) if conj else S[1][0]) * V[0, ...]
        V[0, ...] *= S[0][0]
        V[0, ...] += t
        return V
    rows = V.shape[1]
    step = max(1, fft.BLOCK // max(1, V.shape[2]))
    t = np.empty((min(step, rows),) + V.shape[2:], dtype=np.result_type(S[0][1], V))
    w = np.empty_like(t)
    for lo in range(0, rows, step):
        r = slice(lo, min(lo + step, rows))
        n = r.stop - lo
        v0, v1 = V[0, r], V[1, r]
        np.multiply(S[0][1][r], v1, out=t[:n])
        v1 *= S[1][1][r]
        if conj:
            np.conjugate(S[0][1][r], out=w[:n])
            w[:n] *= v0
        else:
            np.multiply(S[1][0][r], v0, out=w[:n])
        v1 += w[:n]
        v0 *= S[0][0][r]
        v0 += t[:n]
    return V


def inverse_symbol(backend, spectra, lam, floor, diagonal):
    """``(shape, S)``: the spectra ``S`` of ``(K + lam)^-1`` for a symmetric 2 x 2 block symbol ``K`` (eigenvalues
    floored at ``floor * diagonal + lam``), for :func:`block_product`.

    Parameters
    ----------
    backend : bem.backend.Backend
        Where the spectra live.
    spectra : callable
        ``spectra()`` gives ``(shape, K)``: the padded shape ``(Lk, Lq)`` and the kernel spectra ``K[a, b]``
        divided by ``Lk Lq`` (:meth:`bem.InfluenceOperator._kernel_spectra`). Called here, so that on NumPy
        ``K`` is let go once the off-diagonal block of ``S`` is made.
    lam : float
        Uniform layer compliance [length/pressure] added on the diagonal.
    floor : float
        Eigenvalue floor as a fraction of ``diagonal``.
    diagonal : float
        The diagonal coefficient ``C_nn`` [length/pressure].

    Returns
    -------
    shape, S
        ``S = ((S00, S01), (None, S11))``: ``S_10 = conj(S_01)`` is not stored.
    """
    if backend.is_numpy:
        return _inverse_symbol_numpy(spectra, lam, floor, diagonal)
    shape, K = spectra()
    xp = backend.xp
    lam_hat = lam / (shape[0] * shape[1])  # spectra carry the 1/(Lk Lq) of the inverse FFT
    A, D, B = xp.real(K[0, 0, ...]) + lam_hat, xp.real(K[1, 1, ...]) + lam_hat, K[0, 1, ...]
    m = (A + D) / 2
    d = xp.sqrt(((A - D) / 2) ** 2 + xp.abs(B) ** 2)
    low = (floor * diagonal + lam) / (shape[0] * shape[1])
    inv_hi = 1.0 / xp.maximum(m + d, low)
    inv_lo = 1.0 / xp.maximum(m - d, low)
    # H^-1 = P+/l+ + P-/l-,  P+ = (H - (m - d) I) / (2 d),  P- = I - P+
    with backend.errstate(divide="ignore", invalid="ignore"):
        safe = d > 1e-14 * xp.abs(m)
        half = xp.where(safe, 0.5 / xp.where(safe, d, 1.0), 0.0)
    diff = inv_hi - inv_lo
    pb = B * half * diff
    scale = 1.0 / (shape[0] * shape[1]) ** 2  # inverse of a 1/(Lk Lq) symbol, times 1/(Lk Lq)
    # S_10 = conj(S_01): not stored (None), block_product conjugates S_01
    return shape, (((inv_lo + xp.where(safe, (A - m + d) * half, 0.5) * diff) * scale, pb * scale),
                   (None, (inv_lo + xp.where(safe, (D - m + d) * half, 0.5) * diff) * scale))

def _inverse_symbol_numpy(spectra, lam, floor, diagonal):
    """:func:`inverse_symbol` on NumPy: the same operations, in place where they can be (fewer temporaries
    of the box's size), and ``K`` let go once ``S_01`` is made."""
    shape, K = spectra()
    size = shape[0] * shape[1]
    lam_hat = lam / size  # spectra carry the 1/(Lk Lq) of the inverse FFT
    A, D = K[0, 0].real + lam_hat, K[1, 1].real + lam_hat
    m = A + D
    m /= 2
    d = A - D
    d /= 2
    np.square(d, out=d)
    b2 = np.abs(K[0, 1])
    np.square(b2, out=b2)
    d += b2
    del b2
    np.sqrt(d, out=d)
    low = (floor * diagonal + lam) / size
    inv_hi = m + d
    np.maximum(inv_hi, low, out=inv_hi)
    np.divide(1.0, inv_hi, out=inv_hi)
    inv_lo = m - d
    np.maximum(inv_lo, low, out=inv_lo)
    np.divide(1.0, inv_lo, out=inv_lo)
    # H^-1 = P+/l+ + P-/l-,  P+ = (H - (m - d) I) / (2 d),  P- = I - P+
    with np.errstate(divide="ignore", invalid="ignore"):
        safe = d > 1e-14 * np.abs(m)
        half = np.where(safe, d, 1.0)
        np.divide(0.5, half, out=half)
    unsafe = ~safe
    del safe
    half[unsafe] = 0.0
    diff = inv_hi
    diff -= inv_lo  # inv_hi - inv_lo
    scale = 1.0 / size**2  # inverse of a 1/(Lk Lq) symbol, times 1/(Lk Lq)
    pb = K[0, 1] * half
    del K
    pb *= diff
    pb *= scale
    blocks = []
    for X in (D, A):  # (inv_lo + where(safe, (X - m + d) half, 0.5) diff) scale, in place on X
        X -= m
        X += d
        X *= half
        X[unsafe] = 0.5
        X *= diff
        X += inv_lo
        X *= scale
        blocks.append(X)
    # S_10 = conj(S_01): not stored (None), block_product conjugates S_01
    return shape, ((blocks[1], pb), (None, blocks[0]))

