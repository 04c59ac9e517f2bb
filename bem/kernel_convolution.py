"""Non-periodic FFT convolution on the lattice with sampled kernels of definite parity.

The stresses below the surface (:mod:`bem.stress`) are convolutions of the nodal pressures with
kernels that are even or odd in x and y; this module convolves with any such kernel on the
brick-stored lattice, with the same 2 x 2 even/odd-row blocks as :class:`bem.operator.InfluenceOperator`.
"""

from __future__ import annotations

import math

import numpy as np

from . import fft

__all__ = ["SymmetricKernelConvolution"]


def _fast_half(n):
    """Smallest 2,3,5-smooth ``N >= n``: the padded length is ``2 N``."""
    import scipy.fft as sfft

    return sfft.next_fast_len(max(int(n), 2), real=True)


class SymmetricKernelConvolution:
    """Non-periodic FFT convolution on the lattice with sampled kernels of definite parity in x and y.

    ``out[n] = sum_m K(r_n - r_m) v[m]`` for every node ``n`` of ``lattice`` and the nodes ``m``
    of an input box of the continued lattice (brick rows ``rows[0]..rows[1]``, columns
    ``cols[0]..cols[1]``; they may reach beyond ``lattice``). It generalises the product of
    :class:`InfluenceOperator` to kernels with ``K(-x, y) = s_x K(x, y)`` and
    ``K(x, -y) = s_y K(x, y)``, ``s = +1`` (even) or ``-1`` (odd), such as the stresses under a
    pyramid. Same 2 x 2 even/odd-row blocks, zero-padded (exact, no wrap-around); the symmetry
    does half of the work: block (1, 1) equals block (0, 0), block (1, 0) is block (0, 1)
    reflected, and the spectra of blocks (0, 0) and (0, 1) are real transforms of one quadrant
    of samples (DCT-I/DST-I of the whole-step offsets, DCT-II/DST-II of the half-step ones).

    ``workers`` threads per FFT (default: all cores); calls from several threads are safe.

    Usage: sample the kernel at :meth:`offsets`, turn the samples into a spectrum with
    :meth:`spectrum`, the input into spectra with :meth:`transform` (once per input), and sum
    any number of (spectrum, input) products with :meth:`apply`.
    """

    def __init__(self, lattice, rows, cols, *, workers=None):
        self.lattice = lattice
        self.workers = fft.threads() if workers is None else int(workers)
        n_rows, n_cols = lattice.shape
        r_lo, r_hi = int(rows[0]), int(rows[1])
        self.r_lo = r_lo
        self.q_lo, self.q_hi = int(cols[0]), int(cols[1])
        par = (np.arange(n_rows) - lattice.half_rows) % 2
        self._out_rows = [np.flatnonzero(par == a) for a in (0, 1)]
        self._first = [int(r[0]) for r in self._out_rows]
        self.delta = self._first[1] - self._first[0]  # +1 or -1
        # input rows of each parity, as (first brick row, count, first block index k_in)
        self._in = []
        for b in (0, 1):
            first = r_lo + (self._first[b] - r_lo) % 2
            count = max(0, (r_hi - first) // 2 + 1)
            self._in.append((first, count, (first - self._first[b]) // 2))
        self.E_k = max(n_rows - 1 - r_lo, r_hi) // 2
        self.E_q = max(n_cols - 1 - self.q_lo, self.q_hi)
        n_out = max(len(r) for r in self._out_rows)
        i_lo = min(k for _, _, k in self._in)
        i_hi = max(k + c - 1 for _, c, k in self._in)
        span_k = max(i_hi + self.E_k + 3, n_out + self.E_k - i_lo + 2)
        span_q = max(self.q_hi + self.E_q + 3, n_cols + self.E_q - self.q_lo + 2)
        self.N_k = _fast_half(max(self.E_k + 2, (span_k + 1) // 2))
        self.N_q = _fast_half(max(self.E_q + 2, (span_q + 1) // 2))
        m1 = np.arange(2 * self.N_k)
        m2 = np.arange(self.N_q + 1)
        # phase of the half-step offsets of block (0, 1)
        self._phase = np.exp(-1j * math.pi * (self.delta * m1[:, None] / (2 * self.N_k)
                                              + m2[None, :] / (2 * self.N_q)))

    def offsets(self):
        """Quadrant offsets [lattice steps] at which to sample the kernel.

        Returns
        -------
        (x00, y00), (x01, y01) : tuples of ndarray, shape (E_k + 1, E_q + 1)
            ``x00 = j``, ``y00 = sqrt(3) i`` (offsets between rows of equal parity) and
            ``x01 = j + 1/2``, ``y01 = sqrt(3)/2 (2 i + 1)`` (rows of unequal parity),
            ``i = 0..E_k``, ``j = 0..E_q``.
        """
        i = np.arange(self.E_k + 1)[:, None]
        j = np.arange(self.E_q + 1)[None, :]
        h = math.sqrt(3.0) / 2
        zero = np.zeros((self.E_k + 1, self.E_q + 1))
        return (j + zero, 2 * h * i + zero), (j + 0.5 + zero, h * (2 * i + 1) + zero)

    def _axis(self, q, axis, n, odd, half_step):
        """Real transform of quadrant samples along ``axis``: ``n + 1`` frequencies ``0..n``."""
        import scipy.fft as sfft

        workers = self.workers
        if not odd and not half_step:  # samples at j = 0..n: DCT-I
            return sfft.dct(q, type=1, n=n + 1, axis=axis, workers=workers)
        if half_step:  # samples at j + 1/2, j = 0..n-1: DCT-II / DST-II
            y = (sfft.dst if odd else sfft.dct)(q, type=2, n=n, axis=axis, workers=workers)
            pad = (1, 0) if odd else (0, 1)
        else:  # odd, samples at j = 1..n-1 (j = 0 is 0): DST-I
            take = [slice(None)] * q.ndim
            take[axis] = slice(1, None)
            y = sfft.dst(q[tuple(take)], type=1, n=n - 1, axis=axis, workers=workers)
            pad = (1, 1)
        widths = [(0, 0)] * q.ndim
        widths[axis] = pad
        return np.pad(y, widths)

    def spectrum(self, q00, q01, *, odd_x, odd_y):
        """Spectrum of a kernel from its quadrant samples.

        Parameters
        ----------
        q00, q01 : ndarray, shape (..., E_k + 1, E_q + 1)
            The kernel at the two sets of :meth:`offsets` (leading axes: a batch of kernels
            of the same parity).
        odd_x, odd_y : bool
            Parity of the kernel in x and in y.

        Returns
        -------
        tuple
            ``(T00, T01, odd_y, factor)``: real arrays of shape ``(..., N_k + 1, N_q + 1)``, the
            frequencies ``0..N_k`` along the rows (the others follow by symmetry:
            ``T00[2 N_k - m] = +-T00[m]``, ``T01[2 N_k - m] = -+T01[m]``, upper sign for even
            kernels), and the complex factor ``(-i)^(odd_x + odd_y)`` of the block spectra.
        """
        out = []
        for q, half in ((q00, False), (q01, True)):
            t = self._axis(np.asarray(q, dtype=float), -1, self.N_q, odd_x, half)
            out.append(self._axis(t, -2, self.N_k, odd_y, half))
        return out[0], out[1], bool(odd_y), (-1j) ** (int(odd_x) + int(odd_y))

    def transform(self, v):
        """Spectra of an input given on the box (shape ``(rows[1]-rows[0]+1, cols[1]-cols[0]+1)``).

        Returns ``(P_0, P_1, phase P_1, conj(phase) P_0)`` for :meth:`apply`.
        """
        import scipy.fft as sfft

        v = np.asarray(v, dtype=float)
        L_k, L_q = 2 * self.N_k, 2 * self.N_q
        m1 = np.arange(L_k)[:, None]
        m2 = np.arange(self.N_q + 1)[None, :]
        spectra = []
        for first, count, k0 in self._in:
            rows = v[first - self.r_lo: first - self.r_lo + 2 * count: 2]
            s = sfft.rfft(rows, n=L_q, axis=1, workers=self.workers)
            s = sfft.fft(s, n=L_k, axis=0, workers=self.workers)
            s *= np.exp(-2j * math.pi * (k0 * m1 / L_k + self.q_lo * m2 / L_q))
            spectra.append(s)
        return spectra[0], spectra[1], self._phase * spectra[1], np.conj(self._phase) * spectra[0]

    def apply(self, terms, backend=None):
        """``sum over (spectrum, input) of K * v`` on the nodes of the lattice.

        Parameters
        ----------
        terms : list of (spectrum, input)
            :meth:`spectrum` and :meth:`transform` results; the spectra share their batch
            shape and their parity.
        backend : bem.backend.Backend, optional
            Run the products and inverse FFTs on this device (the arrays of ``terms`` are
            copied to it); the result is a NumPy array either way.

        Returns
        -------
        ndarray, shape (..., n_rows, n_cols)
            Brick arrays (batch axes of the spectra first).
        """
        if backend is not None and not backend.is_numpy:
            return self._apply_on(backend, terms)
        import scipy.fft as sfft

        workers = self.workers
        n, n_cols = self.N_k, self.lattice.shape[1]
        first = terms[0][0]
        odd_y, factor = first[2], first[3]
        batch = first[0].shape[:-2]
        out = np.empty(batch + self.lattice.shape)
        acc = np.empty(batch + (2 * n, self.N_q + 1), dtype=complex)
        tmp = np.empty_like(acc)
        low, high = slice(0, n + 1), slice(n + 1, None)
        for a in (0, 1):
            # rows 0..N_k: sum T00 P + T01 Q; rows N_k+1..: T00 and T01 mirrored, with the signs
            # +-1 (T00) and -+1 (T01): accumulate T00 P - T01 Q there, negate once if odd in y
            for i, ((t00, t01, _, _), inp) in enumerate(terms):
                direct, shifted = inp[a], inp[2 + a]
                target = tmp if i else acc
                np.multiply(t00, direct[low], out=target[..., low, :])
                np.multiply(t00[..., n - 1:0:-1, :], direct[high], out=target[..., high, :])
                if i:
                    acc += tmp
                np.multiply(t01, shifted[low], out=tmp[..., low, :])
                np.multiply(t01[..., n - 1:0:-1, :], shifted[high], out=tmp[..., high, :])
                acc[..., low, :] += tmp[..., low, :]
                acc[..., high, :] -= tmp[..., high, :]
            if odd_y:
                np.negative(acc[..., high, :], out=acc[..., high, :])
            col = sfft.ifft(acc, axis=-2, overwrite_x=True, workers=workers)[..., : len(self._out_rows[a]), :]
            if factor != 1:
                col *= factor
            out[..., self._out_rows[a], :] = sfft.irfft(col, n=2 * self.N_q, axis=-1, workers=workers)[..., :n_cols]
        return out

    def _apply_on(self, bk, terms):
        """:meth:`apply` in the namespace of ``bk``: the same sums, without ``out=`` arguments."""
        xp = bk.xp
        n, n_cols = self.N_k, self.lattice.shape[1]
        first = terms[0][0]
        odd_y, factor = first[2], first[3]
        batch = first[0].shape[:-2]
        out = xp.empty(batch + self.lattice.shape, dtype=bk.float64)
        cplx = xp.complex128
        for a in (0, 1):
            acc = xp.zeros(batch + (2 * n, self.N_q + 1), dtype=cplx)
            for (t00, t01, _, _), inp in terms:
                t00, t01 = bk.asarray(t00), bk.asarray(t01)
                direct, shifted = bk.asarray(inp[a], dtype=cplx), bk.asarray(inp[2 + a], dtype=cplx)
                acc[..., : n + 1, :] += t00 * direct[: n + 1, :] + t01 * shifted[: n + 1, :]
                acc[..., n + 1 :, :] += t00[..., n - 1 : 0 : -1, :] * direct[n + 1 :, :] \
                    - t01[..., n - 1 : 0 : -1, :] * shifted[n + 1 :, :]
            if odd_y:
                acc[..., n + 1 :, :] = -acc[..., n + 1 :, :]
            col = xp.fft.ifft(acc, axis=-2)[..., : len(self._out_rows[a]), :]
            if factor != 1:
                col = col * factor
            rows = self._out_rows[a]
            step_rows = slice(int(rows[0]), int(rows[-1]) + 1 if int(rows[-1]) + 1 < out.shape[-2] else None, 2)
            out[..., step_rows, :] = xp.fft.irfft(col, n=2 * self.N_q, axis=-1)[..., :n_cols]
        return bk.to_host(out)
