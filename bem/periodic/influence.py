"""The periodic influence operator: ``u = C p`` on a periodic cell, by circular FFT convolution.

``C[n, m] = c / (pi E*) W(x_n - x_m)``, ``W`` the periodic template of
:func:`bem.periodic.kernel.periodic_template` (the pyramid and all its images, exact for the
pyramid basis, with zero mean). The displacement of any pressure therefore has zero mean
over the cell: a uniform pressure moves the periodic half-space rigidly by an undetermined
amount, which is fixed to zero. The approach of a periodic contact is measured against
this mean (:func:`bem.periodic.solve_periodic`).

As in :mod:`bem.operator`, the rows split by parity into two rectangular lattices, and
``u_a = sum_b K_ab * p_b`` is a 2 x 2 block convolution, here circular on arrays of
``(n_rows/2, n_cols)`` with no padding: two real FFTs of the cell per product. The operator
has the interface the solvers use (``lattice``, ``matvec``, ``preconditioner``,
``diagonal``, ``n_matvec``, ``qp``), so :func:`bem.kalker.solve_qp`, :func:`bem.newton.solve_newton`
and :mod:`bem.fixed_point` run on it unchanged.
"""

from __future__ import annotations

import math

import numpy as np

from .. import fft
from ..backend import backend_of, get_backend
from ..checks import check_positive, fail
from ..template import diagonal_coefficient
from .coated import coated_template
from .kernel import parity_spectra, periodic_spectra, periodic_template
from .spectra import mixed, weighted_dot
from .symbol import Symbol, inverse_blocks

__all__ = ["PeriodicOperator"]


def _checked_bodies(bodies, E_star):
    """``bodies`` when coated (checked against ``E_star``), ``None`` for homogeneous bodies."""
    if bodies is None:
        return None
    from ..coating import Bodies
    from ..errors import InputError

    if not isinstance(bodies, Bodies):
        raise InputError(f"bodies = {bodies!r} is not allowed: it must be a bem.Bodies or None.")
    if abs(bodies.E_star - E_star) > 1e-12 * E_star:
        raise InputError(f"E_star = {E_star!r} is not allowed with bodies: it must be bodies.E_star = "
                         f"{bodies.E_star!r}, the substrates' effective modulus.")
    return bodies if bodies.is_coated else None


def _checked_out(out, shape, dtype):
    """``out`` where it is a C-contiguous NumPy array of ``shape`` and ``dtype``; a new array where it is None."""
    if out is None:
        return np.empty(shape, dtype=dtype)
    if not (isinstance(out, np.ndarray) and out.shape == shape and out.dtype == dtype and out.flags.c_contiguous):
        got = f"{type(out).__name__} of shape {getattr(out, 'shape', None)} and dtype {getattr(out, 'dtype', None)}"
        fail("out", got, f"a C-contiguous NumPy array of shape {shape} and dtype {np.dtype(dtype)}")
    return out


def _packed(spectra):
    """The packed symbol ``(S_00, S_01)`` of :class:`bem.periodic.symbol.Symbol` from the spectra of
    :func:`bem.periodic.kernel.parity_spectra` (new arrays: the spectra themselves are not kept)."""
    d = np.empty((spectra.shape[1], 1, spectra.shape[2]))
    b = np.empty(d.shape, dtype=np.complex128)
    d[:, 0], b[:, 0] = spectra[0].real, spectra[1]
    return d, b


_SYMBOLS = {}  # (n_rows, n_cols, scale): the packed symbols of the last cells, the last used last
_SYMBOLS_KEPT = 8  # the levels of nested iteration of one or two cells


def _homogeneous_symbol(n_rows, n_cols, scale):
    """The packed symbol of the homogeneous operator of a cell, ``scale = c / (pi E*)``, read-only (:func:`_packed`);
    the last :data:`_SYMBOLS_KEPT` are kept."""
    key = (n_rows, n_cols, scale)
    if (symbol := _SYMBOLS.pop(key, None)) is None:
        symbol = _packed(periodic_spectra(n_rows, n_cols) * scale)
        for part in symbol:
            part.setflags(write=False)
    _SYMBOLS[key] = symbol
    while len(_SYMBOLS) > _SYMBOLS_KEPT:
        del _SYMBOLS[next(iter(_SYMBOLS))]
    return symbol


