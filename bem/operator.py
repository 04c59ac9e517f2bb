"""The influence operator ``C`` of eq. 6, applied by zero-padded FFT convolution.

``C[n, m] = c / (pi E*) * w_t((r_n - r_m) / c)``, with ``w_t`` the closed-form
template of :func:`bem.template.template`. ``C`` depends only on the lattice
offset between two nodes, so ``u = C @ p`` is a discrete (non-periodic)
convolution. In the brick storage of :class:`bem.lattice.Lattice` the offset
also depends on the parities of the two rows, so the rows are split into their
even and odd classes and ``u`` is a 2 x 2 block convolution
``u_a = sum_b K_ab * p_b`` on the half-height arrays. Each block is evaluated
exactly with real-to-complex FFTs zero-padded to at least twice the array
size (no wrap-around), both cores used: cost ``O(N log N)``, memory ``O(N)``,
no dense ``N x N`` matrix.
"""

from __future__ import annotations

import math
import os

import numpy as np

from .checks import check_positive
from .template import template

__all__ = ["InfluenceOperator", "diagonal_coefficient"]


def diagonal_coefficient(step, E_star):
    """Diagonal influence coefficient ``C_nn = c / (pi E*) w_t(0, 0)`` [length/pressure] (eq. 6).

    The closure of a node under its own unit pyramid; the paper states layer
    compliances in units of it (``lam = 10 C_nn``, Fig. 5).
    """
    return check_positive("step", step) / (math.pi * check_positive("E_star", E_star)) * float(template(0.0, 0.0))


def _workers():
    return max(1, os.cpu_count() or 1)


