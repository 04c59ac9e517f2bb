"""The 2 x 2 block symbols of the half-space operator (:class:`bem.InfluenceOperator`): the spectra of its
kernel between two boxes, their product with a pair of spectra, and the inverse symbol of its FFT preconditioner.

The rows of a lattice split by parity into two rectangular lattices, and a convolution of the
lattice is a 2 x 2 block convolution of theirs: in the Fourier basis ``V_a <- sum_b S_ab V_b``
(:func:`block_product`). The preconditioner inverts the symmetric symbol of a zero-padded box
frequency by frequency (:func:`inverse_symbol`); its symbol is Hermitian, so ``S_10 = conj(S_01)``
is not stored; so is the symbol of the operator over a box onto itself (:func:`kernel_spectra`), whose
diagonal blocks are real besides. On NumPy both run in place with temporaries of a block of :data:`bem.fft.BLOCK`
entries or of one block of the symbol, the same operations as the whole-array formulas
(``tests/bem/test_memory.py``).
"""

from __future__ import annotations

import numpy as np

from . import fft, pruned_fft

__all__ = ["block_product", "block_quadratic", "inverse_symbol", "kernel_spectra", "padded_kernel", "padded_shape",
           "single_symbol", "table_extent"]


def _conj(x):
    """``conj(x)`` in the array's own namespace (a strict array API namespace has no ``x.conj()``)."""
    space = getattr(x, "__array_namespace__", None)
    return space().conj(x) if space is not None else x.conj()


