"""The influence operator ``C`` of eq. 6, applied by zero-padded FFT convolution.

``C[n, m] = c / (pi E*) * w_t((r_n - r_m) / c)``, with ``w_t`` the closed-form
template of :func:`bem.template.template`. ``C`` depends only on the lattice
offset between two nodes, so ``u = C p`` is a discrete (non-periodic)
convolution. In the brick storage of :class:`bem.lattice.Lattice` the offset
also depends on the parities of the two rows, so the rows are split into their
even and odd classes (strided views, no copy) and ``u`` is a 2 x 2 block
convolution ``u_a = sum_b K_ab * p_b`` on the half-height arrays, evaluated
exactly with pruned real FFTs (:mod:`bem.fft`): cost ``O(N log N)``, memory
``O(N)``, no dense ``N x N`` matrix.

Support windows
    A contact covers a fraction of the candidate region, and every vector the
    solvers multiply (pressures, search directions, residuals) vanishes off
    the contact. For an input supported on a box of ``B`` rows (columns) and
    an output wanted on all ``n`` rows, a circular convolution of length
    ``n + B - 1`` has no wrap-around, against ``2 n - 1`` for a full input.
    :meth:`InfluenceOperator.matvec` therefore pads to the bounding box of the
    support of ``p`` (snapped outwards to a grid of 1/16 of the region so
    that a slowly moving contact reuses the same window) and keeps the kernel
    spectrum of the last few windows. The product is exact for every window;
    the window only changes the cost (issue problem, 1,048,703 nodes, contact
    4 % of the region: 2.7x fewer FFT points per product).
"""

from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np

from . import fft
from .checks import check_positive
from .template import template

__all__ = ["InfluenceOperator", "diagonal_coefficient"]

_WINDOWS_KEPT = 3  # kernel spectra cached per operator (matvec windows, preconditioner boxes)
_SNAP = 16  # support boxes snap to a grid of 1/_SNAP of the region
# A cached matvec window containing the support is reused up to this size ratio (exact either
# way; saves kernel spectra while a contact shrinks). Preconditioner boxes are not reused: a box
# larger than the support weakens M, and the s = 0.2 power-law Newton test then stalls.
_REUSE_UP_TO = 2.0
_FULL_ABOVE = 0.7  # a window with more FFT points than this fraction of the full padding uses the full one


def diagonal_coefficient(step, E_star):
    """Diagonal influence coefficient ``C_nn = c / (pi E*) w_t(0, 0)`` [length/pressure] (eq. 6).

    The closure of a node under its own unit pyramid; the paper states layer
    compliances in units of it (``lam = 10 C_nn``, Fig. 5).
    """
    return check_positive("step", step) / (math.pi * check_positive("E_star", E_star)) * float(template(0.0, 0.0))


def _contains(outer, inner):
    """Whether the box ``outer`` holds every row and column of ``inner``."""
    def within(o, i):
        return i[1] == 0 or (o[0] <= i[0] and i[0] + i[1] <= o[0] + o[1])

    return all(within(o, i) for o, i in zip(outer[0], inner[0])) and within(outer[1], inner[1])


