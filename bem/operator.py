"""The influence operator ``C`` of eq. 6, applied by zero-padded FFT convolution.

``C[n, m] = c / (pi E*) * w_t((r_n - r_m) / c)``, with ``w_t`` the closed-form
template of :func:`bem.template.template`. ``C`` depends only on the lattice
offset between two nodes, so ``u = C p`` is a discrete (non-periodic)
convolution. In the brick storage of :class:`bem.lattice.Lattice` the offset
also depends on the parities of the two rows, so the rows are split into their
even and odd classes (strided views, no copy) and ``u`` is a 2 x 2 block
convolution ``u_a = sum_b K_ab * p_b`` on the half-height arrays, evaluated
exactly with pruned real FFTs (:mod:`bem.pruned_fft`): cost ``O(N log N)``, memory
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
    the window only changes the cost (``benchmarks/side_by_side.py`` measures it;
    ``docs/performance.md``).
"""

from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np

from . import pruned_fft
from .backend import get_backend
from .block_symbol import (block_product, block_quadratic, inverse_symbol, kernel_spectra, padded_shape, single_symbol,
                           table_extent)
from .checks import check_positive
from .column_bands import BANDS_ABOVE, PairedSymbol, convolve_by_bands, paired_spectra
from .matrix_views import dense, linear_operator
from .template import diagonal_coefficient, lattice_table

__all__ = ["InfluenceOperator", "diagonal_coefficient"]

#: nodes of a lattice up to which :class:`InfluenceOperator` holds its coefficient table
TABLE_HELD_UP_TO = 1 << 20
_WINDOWS_KEPT = 3  # kernel spectra cached per operator (matvec windows, preconditioner boxes)
#: Spectrum entries of one row parity above which a product's inverse transform runs one parity at a
#: time (half its output held at once); below, both in one call (fewer, larger transforms)
SPLIT_INVERSE = 1 << 16
_SNAP = 16  # support boxes snap to a grid of 1/_SNAP of the region
# A cached matvec window containing the support is reused up to this size ratio (exact either
# way; saves kernel spectra while a contact shrinks). Preconditioner boxes are not reused: a box
# larger than the support weakens M, and the s = 0.2 power-law Newton test then stalls.
_REUSE_UP_TO = 2.0
# A window with more FFT points than this fraction of the full padding uses the full one: on a device, and on NumPy
# (four blocks below BANDS_ABOVE, paired above; measured in docs/performance.md); a cached paired window is reused
# up to this size ratio (the four blocks up to _REUSE_UP_TO)
_FULL_ABOVE, _NUMPY_FULL_ABOVE, _PAIRED_REUSE_UP_TO = 0.7, 0.85, 1.25


def _contains(outer, inner):
    """Whether the box ``outer`` holds every row and column of ``inner``."""
    def within(o, i):
        return i[1] == 0 or (o[0] <= i[0] and i[0] + i[1] <= o[0] + o[1])

    return all(within(o, i) for o, i in zip(outer[0], inner[0])) and within(outer[1], inner[1])