def block_product(S, V):
    """``V_a <- sum_b S_ab V_b`` in place on a pair of spectra (``V`` of shape ``(2, rows, cols)``).

    Two temporaries: on NumPy of the rows of :data:`bem.fft.BLOCK` entries each per thread (the rows one block after
    the other, in parts on the threads of :func:`bem.fft.in_parts`; the same numbers), elsewhere of a whole spectrum
    each."""
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

    def part(blocks):  # the blocks of rows of a part, on the threads of bem.fft.in_parts
        t = np.empty((min(step, rows),) + V.shape[2:], dtype=np.result_type(S[0][1], V))
        w = np.empty_like(t)
        for lo in range(blocks.start * step, min(blocks.stop * step, rows), step):
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

    fft.in_parts(part, -(-rows // step), V.size)
    return V


def block_quadratic(S, V, n_cols, xp=np):
    """``sum_q sum_ab conj(V_a) S_ab V_b`` over the whole spectrum of a pair of real arrays [the units of ``S``
    times those of ``V`` squared], from their half spectra ``V`` (shape ``(2, rows, n_cols // 2 + 1)``, of
    :func:`bem.pruned_fft.forward`) and a Hermitian symbol ``S`` of :func:`kernel_spectra` (``S_10`` not stored).

    With ``S`` the spectra of ``C`` over a box onto itself and ``V`` the padded spectra of ``v`` on that box, the
    quadratic form ``v.C v``. The columns of the half spectrum weigh as :func:`bem.fft.half_spectrum_weights`.
    Summed in double precision; on NumPy by bands of rows of :data:`bem.fft.BLOCK` entries (no temporary of the
    spectrum's size).
    """
    (s00, s01), (_, s11) = S
    if S[1][0] is not None:
        raise ValueError("S must be a Hermitian symbol ((S_00, S_01), (None, S_11)) of kernel_spectra(hermitian=True)")
    weight = fft.half_spectrum_weights(n_cols, xp)

    def terms(s00, s01, s11, v0, v1, xp):  # S_00 |V_0|^2 + S_11 |V_1|^2 + 2 Re(conj(V_0) S_01 V_1)
        re, im = xp.real, xp.imag
        a, b, c, d = re(v0), im(v0), re(v1), im(v1)
        cross = (a * c + b * d) * re(s01) - (a * d - b * c) * im(s01)
        return s00 * (a * a + b * b) + s11 * (c * c + d * d) + 2 * cross

    def weighted(e, xp):  # one sum: one scalar to the host off NumPy
        return float(xp.sum(xp.astype(e, xp.float64) * weight))

    if not isinstance(V, np.ndarray):
        return weighted(terms(s00, s01, s11, V[0, ...], V[1, ...], xp), xp)
    rows = V.shape[1]
    step = max(1, fft.BLOCK // max(1, V.shape[2]))
    total = 0.0  # NumPy: by bands of rows
    for lo in range(0, rows, step):
        r = slice(lo, min(lo + step, rows))
        total += weighted(terms(s00[r], s01[r], s11[r], V[0, r], V[1, r], np), np)
    return total


def single_symbol(xp, S):
    """A Hermitian symbol ``((S_00, S_01), (None, S_11))`` rounded to single precision (float32 diagonal blocks,
    complex64 ``S_01``)."""
    (s00, s01), (_, s11) = S
    return (xp.astype(s00, xp.float32), xp.astype(s01, xp.complex64)), (None, xp.astype(s11, xp.float32))


def inverse_symbol(backend, spectra, lam, floor, diagonal, single=False):
    """``(shape, S)``: the spectra ``S`` of ``(K + lam)^-1`` for a symmetric 2 x 2 block symbol ``K`` (eigenvalues
    floored at ``floor * diagonal + lam``), for :func:`block_product`.

    Parameters
    ----------
    backend : bem.backend.Backend
        Where the spectra live.
    spectra : callable
        ``spectra()`` gives ``(shape, K)``: the padded shape ``(Lk, Lq)`` and the kernel spectra divided by
        ``Lk Lq`` of a box onto itself, ``K = ((K_00, K_01), (None, K_11))`` with real diagonal blocks
        (:meth:`bem.InfluenceOperator._kernel_spectra` with ``hermitian=True``). Called here, so that on NumPy
        ``K`` is held only while ``S`` is made.
    lam : float
        Uniform layer compliance [length/pressure] added on the diagonal.
    floor : float
        Eigenvalue floor as a fraction of ``diagonal``.
    diagonal : float
        The diagonal coefficient ``C_nn`` [length/pressure].
    single : bool
        On NumPy: ``S`` rounded to single precision (float32, complex64) band by band (elsewhere the caller
        rounds it).

    Returns
    -------
    shape, S
        ``S = ((S00, S01), (None, S11))``: ``S_10 = conj(S_01)`` is not stored.
    """
    if backend.is_numpy:
        return _inverse_symbol_numpy(spectra, lam, floor, diagonal, single)
    shape, K = spectra()
    xp = backend.xp
    lam_hat = lam / (shape[0] * shape[1])  # spectra carry the 1/(Lk Lq) of the inverse FFT
    A, D, B = K[0][0] + lam_hat, K[1][1] + lam_hat, K[0][1]
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

def _inverse_symbol_numpy(spectra, lam, floor, diagonal, single=False):
    """:func:`inverse_symbol` on NumPy: the same operations, a band of rows of :data:`bem.fft.BLOCK` entries at a
    time into the blocks of ``S`` (temporaries of a band, not of the box), rounded there to single precision where
    ``single``."""
    shape, K = spectra()
    size = shape[0] * shape[1]
    k00, k01, k11 = K[0][0], K[0][1], K[1][1]
    del K
    real, cplx = (np.float32, np.complex64) if single else (np.float64, np.complex128)
    s00, s01, s11 = np.empty(k00.shape, real), np.empty(k01.shape, cplx), np.empty(k11.shape, real)
    rows = k00.shape[0]
    step = max(1, fft.BLOCK // max(1, k00[0].size))
    for lo in range(0, rows, step):
        r = slice(lo, min(lo + step, rows))
        s00[r], s01[r], s11[r] = _inverse_band(k00[r], k01[r], k11[r], lam, floor, diagonal, size)
    # S_10 = conj(S_01): not stored (None), block_product conjugates S_01
    return shape, ((s00, s01), (None, s11))


def _inverse_band(k00, k01, k11, lam, floor, diagonal, size):
    """The blocks ``(S_00, S_01, S_11)`` of :func:`inverse_symbol` on a band of frequencies (NumPy, in place on
    the band's temporaries)."""
    lam_hat = lam / size  # spectra carry the 1/(Lk Lq) of the inverse FFT
    A, D = k00 + lam_hat, k11 + lam_hat
    m = A + D
    m /= 2
    d = A - D
    d /= 2
    np.square(d, out=d)
    b2 = np.abs(k01)
    np.square(b2, out=b2)
    d += b2
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
    half[unsafe] = 0.0
    diff = inv_hi
    diff -= inv_lo  # inv_hi - inv_lo
    scale = 1.0 / size**2  # inverse of a 1/(Lk Lq) symbol, times 1/(Lk Lq)
    pb = k01 * half
    pb *= diff
    pb *= scale
    for X in (D, A):  # (inv_lo + where(safe, (X - m + d) half, 0.5) diff) scale, in place on X
        X -= m
        X += d
        X *= half
        X[unsafe] = 0.5
        X *= diff
        X += inv_lo
        X *= scale
    return A, pb, D


def padded_shape(out_box, in_box):
    """``(Lk, Lq)``: the padding of the product of data on ``in_box`` onto ``out_box`` (:func:`kernel_spectra`),
    ``out + in - 1`` per axis rounded up to a fast length."""
    lk = fft.fast_length(max(o[1] for o in out_box[0]) + max(i[1] for i in in_box[0]) - 1, real=False)
    return lk, fft.fast_length(out_box[1][1] + in_box[1][1] - 1, real=True)


def _offsets(start, a, b, rows, cols, shift):
    """The brick-row offsets ``dr`` and table columns ``t`` of :func:`padded_kernel`'s rows and columns."""
    e, f = np.r_[0 : rows[0], -rows[1] : 0], np.r_[0 : cols[0], -cols[1] : 0]
    dr = start[a] - start[b] + 2 * (e + shift[0])  # brick row offset
    t = (np.abs(2 * (f + shift[1]) + (a - b)) - (a != b)) // 2  # table column (x offset in half steps)
    return dr, t


def _block_args(out_box, in_box, a, b):
    """``(rows, cols, shift)`` of :func:`padded_kernel` for the block from parity ``b`` of ``in_box`` to ``a``."""
    (o_rows, (oq, nq)), (i_rows, (iq, bq)) = out_box, in_box
    (oa, na), (ib, nb) = o_rows[a], i_rows[b]
    return (na, nb - 1), (nq, bq - 1), (oa - ib, oq - iq)


def table_extent(start, out_box, in_box):
    """``(rows, cols)``: the smallest lattice shape whose coefficient table (:func:`bem.template.lattice_table`,
    ``rows x (cols + 1)`` offsets) holds every offset that :func:`kernel_spectra` of these boxes meets."""
    rows = cols = 0
    for a, b in ((0, 0), (0, 1), (1, 0), (1, 1)):
        dr, t = _offsets(start, a, b, *_block_args(out_box, in_box, a, b))
        rows, cols = max(rows, int(np.abs(dr).max(initial=-1)) + 1), max(cols, int(t.max(initial=0)))
    return rows, cols


def padded_kernel(table, start, a, b, rows, cols, shift, shape, out=None, clip=False):
    """The kernel from the rows of parity ``b`` to those of parity ``a`` in a zero-padded array of ``shape`` (``out``
    where given): at the parity-row offsets ``e = 0 .. rows[0] - 1`` from its first row and ``-rows[1] .. -1`` in its
    last rows, the column offsets ``f`` from ``cols`` alike, the coefficient of ``table`` at the brick-row offset
    ``start[a] - start[b] + 2 (e + shift[0])`` and the half-step column offset ``2 (f + shift[1]) + a - b``.
    ``clip``: offsets beyond the table take its last entries (offsets that no product meets)."""
    dr, t = _offsets(start, a, b, rows, cols, shift)
    mode = "clip" if clip else "raise"
    block = table.take(np.abs(dr), axis=0, mode=mode).take(t, axis=1, mode=mode)  # rows e, columns f
    kernel = np.zeros(shape) if out is None else out
    (lk, lq), (na, nb), (nq, bq) = shape, rows, cols
    for r, src_r in ((slice(0, na), slice(0, na)), (slice(lk - nb, lk), slice(na, None))):
        for c, src_c in ((slice(0, nq), slice(0, nq)), (slice(lq - bq, lq), slice(nq, None))):
            kernel[r, c] = block[src_r, src_c]
    return kernel


def kernel_spectra(backend, table, start, out_box, in_box, hermitian=False):
    """Spectra ``S_ab`` of the blocks mapping ``in_box`` data to ``out_box`` values.

    A box is ``((k0_even, rows_even), (k0_odd, rows_odd)), (q0, cols)`` in parity
    row and column indices. The input block sits at the origin of the padded
    array and the kernel is stored shifted so that the output lands at the
    origin too; the padding ``out + in - 1`` per axis leaves no wrap-around.
    Returns the padded shape and the spectra divided by the padded size. ``table``: the influence
    coefficients at every lattice offset (:class:`bem.InfluenceOperator`), ``start``: the first brick row of
    each parity, ``backend``: where the spectra live (made on the host).

    ``hermitian`` (``out_box == in_box``): the symbol of a box onto itself is Hermitian, its diagonal
    blocks are the spectra of even kernels, real, and ``S_10 = conj(S_01)`` (their imaginary parts and
    differences are round-off, ``tests/bem/test_operator.py``). Then only ``S_00``, ``S_01`` and
    ``S_11`` are made, as ``((S_00.real, S_01), (None, S_11.real))`` for :func:`block_product`:
    half the memory of the four complex blocks.
    """
    if hermitian and out_box != in_box:
        raise ValueError(f"hermitian = True needs out_box == in_box, got {out_box!r} and {in_box!r}")
    lk, lq = padded_shape(out_box, in_box)
    # on NumPy one block at a time into the spectra (the same numbers as the batch: each line is
    # transformed alone), so that the padded kernels are never all held at once; the four complex blocks
    # transformed in the array that keeps them (no spectrum of a block made beside it and copied)
    numpy = backend.is_numpy
    # the complex block last: two real diagonal blocks held while it is made (not a complex and a real one)
    blocks = ((0, 0), (1, 1), (0, 1)) if hermitian else ((0, 0), (0, 1), (1, 0), (1, 1))
    if numpy and hermitian:
        out = {}
    else:
        out = np.empty((2, 2, lk, lq // 2 + 1), dtype=complex) if numpy else np.zeros((2, 2, lk, lq))
    for a, b in blocks:
        kernel = padded_kernel(table, start, a, b, *_block_args(out_box, in_box, a, b), (lk, lq),
                               None if numpy else out[a, b])
        if numpy:
            kernel /= lk * lq
            if not hermitian:
                pruned_fft.forward_parts([kernel], (lk, lq), out=out[a, b][None])
                continue
            spectrum = pruned_fft.forward(kernel, (lk, lq))
            del kernel
            out[a, b] = spectrum.real.copy() if a == b else spectrum
            del spectrum
    if numpy:
        return (lk, lq), (((out[0, 0], out[0, 1]), (None, out[1, 1])) if hermitian else out)
    out /= lk * lq
    K = backend.forward(backend.asarray(out), (lk, lq))
    if not hermitian:
        return (lk, lq), K
    xp = backend.xp
    return (lk, lq), ((xp.real(K[0, 0, ...]), K[0, 1, ...]), (None, xp.real(K[1, 1, ...])))