class InfluenceOperator:
    """Matrix-free ``u = C p`` on the nodes of a lattice.

    Parameters
    ----------
    lattice : Lattice
        The candidate region.
    E_star : float
        Effective modulus ``E*`` [pressure], ``1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2``.

    Notes
    -----
    Pressures are brick arrays of shape ``lattice.shape`` [pressure];
    displacements come back in the same shape [length]. Masked nodes of the
    input must be zero; they are zero on output too.
    """

    def __init__(self, lattice, E_star):
        import scipy.fft as sfft

        self.lattice = lattice
        self.n_matvec = 0  # products C p so far (the work measure of ContactResult.n_matvec)
        self.E_star = check_positive("E_star", E_star)
        n_rows, n_cols = lattice.shape
        par = lattice.parity
        self._rows = [np.flatnonzero(par == a) for a in (0, 1)]
        n_a = [len(r) for r in self._rows]
        self._pad = (
            sfft.next_fast_len(2 * max(n_a) - 1, real=True),
            sfft.next_fast_len(2 * n_cols - 1, real=True),
        )
        lk, lq = self._pad
        table = self._template_table()
        scale = lattice.step / (math.pi * self.E_star)
        kernel = np.zeros((2, 2, lk, lq))
        dq = np.r_[0:n_cols, -(n_cols - 1):0]
        for a in (0, 1):
            for b in (0, 1):
                dk = np.r_[0 : n_a[a], -(n_a[b] - 1) : 0]
                dr = self._rows[a][0] - self._rows[b][0] + 2 * dk  # row offset
                dm = 2 * dq + (a - b)  # x offset in half steps
                n = np.abs(dr)[:, None]
                t = (np.abs(dm)[None, :] - n % 2) // 2
                kernel[a, b][np.ix_(dk % lk, dq % lq)] = table[n, t]
        self._kernel_hat = sfft.rfft2(kernel * scale, workers=_workers())
        self.diagonal = diagonal_coefficient(lattice.step, self.E_star)

    def _template_table(self):
        """``w_t`` at every offset ``(m/2, n*sqrt(3)/2)`` with ``m = n mod 2`` (lattice units)."""
        n_rows, n_cols = self.lattice.shape
        n = np.arange(n_rows)[:, None]
        t = np.arange(n_cols + 1)[None, :]
        dx = (2 * t + n % 2) / 2.0
        dy = n * (math.sqrt(3.0) / 2)
        return template(dx, dy)

    def matvec(self, p):
        """Return ``u = C p`` for a brick array ``p`` [pressure] -> [length]."""
        self.n_matvec += 1
        return self._block_convolve(self._kernel_hat, np.asarray(p, dtype=float))

    __call__ = matvec

    def _block_convolve(self, spectrum, v):
        """Apply a 2 x 2 block convolution given by its spectrum to a brick array.

        Pruned transforms: the real FFT along x runs only over the rows that
        hold data (forward) or are kept (inverse); the complex FFT along y
        does the zero padding.
        """
        import scipy.fft as sfft

        lk, lq = self._pad
        n_rows = [len(r) for r in self._rows]
        workers = _workers()
        v_hat = [
            sfft.fft(sfft.rfft(v[self._rows[b]], n=lq, axis=1, workers=workers), n=lk, axis=0,
                     overwrite_x=True, workers=workers)
            for b in (0, 1)
        ]
        out = np.empty(self.lattice.shape)
        n_cols = out.shape[1]
        for a in (0, 1):
            acc = spectrum[a, 0] * v_hat[0]
            acc += spectrum[a, 1] * v_hat[1]
            col = sfft.ifft(acc, axis=0, overwrite_x=True, workers=workers)[: n_rows[a]]
            out[self._rows[a]] = sfft.irfft(col, n=lq, axis=1, workers=workers)[:, :n_cols]
        out[~self.lattice.mask] = 0.0
        return out

    def preconditioner(self, lam=0.0, floor=0.5):
        """FFT preconditioner ``z ~ (C + lam I)^-1 r`` for the conjugate gradients.

        The inverse of the 2 x 2 block symbol of the zero-padded (circulant)
        embedding of ``C + lam I``. Truncating the ``1/r`` kernel at the
        padding edge makes a few symbol eigenvalues small or negative; they are
        raised to ``floor * C_nn + lam`` so that ``M`` stays positive definite.

        Parameters
        ----------
        lam : float
            Uniform layer compliance [length/pressure] added on the diagonal.
        floor : float
            Eigenvalue floor as a fraction of the diagonal coefficient ``C_nn``.

        Returns
        -------
        callable
            ``M(r)`` on brick arrays.
        """
        K = self._kernel_hat
        A, D, B = K[0, 0].real + lam, K[1, 1].real + lam, K[0, 1]
        m = (A + D) / 2
        d = np.sqrt(((A - D) / 2) ** 2 + np.abs(B) ** 2)
        low = floor * self.diagonal + lam
        inv_hi = 1.0 / np.maximum(m + d, low)
        inv_lo = 1.0 / np.maximum(m - d, low)
        # H^-1 = P+/l+ + P-/l-,  P+ = (H - (m - d) I) / (2 d),  P- = I - P+
        with np.errstate(divide="ignore", invalid="ignore"):
            safe = d > 1e-14 * np.abs(m)
            half = np.where(safe, 0.5 / np.where(safe, d, 1.0), 0.0)
        pa = np.where(safe, (A - m + d) * half, 0.5)
        pd = np.where(safe, (D - m + d) * half, 0.5)
        pb = B * half
        diff = inv_hi - inv_lo
        spectrum = np.empty_like(K)
        spectrum[0, 0] = inv_lo + pa * diff
        spectrum[1, 1] = inv_lo + pd * diff
        spectrum[0, 1] = pb * diff
        spectrum[1, 0] = np.conj(pb) * diff
        return lambda r: self._block_convolve(spectrum, r)

    def as_linear_operator(self):
        """``scipy.sparse.linalg.LinearOperator`` acting on the flattened candidate nodes."""
        from scipy.sparse.linalg import LinearOperator

        mask = self.lattice.mask
        n = int(mask.sum())

        def mv(v):
            p = np.zeros(self.lattice.shape)
            p[mask] = np.ravel(v)
            return self.matvec(p)[mask]

        return LinearOperator((n, n), matvec=mv, rmatvec=mv, dtype=float)

    def dense(self):
        """The dense matrix ``C`` over the flattened candidate nodes (small problems only).

        Built directly from :func:`bem.template.template` at every node pair,
        independently of the FFT path, so the two can be checked against each other.
        """
        mask = self.lattice.mask
        x = self.lattice.x[mask] / self.lattice.step
        y = self.lattice.y[mask] / self.lattice.step
        if x.size > 20000:
            raise MemoryError(f"dense C for {x.size} nodes would need {8 * x.size**2 / 1e9:.1f} GB")
        scale = self.lattice.step / (math.pi * self.E_star)
        return scale * template(x[:, None] - x[None, :], y[:, None] - y[None, :])