def _by_bands(backend, shape, single=False):
    """Whether a product of the padded ``shape`` runs by bands of columns: on NumPy above ``BANDS_ABOVE`` bytes of its
    pair of half spectra (complex128, complex64 where ``single``)."""
    return backend.is_numpy and 2 * shape[0] * (shape[1] // 2 + 1) * (8 if single else 16) > BANDS_ABOVE


def _rows(s, k0, n, n_rows):
    """Slice of the brick rows ``s + 2 k``, ``k0 <= k < k0 + n``, of an array of ``n_rows`` rows."""
    stop = s + 2 * (k0 + n) - 1
    return slice(s + 2 * k0, stop if stop < n_rows else None, 2)


class InfluenceOperator:
    """Matrix-free ``u = C p`` on the nodes of a lattice.

    Parameters
    ----------
    lattice : Lattice or bem.lattice.LatticeWindow
        The candidate region, or a window of it (the operator of the nodes in the window).
    E_star : float
        Effective modulus ``E*`` [pressure], ``1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2``.
    device : {"cpu", "cuda"} or module, optional
        Where the products run (:func:`bem.backend.get_backend`).
    bodies : bem.Bodies, optional
        Coated bodies: the influence coefficients are those of their compliance per mode
        (:func:`bem.coated_kernel.coated_table`, cached per step, shape and bodies); ``E_star``
        is then the substrates' (``bodies.E_star``), the scale of tolerances and bounds. ``None``
        or uncoated bodies: the half-space of ``E_star``.

    Notes
    -----
    Pressures are brick arrays of shape ``lattice.shape`` [pressure] in the device's
    namespace; displacements come back in the same shape and namespace [length]. Masked
    nodes of the input must be zero; they are zero on output too. On the CPU the FFTs use
    :func:`bem.fft.threads` threads. The kernel spectra of a support window are built on
    the host and copied to the device once per window (a few windows are cached).
    """

    def __init__(self, lattice, E_star, device="cpu", bodies=None):
        self.lattice = lattice
        self.backend = get_backend(device)
        self.mask = self.backend.asarray(lattice.mask, dtype=self.backend.xp.bool)  # candidate nodes, on the device
        # products C p and 2-D FFTs of lattice arrays (forward or inverse) so far: ContactResult's work measures
        self.n_matvec = self.n_transforms = 0
        self.E_star = check_positive("E_star", E_star)
        n_rows, n_cols = lattice.shape
        self._start = tuple(0 if int(lattice.parity[0]) == a else 1 for a in (0, 1))  # first brick row of parity a
        self._n = tuple(len(range(s, n_rows, 2)) for s in self._start)  # rows of parity a
        # the last node of the odd rows lies outside the region (a window off the right edge has none)
        self._masked_last = not bool(lattice.mask[:, -1].all())
        self.bodies = bodies if bodies is not None and bodies.is_coated else None
        self._held = None  # the coefficient table where it is held (see _table)
        if self.bodies is not None:  # coated bodies: the coefficients of bem.coated_kernel (cached)
            from .coated_kernel import coated_table

            self._held = coated_table(lattice.step, (n_rows, n_cols), self.bodies)
            self.diagonal = float(self._held[0, 0])
        else:
            self.diagonal = diagonal_coefficient(lattice.step, self.E_star)
        self._spectra = OrderedDict()
        self._quad = None

    def _table_within(self, shape):
        """``C`` at the offsets of a lattice of ``shape`` or more (:func:`bem.template.lattice_table`, or a coated
        body's table): held over the whole lattice where it has at most :data:`TABLE_HELD_UP_TO` nodes, made anew
        over ``shape`` where a symbol is built on larger ones (not held through the solve; the template costs little
        against the symbol's transforms)."""
        if self._held is None and math.prod(self.lattice.shape) <= TABLE_HELD_UP_TO:
            self._held = lattice_table(self.lattice.shape, self.lattice.step, self.E_star)
        return self._held if self._held is not None else lattice_table(shape, self.lattice.step, self.E_star)

    _table = property(lambda self: self._table_within(self.lattice.shape), doc="``C`` at every lattice offset.")

    # -- geometry of the 2 x 2 block convolution -------------------------------------------------

    def _box(self, v):
        """Snapped bounding box of the support of ``v``: parity row ranges and a column range (``None``: ``v = 0``)."""
        n_rows, n_cols = v.shape
        if self.backend.is_numpy:
            rows = np.flatnonzero(v.any(axis=1))  # NaN counts as support
            if rows.size == 0:
                return None
            first, last = int(rows[0]), int(rows[-1])
            cols = np.flatnonzero(v[first : last + 1].any(axis=0))
        else:  # the same on the device: two index vectors come back, not the array
            xp = self.backend.xp
            rows = xp.nonzero(xp.any(v != 0, axis=1))[0]
            if rows.shape[0] == 0:
                return None
            first, last = int(rows[0]), int(rows[-1])
            cols = xp.nonzero(xp.any(v[first : last + 1, :] != 0, axis=0))[0]
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

    def _kernel_spectra(self, out_box, in_box, hermitian=False):
        """:func:`bem.block_symbol.kernel_spectra` of this operator's coefficients at the offsets the boxes meet."""
        table = self._table_within(table_extent(self._start, out_box, in_box))
        return kernel_spectra(self.backend, table, self._start, out_box, in_box, hermitian)

    def _cached(self, key, build):
        if key in self._spectra:
            self._spectra.move_to_end(key)
            return self._spectra[key]
        value = build()
        self._spectra[key] = value
        while len(self._spectra) > _WINDOWS_KEPT:
            self._spectra.popitem(last=False)
        return value

    def _reuse(self, kind, box, size, up_to=_REUSE_UP_TO):
        """A cached box of this kind that contains ``box`` at most ``up_to`` times its size."""
        best = None
        for key in self._spectra:
            if key[0] == kind and _contains(key[1], box) and size(key[1]) <= up_to * size(box):
                best = key[1] if best is None or size(key[1]) < size(best) else best
        return best

    def _window(self, box):
        """Kernel spectra for input on ``box`` (or a cached window containing it), output everywhere: above
        ``BANDS_ABOVE`` bytes of the padded pair on NumPy :func:`bem.column_bands.paired_spectra` of the box widened
        to the same rows of both parities (half the memory of the four blocks of
        :func:`bem.block_symbol.kernel_spectra`), where every parity has those rows."""
        full, n_cols = self._full(), self.lattice.shape[1]

        def size(b):  # padded FFT points, up to the fast-length rounding
            return (max(self._n) + max(r[1] for r in b[0])) * (n_cols + b[1][1])

        paired = _by_bands(self.backend, padded_shape(full, box))
        if size(box) > (_NUMPY_FULL_ABOVE if self.backend.is_numpy else _FULL_ABOVE) * size(full):
            box = full
        up_to = _PAIRED_REUSE_UP_TO if paired else _REUSE_UP_TO
        box = self._reuse("C", box, size, up_to) or (self._reuse("P", box, size, up_to) if paired else None) or box
        first, end = min(r[0] for r in box[0]), max(r[0] + r[1] for r in box[0])
        if paired and box != full and end <= min(self._n):
            # the same rows of both parities (the box widened by at most a row): two blocks and the phase of the
            # shift between the parities
            box = (((first, end - first),) * 2, box[1])
            return box, self._cached(("P", box), lambda: paired_spectra(self._table, self._start, self._n, n_cols, box))
        return box, self._cached(("C", box), lambda: self._kernel_spectra(full, box, hermitian=box == full))

    def _parts(self, v, box):
        """The rows of each parity of ``v`` in ``box`` (views), for :func:`bem.pruned_fft.forward_parts`."""
        i_rows, (iq, bq) = box
        return [v[_rows(s, k0, nb, v.shape[0]), iq : iq + bq] for s, (k0, nb) in zip(self._start, i_rows)]

    def _batch(self, v, box, dtype, scale=None):
        """:meth:`_parts` gathered into one zero-filled ``(2, rows, cols)`` array of ``dtype`` (times ``scale``)."""
        xp = self.backend.xp
        data = xp.zeros((2, max(r[1] for r in box[0]), box[1][1]), dtype=dtype)
        for b, part in enumerate(self._parts(v, box)):  # the rows of parity b: brick rows s, s + 2, ...
            data[b, : part.shape[0], :] = xp.astype(part if scale is None else part * scale, dtype, copy=False)
        return data

    def _convolve(self, spectra, shape, v, in_box, out_box, out, single=False):
        """``out[out_box] = sum_b S_ab v_b[in_box]``; other entries of ``out`` are left alone (``single``: the
        transforms in single precision, with single-precision spectra)."""
        o_rows, (oq, nq) = out_box
        bk = self.backend
        self.n_transforms += 2  # the forward transform of the input's box, the inverse onto the output's
        if isinstance(spectra, PairedSymbol) or _by_bands(bk, shape, single):
            dests = [out[_rows(s, k0, na, out.shape[0]), oq : oq + nq] for s, (k0, na) in zip(self._start, o_rows)]
            convolve_by_bands(spectra, shape, self._parts(v, in_box), dests, np.float32 if single else np.float64)
        elif bk.is_numpy:  # the parities' rows transformed where they are, the products written where they go
            dtype = np.float32 if single else np.float64
            V = block_product(spectra, pruned_fft.forward_parts(self._parts(v, in_box), shape, dtype))
            for a, s in enumerate(self._start):
                k0, na = o_rows[a]
                pruned_fft.inverse_into(V[a], shape, out[_rows(s, k0, na, out.shape[0]), oq : oq + nq])
        else:
            self._convolve_device(spectra, shape, v, in_box, out_box, out, single)
        if self._masked_last:
            out[self._start[1] :: 2, -1] = 0.0  # the masked last node of the odd rows

    def _convolve_device(self, spectra, shape, v, in_box, out_box, out, single):
        """:meth:`_convolve` off NumPy: the parities gathered into one batch, its products split off."""
        o_rows, (oq, nq) = out_box
        bk = self.backend
        xp = bk.xp
        V = block_product(spectra, bk.forward(self._batch(v, in_box, xp.float32 if single else bk.float64), shape))
        split = V[0, ...].size > SPLIT_INVERSE  # large: one parity at a time, half the inverse's output held at once
        both = None if split else bk.inverse(V, shape, (max(r[1] for r in o_rows), nq))
        for a, s in enumerate(self._start):
            k0, na = o_rows[a]
            part = bk.inverse(V[a, ...], shape, (na, nq)) if split else both[a, :na, :]
            out[_rows(s, k0, na, out.shape[0]), oq : oq + nq] = xp.astype(part, out.dtype, copy=False)

    def quadratic(self, v):
        """``v.C v`` of a brick array ``v`` [pressure] -> [length pressure^2], without the product ``C v``: over the
        padded box of the support of ``v`` onto itself (:func:`bem.block_symbol.block_quadratic`), one forward
        transform of ``v / max |v|`` in single precision, the box's symbol rounded to single precision (kept for the
        next call on that box), the sum in double precision; relative error about ``1e-7``."""
        bk, xp = self.backend, self.backend.xp
        v = bk.asarray(v)
        box = self._box(v)
        if box is None:
            return 0.0
        if self._quad is None or self._quad[0] != box:
            self._quad = None  # one box at a time: the last one goes before the next is made
            shape, K = self._kernel_spectra(box, box, hermitian=True)
            self._quad = box, shape, single_symbol(xp, K)
        _, shape, symbol = self._quad
        s = max(float(xp.max(v)), -float(xp.min(v)))  # v / s in single precision: no overflow
        if not math.isfinite(s):
            return math.nan
        self.n_transforms += 1
        if bk.is_numpy:
            V = pruned_fft.forward_parts(self._parts(v, box), shape, np.float32, scale=1.0 / s)
        else:
            V = bk.forward(self._batch(v, box, xp.float32, 1.0 / s), shape)
        return block_quadratic(symbol, V, shape[1], xp) * s * s

    # -- public products ---------------------------------------------------------------------------

    def matvec(self, p, *, overwrite_p=False):
        """Return ``u = C p`` for a brick array ``p`` [pressure] -> [length]; with ``overwrite_p`` the contents of
        ``p`` may be destroyed: ``u`` is then written into a float64 ``p`` (one array of the lattice fewer)."""
        self.n_matvec += 1
        bk = self.backend
        p = bk.asarray(p)
        box = self._box(p)
        if box is None:
            return bk.xp.zeros(self.lattice.shape, dtype=bk.float64)
        # every entry is written below, after the input is read
        out = p if overwrite_p and p.dtype == bk.float64 else bk.xp.empty(self.lattice.shape, dtype=bk.float64)
        box, (shape, spectra) = self._window(box)
        self._convolve(spectra, shape, p, box, self._full(), out)
        return out

    __call__ = matvec

    def qp(self, h, *, lam=0.0, precondition=True, contact=None, **kw):
        """The constrained-CG step of Kalker's QP ``min 1/2 p.(C + lam) p + p.(h - delta), p >= 0``
        on this operator: :func:`bem.kalker.constrained_cg` (its arguments); a
        :class:`bem.cg_rules.QPSolution`."""
        from .kalker import constrained_cg

        return constrained_cg(self, h, lam=lam, precondition=precondition, contact=contact, **kw)

    def preconditioner(self, lam=0.0, floor=0.5, box="support", single=False, overwrite_r=False):
        """FFT preconditioner ``z ~ (C + lam I)^-1 r`` for the conjugate gradients.

        The inverse of the 2 x 2 block symbol of the zero-padded (circulant) embedding of ``C + lam I`` over the
        snapped bounding box of the support of ``r`` (Vollebregt 2014: the solvers apply it to residuals that vanish
        off the contact, and mask its output to the contact). Truncating the ``1/r`` kernel at the padding edge makes
        a few symbol eigenvalues small or negative; they are raised to ``floor * C_nn + lam`` so that ``M`` stays
        positive definite.

        Parameters
        ----------
        lam : float
            Uniform layer compliance [length/pressure] added on the diagonal.
        floor : float
            Eigenvalue floor as a fraction of the diagonal coefficient ``C_nn``.
        box : {"support", "full"}
            ``"support"``: the embedding over the snapped bounding box of the support of each ``r``, 0 outside it;
            for all ``r`` with one box it is one symmetric positive definite operator. ``"full"``: over the whole
            candidate region, one SPD operator for every ``r``. Where the contact is small ``"support"`` is cheaper
            for as many iterations (``benchmarks/side_by_side.py``; ``docs/performance.md``).
        single : bool
            Apply it in single precision (its symbol rounded to single precision, the transforms of ``r``
            in single precision; the output in double precision): half the memory of the symbol and
            about half the time of the transforms, for a preconditioner of the constrained CG, which only
            approximates ``(C + lam I)^-1``.
        overwrite_r : bool
            Whether ``M`` may destroy the contents of ``r``: ``M r`` is then written into a float64 ``r``.

        Returns
        -------
        callable
            ``M(r)`` on brick arrays.
        """
        from .checks import check_choice

        full = check_choice("box", box, ("support", "full")) == "full"
        symbols, bk = {}, self.backend

        def apply(r):
            r = bk.asarray(r)
            box = self._box(r)
            if box is None:
                return bk.xp.zeros(self.lattice.shape, dtype=bk.float64)
            if full:
                box = self._full()
            if box not in symbols:
                symbols.clear()  # one box at a time: the contact moves rarely
                symbols[box] = self._inverse_symbol(box, lam, floor, single)  # its spectra are not kept
            shape, spectra = symbols[box]
            # the output on the box, after its input is read; r = 0 off its box (the support's, or the whole region)
            out = r if overwrite_r and r.dtype == bk.float64 else bk.xp.zeros(self.lattice.shape, dtype=bk.float64)
            self._convolve(spectra, shape, r, box, box, out, single)
            return out

        return apply

    def _inverse_symbol(self, box, lam, floor, single=False):
        """``(shape, S)``: the spectra of ``(K + lam)^-1`` for the symbol ``K`` of ``box``
        (:func:`bem.block_symbol.inverse_symbol`), rounded to single precision where ``single``; ``K`` is kept,
        rounded, for :meth:`quadratic` on the same box (the support of a direction is the residual's)."""

        def spectra():
            if self._quad is not None and self._quad[0] != box:
                self._quad = None  # one box at a time
            shape, K = self._kernel_spectra(box, box, hermitian=True)
            if self._quad is None:
                self._quad = box, shape, single_symbol(self.backend.xp, K)
            return shape, K

        shape, S = inverse_symbol(self.backend, spectra, lam, floor, self.diagonal, single)
        if not single or self.backend.is_numpy:  # NumPy: rounded as it is made
            return shape, S
        return shape, single_symbol(self.backend.xp, S)

    def as_linear_operator(self):
        """``scipy.sparse.linalg.LinearOperator`` acting on the flattened candidate nodes."""
        return linear_operator(self)

    def dense(self):
        """The dense matrix ``C`` over the flattened candidate nodes (small problems only):
        :func:`bem.matrix_views.dense`, built at every node pair independently of the FFT path, so that the two can be
        checked against each other."""
        return dense(self.lattice, self.E_star, self._table if self.bodies is not None else None)