def _block_product(S, V):
    """``V_a <- sum_b S_ab V_b`` in place on a pair of spectra, two temporaries."""
    t = S[0][1] * V[1]
    V[1] *= S[1][1]
    V[1] += S[1][0] * V[0]
    V[0] *= S[0][0]
    V[0] += t
    return V


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
    input must be zero; they are zero on output too. The FFTs use
    :func:`bem.fft.threads` threads.
    """

    def __init__(self, lattice, E_star):
        self.lattice = lattice
        self.n_matvec = 0  # products C p so far (the work measure of ContactResult.n_matvec)
        self.E_star = check_positive("E_star", E_star)
        n_rows, n_cols = lattice.shape
        self._start = tuple(0 if int(lattice.parity[0]) == a else 1 for a in (0, 1))  # first brick row of parity a
        self._n = tuple(len(range(s, n_rows, 2)) for s in self._start)  # rows of parity a
        # w_t at every offset (m/2, n sqrt3/2), m = n mod 2 (lattice units), times c / (pi E*)
        n = np.arange(n_rows)[:, None]
        t = np.arange(n_cols + 1)[None, :]
        self._table = template((2 * t + n % 2) / 2.0, n * (math.sqrt(3.0) / 2))
        self._table *= lattice.step / (math.pi * self.E_star)
        self._spectra = OrderedDict()
        self.diagonal = diagonal_coefficient(lattice.step, self.E_star)

    # -- geometry of the 2 x 2 block convolution -------------------------------------------------

    def _parity_rows(self, v):
        """Views of the even-class and odd-class rows of a brick array."""
        return [v[s::2] for s in self._start]

    def _box(self, v):
        """Snapped bounding box of the support of ``v``: parity row ranges and a column range.

        Returns ``None`` for ``v = 0``.
        """
        n_rows, n_cols = v.shape
        rows = np.flatnonzero(v.any(axis=1))  # NaN counts as support
        if rows.size == 0:
            return None
        first, last = int(rows[0]), int(rows[-1])
        cols = np.flatnonzero(v[first : last + 1].any(axis=0))
        gr, gc = -(-n_rows // _SNAP), -(-n_cols // _SNAP)
        r0, r1 = (first - 1) // gr * gr, min(n_rows, (last + 1 + gr) // gr * gr)
        c0, c1 = (int(cols[0]) - 1) // gc * gc, min(n_cols, (int(cols[-1]) + 1 + gc) // gc * gc)
        r0, c0 = max(r0, 0), max(c0, 0)
        ranges = []
        for s, n in zip(self._start, self._n):
            k0, k1 = min(n, max(0, -(-(r0 - s) // 2))), min(n, max(0, -(-(r1 - s) // 2)))
            ranges.append((k0, k1 - k0))
        return tuple(ranges), (c0, c1 - c0)

    def _full(self):
        return tuple((0, n) for n in self._n), (0, self.lattice.shape[1])

    def _kernel_spectra(self, out_box, in_box):
        """Spectra ``S_ab`` of the blocks mapping ``in_box`` data to ``out_box`` values.

        A box is ``((k0_even, rows_even), (k0_odd, rows_odd)), (q0, cols)`` in parity
        row and column indices. The input block sits at the origin of the padded
        array and the kernel is stored shifted so that the output lands at the
        origin too; the padding ``out + in - 1`` per axis leaves no wrap-around.
        Returns the padded shape and the spectra divided by the padded size.
        """
        (o_rows, (oq, nq)), (i_rows, (iq, bq)) = out_box, in_box
        lk = fft.fast_length(max(o[1] for o in o_rows) + max(i[1] for i in i_rows) - 1, real=False)
        lq = fft.fast_length(nq + bq - 1, real=True)
        f = np.r_[0:nq, -(bq - 1) : 0]  # circular column positions
        dq = f + oq - iq  # column offset output - input
        kernels = np.zeros((2, 2, lk, lq))
        for a in (0, 1):
            for b in (0, 1):
                (oa, na), (ib, nb) = o_rows[a], i_rows[b]
                e = np.r_[0:na, -(nb - 1) : 0]
                dr = self._start[a] - self._start[b] + 2 * (e + oa - ib)  # brick row offset
                t = (np.abs(2 * dq + (a - b)) - (a != b)) // 2  # table column (x offset in half steps)
                block = self._table.take(np.abs(dr), axis=0).take(t, axis=1)  # rows e, columns f
                for rows, src_r in ((slice(0, na), slice(0, na)), (slice(lk - nb + 1, lk), slice(na, None))):
                    for cols, src_c in ((slice(0, nq), slice(0, nq)), (slice(lq - bq + 1, lq), slice(nq, None))):
                        kernels[a, b, rows, cols] = block[src_r, src_c]
        kernels /= lk * lq
        return (lk, lq), fft.forward(kernels, (lk, lq))

    def _cached(self, key, build):
        if key in self._spectra:
            self._spectra.move_to_end(key)
            return self._spectra[key]
        value = build()
        self._spectra[key] = value
        while len(self._spectra) > _WINDOWS_KEPT:
            self._spectra.popitem(last=False)
        return value

    def _reuse(self, kind, box, size):
        """A cached box of this kind that contains ``box`` at most ``_REUSE_UP_TO`` times its size."""
        best = None
        for key in self._spectra:
            if key[0] == kind and _contains(key[1], box) and size(key[1]) <= _REUSE_UP_TO * size(box):
                best = key[1] if best is None or size(key[1]) < size(best) else best
        return best

    def _window(self, box):
        """Kernel spectra for input on ``box`` (or a cached window containing it), output everywhere."""
        full, n_cols = self._full(), self.lattice.shape[1]

        def size(b):  # padded FFT points, up to the fast-length rounding
            return (max(self._n) + max(r[1] for r in b[0])) * (n_cols + b[1][1])

        if size(box) > _FULL_ABOVE * size(full):
            box = full
        box = self._reuse("C", box, size) or box
        return box, self._cached(("C", box), lambda: self._kernel_spectra(full, box))

    def _convolve(self, spectra, shape, v, in_box, out_box, out):
        """``out[out_box] = sum_b S_ab v_b[in_box]``; other entries of ``out`` are left alone."""
        (i_rows, (iq, bq)), (o_rows, (oq, nq)) = in_box, out_box
        data = np.zeros((2, max(r[1] for r in i_rows), bq))
        for b, vb in enumerate(self._parity_rows(v)):
            k0, nb = i_rows[b]
            data[b, :nb] = vb[k0 : k0 + nb, iq : iq + bq]
        V = _block_product(spectra, fft.forward(data, shape))
        res = fft.inverse(V, shape, (max(r[1] for r in o_rows), nq))
        for a, oa in enumerate(self._parity_rows(out)):
            k0, na = o_rows[a]
            oa[k0 : k0 + na, oq : oq + nq] = res[a, :na]
        out[self._start[1] :: 2, -1] = 0.0  # the masked last node of the odd rows

    # -- public products ---------------------------------------------------------------------------

    def matvec(self, p):
        """Return ``u = C p`` for a brick array ``p`` [pressure] -> [length]."""
        self.n_matvec += 1
        p = np.asarray(p, dtype=float)
        box = self._box(p)
        if box is None:
            return np.zeros(self.lattice.shape)
        out = np.empty(self.lattice.shape)  # every entry is written below
        box, (shape, spectra) = self._window(box)
        self._convolve(spectra, shape, p, box, self._full(), out)
        return out

    __call__ = matvec

    def preconditioner(self, lam=0.0, floor=0.5, box="support"):
        """FFT preconditioner ``z ~ (C + lam I)^-1 r`` for the conjugate gradients.

        The inverse of the 2 x 2 block symbol of the zero-padded (circulant)
        embedding of ``C + lam I`` over the snapped bounding box of the support
        of ``r`` (Vollebregt 2014: the solvers apply it to residuals that vanish
        off the contact, and mask its output to the contact). Truncating the
        ``1/r`` kernel at the padding edge makes a few symbol eigenvalues small
        or negative; they are raised to ``floor * C_nn + lam`` so that ``M``
        stays positive definite.

        Parameters
        ----------
        lam : float
            Uniform layer compliance [length/pressure] added on the diagonal.
        floor : float
            Eigenvalue floor as a fraction of the diagonal coefficient ``C_nn``.
        box : {"support", "full"}
            ``"support"``: the embedding over the snapped bounding box of the
            support of each ``r``, 0 outside it; for all ``r`` with one box it
            is one symmetric positive definite operator. ``"full"``: over the
            whole candidate region, one SPD operator for every ``r``. Measured on
            the issue problem (1,048,703 nodes, contact 4 % of the region): same
            15 iterations, Hertz solve 1.30 s against 2.06 s with ``"full"``.

        Returns
        -------
        callable
            ``M(r)`` on brick arrays.
        """
        from .checks import check_choice

        full = check_choice("box", box, ("support", "full")) == "full"
        symbols = {}

        def apply(r):
            r = np.asarray(r, dtype=float)
            out = np.zeros(self.lattice.shape)
            box = self._box(r)
            if box is None:
                return out
            if full:
                box = self._full()
            if box not in symbols:
                shape, K = self._cached(("M", box), lambda: self._kernel_spectra(box, box))
                symbols.clear()  # one box at a time: the contact moves rarely
                symbols[box] = shape, self._inverse_symbol(K, shape, lam, floor)
            shape, spectra = symbols[box]
            self._convolve(spectra, shape, r, box, box, out)
            return out

        return apply

    def _inverse_symbol(self, K, shape, lam, floor):
        """Spectra of ``(K + lam)^-1`` for a symmetric 2 x 2 block symbol (eigenvalues floored)."""
        lam_hat = lam / (shape[0] * shape[1])  # spectra carry the 1/(Lk Lq) of the inverse FFT
        A, D, B = K[0, 0].real + lam_hat, K[1, 1].real + lam_hat, K[0, 1]
        m = (A + D) / 2
        d = np.sqrt(((A - D) / 2) ** 2 + np.abs(B) ** 2)
        low = (floor * self.diagonal + lam) / (shape[0] * shape[1])
        inv_hi = 1.0 / np.maximum(m + d, low)
        inv_lo = 1.0 / np.maximum(m - d, low)
        # H^-1 = P+/l+ + P-/l-,  P+ = (H - (m - d) I) / (2 d),  P- = I - P+
        with np.errstate(divide="ignore", invalid="ignore"):
            safe = d > 1e-14 * np.abs(m)
            half = np.where(safe, 0.5 / np.where(safe, d, 1.0), 0.0)
        diff = inv_hi - inv_lo
        pb = B * half * diff
        scale = 1.0 / (shape[0] * shape[1]) ** 2  # inverse of a 1/(Lk Lq) symbol, times 1/(Lk Lq)
        return ((inv_lo + np.where(safe, (A - m + d) * half, 0.5) * diff) * scale, pb * scale), \
            (np.conj(pb) * scale, (inv_lo + np.where(safe, (D - m + d) * half, 0.5) * diff) * scale)

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



# --- convolution with any sampled kernel of definite parity (used by bem.stress) -------------------


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

    def apply(self, terms):
        """``sum over (spectrum, input) of K * v`` on the nodes of the lattice.

        Parameters
        ----------
        terms : list of (spectrum, input)
            :meth:`spectrum` and :meth:`transform` results; the spectra share their batch
            shape and their parity.

        Returns
        -------
        ndarray, shape (..., n_rows, n_cols)
            Brick arrays (batch axes of the spectra first).
        """
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