def forget_symbols(below):
    """Let go of the kept symbols of cells of fewer than ``below`` nodes (the coarser levels of a cell)."""
    for key in [key for key in _SYMBOLS if key[0] * key[1] < below]:
        del _SYMBOLS[key]


class PeriodicOperator:
    """Matrix-free ``u = C p`` on a :class:`bem.periodic.PeriodicCell`.

    Parameters
    ----------
    lattice : bem.periodic.PeriodicCell
        The cell.
    E_star : float
        Effective modulus ``E*`` [pressure].
    device : {"cpu", "cuda"} or module, optional
        Where the products run (:func:`bem.backend.get_backend`); brick arrays in and out are
        in its namespace. The kernel spectra are computed on the host once and copied over.
    bodies : bem.Bodies, optional
        Coated bodies: the operator carries their compliance per mode ``2 s(k) / k``
        (:func:`bem.periodic.coated.coated_template`); ``E_star`` must then be
        ``bodies.E_star``, the substrates'. ``None`` (or bodies without a coating): the
        homogeneous operator of ``E_star``.

    Attributes
    ----------
    diagonal : float
        The local self-compliance ``C_nn = c / (pi E*) w_t(0, 0)`` of the half-space (the
        scale of layer compliances and of the solvers' Jacobi estimates), as for
        :class:`bem.operator.InfluenceOperator`; the periodic coefficient ``C[n, n]`` differs
        from it by the images and the zero mean. With coatings it is scaled by the ratio of the
        periodic coefficients ``C[n, n]`` with and without them (the coating's ``C_nn`` for a
        thick coating, the substrate's for a thin one).
    """

    def __init__(self, lattice, E_star, device="cpu", *, bodies=None):
        self.lattice = lattice
        self.backend = bk = get_backend(device)
        self.mask = bk.asarray(lattice.mask, dtype=bk.xp.bool)
        self.E_star = check_positive("E_star", E_star)
        self.bodies = _checked_bodies(bodies, self.E_star)
        self.n_matvec = self.n_transforms = 0  # products, 2-D FFTs of brick arrays: ContactResult's work measures
        self.diagonal = diagonal_coefficient(lattice.step, self.E_star)
        self._spectrum_shape = (lattice.n_rows // 2, lattice.n_cols // 2 + 1)
        self._symbol32 = self._symbol = self._s00 = None
        scale = lattice.step / (math.pi * self.E_star)
        if self.bodies is None and bk.is_numpy:  # the packed symbol only, shared by the operators of a cell
            self._symbol = _homogeneous_symbol(lattice.n_rows, lattice.n_cols, scale)
            return
        w = self._template()
        if self.bodies is not None:
            self.diagonal *= w[0, 0] / periodic_template(lattice.n_rows, lattice.n_cols)[0, 0]
        spectra = parity_spectra(w * scale)
        if bk.is_numpy:
            self._symbol = _packed(spectra)
        else:
            self._s00, self._s01 = (bk.asarray(s, dtype=bk.xp.complex128) for s in spectra)  # S_10 = conj(S_01)

    def _template(self):
        """The dimensionless template of the cell: periodic, or of the coated bodies."""
        lat = self.lattice
        if self.bodies is None:
            return periodic_template(lat.n_rows, lat.n_cols, cache=False)
        return coated_template(lat.n_rows, lat.n_cols, lat.step, self.bodies)

    @property
    def kernel(self):
        """``C`` between node ``(0, 0)`` and node ``(q, r)`` [length/pressure], brick array (made at each call)."""
        return self._template() * (self.lattice.step / (math.pi * self.E_star))

    def _forward(self, v):
        """Spectra of the even and odd rows of a brick array: ``(2, n_rows/2, n_cols/2 + 1)``.

        The real FFT along the rows runs on the whole array at once; the complex FFT along the
        columns on each parity's strided rows, so the parities are never copied apart.
        """
        bk = self.backend
        self.n_transforms += 1
        rows = bk.rfft(v, axis=-1)
        out = bk.xp.empty((2,) + self._spectrum_shape, dtype=bk.xp.complex128)
        for a in (0, 1):
            out[a, ...] = bk.cfft(rows[a::2, :], axis=0)
        return out

    def spectrum(self, v, out=None):
        """Spectra of the two parities of a brick array, shape ``(n_rows/2, 2, n_cols/2 + 1)``.

        ``[:, a, :]`` is the 2-D real FFT of the rows of parity ``a``: one ``rfft2`` over the
        axes 0 and 2 of the view ``(n_rows/2, 2, n_cols)`` of the brick array, no copy. A float32
        array gives a complex64 spectrum. In the namespace of the operator's device (``xp.fft``
        off NumPy). ``out``: a C-contiguous array of that shape and dtype that receives it (NumPy; default: a
        new array, as off NumPy).
        """
        n_rows, n_cols = self.lattice.shape
        self.n_transforms += 1
        if not self.backend.is_numpy:
            xp = self.backend.xp
            return xp.fft.fft(xp.fft.rfft(xp.reshape(v, (n_rows // 2, 2, n_cols)), axis=2), axis=0)
        # the two 1-D passes of rfft2, the second in place: the same numbers, 10-15 % faster
        # (benchmarks/periodic_rough.py --cases products); each on the threads of bem.fft.in_parts
        out = _checked_out(out, (n_rows // 2, 2, n_cols // 2 + 1), np.result_type(v.dtype, np.complex64))
        return fft.cfft_in_place(fft.rfft_into(v.reshape(n_rows // 2, 2, n_cols), out, 2), 0, 2)

    def brick(self, spectrum, overwrite=False, out=None):
        """The brick array of a spectrum laid out as :meth:`spectrum` gives it (the inverse of it).

        ``overwrite``: the spectrum may be destroyed; ``out``: a C-contiguous array of the lattice's shape and the
        spectrum's real dtype that receives it (NumPy; default: a new array, as off NumPy)."""
        n_rows, n_cols = self.lattice.shape
        self.n_transforms += 1
        if not self.backend.is_numpy:
            xp = self.backend.xp
            return xp.reshape(xp.fft.irfft(xp.fft.ifft(spectrum, axis=0), n=n_cols, axis=2), (n_rows, n_cols))
        cols = fft.cfft_in_place(spectrum if overwrite else spectrum.copy(), 0, 2, inverse=True)  # irfft2 in two passes
        out = _checked_out(out, (n_rows, n_cols), cols.real.dtype).reshape(n_rows // 2, 2, n_cols)
        return fft.irfft_into(cols, out, n_cols, 2).reshape(n_rows, n_cols)

    @staticmethod
    def mix(spectrum, symbol, out=None):
        """``out_a = sum_b S_ab X_b`` on a spectrum ``X`` of :meth:`spectrum`'s layout, by a :meth:`symbol`.

        With ``(D, B)`` the symbol's arrays (:meth:`bem.periodic.symbol.Symbol.rows`: ``D[:, 0] = S_00 = S_11``,
        ``B[:, a] = S_a(1-a)``) ``out = D X + B X'``, ``X'`` the spectrum with its parities swapped: on NumPy over
        blocks of :data:`bem.fft.BLOCK` entries on :func:`bem.fft.in_parts` threads, the symbol's blocks made as
        they are used (:func:`bem.periodic.spectra.mixed`). ``out`` (default: a new array; C-contiguous, of the
        spectrum's shape and dtype) may be ``spectrum`` itself. Off NumPy, ``D X + B X'`` in the spectrum's
        namespace (a new array; ``out`` is not used).
        """
        if not isinstance(symbol, Symbol):  # a device's arrays
            d, b = symbol
            return d * spectrum + b * backend_of(spectrum).xp.flip(spectrum, axis=1)
        return mixed(spectrum, symbol, _checked_out(out, spectrum.shape, spectrum.dtype), None)[0]

    def mix_inner(self, spectrum, symbol, out=None):
        """:meth:`mix` and the :meth:`inner` of ``X`` and the product: ``(out, sum x y)``.

        On NumPy the sum is taken block by block as the product is made (no second pass over the two
        spectra), in double precision; ``out`` (as for :meth:`mix`) must not be ``spectrum``.
        """
        n_rows, n_cols = self.lattice.shape
        if not isinstance(symbol, Symbol):  # a device's arrays
            out = self.mix(spectrum, symbol)
            return out, self.inner(spectrum, out)
        if out is spectrum:
            raise ValueError("out: the product cannot overwrite the spectrum whose inner product it takes")
        out, sums = mixed(spectrum, symbol, _checked_out(out, spectrum.shape, spectrum.dtype), n_cols % 2 == 0)
        return out, sum(sums) / (n_rows // 2 * n_cols)

    def inner(self, x, y):
        """``sum x y`` over the cell of two real brick arrays from their spectra (:meth:`spectrum`)."""
        n_rows, n_cols = self.lattice.shape
        if not self.backend.is_numpy:  # in double precision on the device, as below
            xp = self.backend.xp
            weight = fft.half_spectrum_weights(n_cols, xp)
            w = (xp.astype(xp.real(x), xp.float64) * xp.astype(xp.real(y), xp.float64)
                 + xp.astype(xp.imag(x), xp.float64) * xp.astype(xp.imag(y), xp.float64))
            return float(xp.sum(w * weight)) / (n_rows // 2 * n_cols)  # one transfer to the host
        return weighted_dot(x, y, n_cols % 2 == 0) / (n_rows // 2 * n_cols)

    def symbol(self, lam=0.0, inverse=False, single=False):
        """The 2 x 2 block symbol of ``C + lam I``, or of :meth:`preconditioner` (``inverse``), for :meth:`mix`.

        On NumPy a :class:`bem.periodic.symbol.Symbol` over the operator's packed symbol (its blocks made as a
        product uses them: no array of their own). On a device ``(D, B)``, arrays in its namespace: the diagonal
        blocks are real and equal (the kernel of a parity on itself is even, and the same for both parities), ``D``
        holds their real part once, shape ``(n_rows/2, 1, n_cols/2 + 1)``, ``B`` the off-diagonal blocks, shape
        ``(n_rows/2, 2, n_cols/2 + 1)``. ``single``: in single precision (float32, complex64), rounded from the
        double-precision blocks.
        """
        if self.backend.is_numpy:
            return Symbol(*self._symbol, lam=float(lam), inverse=inverse, shift=self._shift, single=single)
        if inverse:
            return self._pack(*self._inverse_blocks(lam), single=single)
        if self._symbol is None:  # packed from its spectra once
            self._symbol = self._pack(self.backend.xp.real(self._s00), self._s01)
        d, b = self._symbol
        if single and not lam:  # the symbol of C alone, rounded once per operator
            if self._symbol32 is None:
                self._symbol32 = self._rounded(d, b)
            return self._symbol32
        d = d + lam if lam else d
        return self._rounded(d, b) if single else (d, b)

    def _rounded(self, d, b):
        """``(D, B)`` of :meth:`symbol` on a device rounded to single precision."""
        xp = self.backend.xp
        return xp.astype(d, xp.float32), xp.astype(b, xp.complex64)

    @staticmethod
    def _pack(d00, s01, single=False):
        """``(D, B)`` of :meth:`symbol` on a device from the real diagonal block ``d00`` and ``S_01`` (``S_10`` its
        conjugate), in their namespace."""
        xp = backend_of(d00).xp
        d = xp.reshape(d00, (d00.shape[0], 1, d00.shape[1]))
        b = xp.stack([s01, xp.conj(s01)], axis=1)
        return (xp.astype(d, xp.float32), xp.astype(b, xp.complex64)) if single else (d, b)

    def _apply(self, v, s00, s01, s10, s11, single=False):
        """``out_a = sum_b S_ab v_b`` by the spectra ``S`` of a 2 x 2 block symbol (NumPy: ``s00`` is ``(D, B)``;
        ``single``: a single-precision ``(D, B)``, the transforms in single precision, the result in double)."""
        bk = self.backend
        if bk.is_numpy:
            x = self.spectrum(np.asarray(v, dtype=np.float32 if single else float))
            out = self.brick(self.mix(x, s00, out=x), overwrite=True)
            return out.astype(np.float64) if single else out

        P = self._forward(bk.asarray(v))
        u1 = s10 * P[0, ...]
        u1 += s11 * P[1, ...]
        P[0, ...] *= s00
        P[0, ...] += s01 * P[1, ...]
        P[1, ...] = u1
        rows = bk.xp.empty((self.lattice.n_rows, self._spectrum_shape[1]), dtype=bk.xp.complex128)
        self.n_transforms += 1
        for a in (0, 1):
            rows[a::2, :] = bk.cfft(P[a, ...], axis=0, inverse=True)
        return bk.irfft(rows, n=self.lattice.n_cols, axis=-1)

    def matvec(self, p, *, overwrite_p=False):
        """Return ``u = C p`` for a brick array ``p`` [pressure] -> [length]; ``u`` has zero mean (a new array: the
        ``overwrite_p`` of :meth:`bem.InfluenceOperator.matvec` is accepted, and ``p`` kept)."""
        self.n_matvec += 1
        if self.backend.is_numpy:
            return self._apply(p, self.symbol(), None, None, None)
        return self._apply(p, self._s00, self._s01, self.backend.xp.conj(self._s01), self._s00)

    __call__ = matvec

    def qp(self, h, *, lam=0.0, precondition=True, contact=None, **kw):
        """The constrained-CG step of Kalker's QP ``min 1/2 p.(C + lam) p + p.(h - delta), p >= 0``
        on the cell: preconditioned, in the Fourier basis on every device
        (:func:`bem.periodic.qp.solve_periodic_qp`, whose preconditioner for a ``lam`` per node
        starts from the contact of ``x0``), else :func:`bem.kalker.constrained_cg`; either may hold its
        iterate in ``x0`` with ``overwrite_x0``; a :class:`bem.cg_rules.QPSolution`."""
        if precondition:
            from .qp import solve_periodic_qp

            return solve_periodic_qp(self, h, lam=lam, **kw)
        from ..kalker import constrained_cg

        return constrained_cg(self, h, lam=lam, precondition=precondition, contact=contact, **kw)

    def shared_model_state(self):
        """Keyword arguments of :meth:`qp` that the preconditioned model QPs of one Newton solve share
        (:func:`bem.newton.solve_newton`): the direction of their oblique projection (made by the first)."""
        from .qp_parts import Projection

        return {"projection": Projection()}

    def preconditioner(self, lam=0.0, single=False):
        """``z = (C + lam I)^-1 r`` on the whole cell, by the inverse 2 x 2 block symbol.

        Exact for a contact over the whole cell. The constant mode, where ``C`` vanishes
        (zero mean), gets the eigenvalue ``C_nn + lam`` instead, so that ``M`` is symmetric
        positive definite for every ``lam >= 0``.

        Parameters
        ----------
        lam : float
            Uniform layer compliance [length/pressure] added on the diagonal.
        single : bool
            On NumPy: the symbol and the transforms in single precision (the output in double
            precision), as the preconditioner of :func:`bem.periodic.qp.solve_periodic_qp`; on a
            device it runs in double precision.

        Returns
        -------
        callable
            ``M(r)`` on brick arrays.
        """
        single = single and self.backend.is_numpy
        if self.backend.is_numpy:
            i00, i01, i10, i11 = self.symbol(lam, inverse=True, single=single), None, None, None
        else:
            a, b = self._inverse_blocks(lam)
            i00, i01, i10, i11 = a, b, self.backend.xp.conj(b), a

        def apply(r):
            return self._apply(r, i00, i01, i10, i11, single)

        return apply

    @property
    def _shift(self):
        """What the inverse symbol adds at frequency 0 (:func:`bem.periodic.symbol.inverse_blocks`): the constant mode
        ``(1, 1) / sqrt 2``, where ``C`` vanishes, takes the eigenvalue ``C_nn + lam``."""
        return 0.5 * float(self.diagonal)

    def _inverse_blocks(self, lam):
        """The blocks ``(I00, I01)`` of the symbol of :meth:`preconditioner` on a device (``I11 = I00``, ``I10 =
        conj(I01)``), by :func:`bem.periodic.symbol.inverse_blocks` as :meth:`bem.periodic.symbol.Symbol.rows` makes
        them on NumPy.

        ``C`` is symmetric, so its symbol is Hermitian: ``S_11 = S_00`` is real and
        ``S_10 = conj(S_01)``. The determinant ``S_00^2 - |S_01|^2`` is then real, ``I00 = I11``
        is real and ``I10 = conj(I01)``.
        """
        xp = self.backend.xp
        return inverse_blocks(xp, xp.real(self._s00) + lam, self.backend.copy(self._s01), self._shift)

    def dense(self):
        """The dense matrix ``C`` over the flattened nodes (small cells only), from :attr:`kernel` by offsets."""
        lat = self.lattice
        n_rows, n_cols = lat.shape
        if lat.n_nodes > 20000:
            raise MemoryError(f"dense C for {lat.n_nodes} nodes would need {8 * lat.n_nodes**2 / 1e9:.1f} GB")
        r = np.repeat(np.arange(n_rows), n_cols)
        q = np.tile(np.arange(n_cols), n_rows)
        i, j = q - r // 2, r  # lattice coordinates
        di, dj = i[:, None] - i[None, :], j[:, None] - j[None, :]
        return self.kernel[np.mod(dj, n_rows), np.mod(di + np.floor_divide(dj, 2), n_cols)]
