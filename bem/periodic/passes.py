"""Element-wise passes of :mod:`bem.periodic.qp` over the whole cell, and the block products of its spectra, as
compiled kernels on the FFT threads.

With numba installed (the optional extra ``contactlab[fast]``) and a cell of at least :data:`MIN_NODES` nodes, the
periodic QP on NumPy makes these passes with the kernels of this module, each split into :func:`bem.fft.threads`
contiguous parts run at once (:func:`bem.fft.in_parts`):

- ``scan``: ``min (u + h)``, ``max u`` and ``min u`` (the KKT residual and its scale) and the mask
  ``(u + h < delta) & (p == 0)`` of the nodes that may enter the contact, in one pass with no array of the gap
  (``gap``: the extremes with the gap ``g = u + h`` written into an array, for the bounded QP of a hardness);
- ``subtract_scaled``: the update ``u = s (u - tau (C + lam) t)`` from the product in single precision (``s`` the
  rescaling to the force), one pass instead of three;
- ``add_at``: ``x[idx] += times * values`` in ``x``'s precision (a compliance per node's terms of ``u``, a gap's
  offset), one pass instead of a gather, a sum and a scatter;
- ``gather``: the preconditioned gap (single precision) or a compliance per node at the contact's nodes, in double
  precision;
- ``gap_at``: the gap ``u + h`` at the contact's nodes (or the entering ones), one gather instead of two and a sum;
- ``merge``: the next contact made from the step, its nodes that stayed and the entering ones merged in order, with
  their pressures, into given arrays (:class:`bem.periodic.qp_parts.ContactNodes`), in one pass (serial);
- ``mix``: the 2 x 2 block product of a spectrum (:func:`bem.periodic.spectra.mixed`, every product with ``C``
  or its inverse), the blocks of the :class:`bem.periodic.symbol.Symbol` made per entry in the spectrum's
  precision, and, for the curvature of the step, its weighted sum with the spectrum, one pass instead of four.

Without numba, or on a smaller cell, the same passes run as the NumPy forms (:func:`numpy_kernels`,
:func:`bem.periodic.spectra.numpy_mixed`; the merge as ``numpy.insert`` in :class:`bem.periodic.qp_parts.ContactNodes`).
The element-wise passes give NumPy's numbers bit for bit: each makes the same operations in the same precision at every
node, and their reductions are minima and maxima, whose value does not depend on their order; a NaN propagates as in
NumPy. The merge copies values. The block product rounds each operation as written (NumPy's
loops may fuse a multiply and an add: the two can differ in the last bit) and sums each block of rows in the order
of its entries (``tests/bem/test_periodic_passes.py``). Selections and most gathers stay NumPy's, faster than a
compiled loop at these sizes (``docs/performance.md``, "Compiled passes").

Loading the kernels costs the process numba's import and its cached machine code, once (:func:`load`; the first
run after an install compiles them into ``__pycache__``).
"""

from __future__ import annotations

import numpy as np

from .. import fft

__all__ = ["MIN_NODES", "kernels", "load", "numpy_kernels"]

MIN_NODES = 1 << 18  # below it a pass is too short for the threads' start
CHUNK = 1 << 16  # nodes a part of the NumPy form of ``scan`` (a buffer of 512 kB)
_COMPILED = []  # the compiled kernels, made at the first call of kernels()


class _NumPyKernels:
    """The NumPy forms of the kernels (the reference of the compiled ones)."""

    compiled = False

    @staticmethod
    def gap(u, h, g):
        """``(g, min g, max u, min u)`` for ``g = u + h``, made in ``g``'s buffer."""
        np.add(u, h, out=g)
        return g, float(g.min()), float(u.max()), float(u.min())

    @staticmethod
    def scan(u, h, delta, p, out):
        """``(out, min (u + h), max u, min u)`` with ``out = (u + h < delta) & (p == 0)`` (boolean, the cell's
        shape), the sum made a part of :data:`CHUNK` nodes at a time where every array is contiguous (no array of
        the cell's size)."""
        if not all(a.flags.c_contiguous for a in (u, h, p, out)):  # no flat view of each: the whole arrays
            g = np.add(u, h)
            return np.logical_and(g < delta, p == 0, out=out), float(g.min()), float(u.max()), float(u.min())
        uf, hf, pf, of = u.reshape(-1), h.reshape(-1), p.reshape(-1), out.reshape(-1)
        buf, zero, lows = np.empty(min(CHUNK, uf.size)), np.empty(min(CHUNK, uf.size), dtype=bool), []
        for i in range(0, uf.size, CHUNK):
            n = min(CHUNK, uf.size - i)
            g = np.add(uf[i : i + n], hf[i : i + n], out=buf[:n])
            lows.append(float(g.min()))
            np.logical_and(np.less(g, delta, out=of[i : i + n]), np.equal(pf[i : i + n], 0, out=zero[:n]),
                           out=of[i : i + n])
        return out, float(np.min(lows)), float(u.max()), float(u.min())

    @staticmethod
    def subtract_scaled(u, r, tau, s=1.0):
        """``u = (u - r * tau) * s`` with ``r * tau`` rounded to ``r``'s precision (float32) first and ``s`` to
        ``u``'s; ``r`` is overwritten."""
        r *= np.float32(tau)
        u -= r
        if s != 1.0:
            u *= u.dtype.type(s)  # in u's precision

    @staticmethod
    def add_at(x, idx, values, times=1.0):
        """``x[idx] += times * values`` at the distinct flat indices ``idx``, the sum rounded to ``x``'s precision;
        ``x``."""
        flat = x.reshape(-1)
        flat[idx] = (np.take(flat, idx) + times * values).astype(x.dtype, copy=False)
        return x

    @staticmethod
    def gather(x, idx):
        """``x`` (float32 or float64) at the flat indices ``idx``, in double precision."""
        return np.take(x.reshape(-1), idx).astype(np.float64)

    @staticmethod
    def gap_at(u, h, idx):
        """``u + h`` at the flat indices ``idx`` (float64)."""
        return np.take(u.reshape(-1), idx) + np.take(h.reshape(-1), idx)


class _NamespaceKernels:
    """The forms on another array namespace (:class:`bem.backend.Backend` ``bk``): new arrays where NumPy reuses
    buffers (``g`` is not used)."""

    compiled = False

    def __init__(self, bk):
        self.bk = bk

    def gap(self, u, h, g):
        xp = self.bk.xp
        g = u + h
        return g, float(xp.min(g)), float(xp.max(u)), float(xp.min(u))

    def scan(self, u, h, delta, p, out):
        g, *rest = self.gap(u, h, None)
        return ((g < delta) & (p == 0), *rest)

    def subtract_scaled(self, u, r, tau, s=1.0):
        r *= tau
        u -= r
        if s != 1.0:
            u *= s

    def add_at(self, x, idx, values, times=1.0):
        return self.bk.add_at(x, idx, times * values)

    def gather(self, x, idx):
        return self.bk.xp.astype(self.bk.take(x, idx), self.bk.xp.float64)

    def gap_at(self, u, h, idx):
        return self.bk.take(u, idx) + self.bk.take(h, idx)


def numpy_kernels():
    """The NumPy forms of the kernels."""
    return _NumPyKernels


def kernels(n_nodes, bk=None):
    """The kernels for a cell of ``n_nodes`` nodes: compiled where numba is installed and the cell has at least
    :data:`MIN_NODES` nodes, else :func:`numpy_kernels`; off NumPy their forms in the backend's namespace.

    Parameters
    ----------
    n_nodes : int
        Nodes of the cell.
    bk : bem.backend.Backend, optional
        The arrays' backend (default: NumPy).

    Returns
    -------
    class or object
        Methods ``gap(u, h, g)``, ``scan(u, h, delta, p, out)`` (``out`` a boolean brick array, or None off NumPy),
        ``subtract_scaled(u, r, tau, s=1.0)``, ``add_at(x, idx, values, times=1.0)`` (``x``; on NumPy
        in place), ``gather(x, idx)``, ``gap_at(u, h, idx)`` (and, compiled,
        ``mix(spectrum, symbol, out, even, rows)`` and ``merge(idx, values, stayed, new, new_values, out_idx,
        out_values, at)``) and the flag ``compiled``.
    """
    return chosen(n_nodes, bk, _NumPyKernels, _NamespaceKernels, _COMPILED, _compile)


def chosen(n_nodes, bk, numpy_form, namespace_form, compiled, compile):
    """The form of a family of kernels for a cell of ``n_nodes`` nodes: ``namespace_form(bk)`` off NumPy, else the
    compiled one where the cell has at least :data:`MIN_NODES` nodes and ``compile()`` made one (kept in the list
    ``compiled`` at its first call; None without numba), else ``numpy_form``."""
    if bk is not None and not bk.is_numpy:
        return namespace_form(bk)
    if n_nodes < MIN_NODES:
        return numpy_form
    if not compiled:
        compiled.append(compile())
    return compiled[0] or numpy_form


def run_in_parts(kernel, n):
    """``kernel(lo, hi)`` on the parts of ``range(n)`` on the FFT threads (:func:`bem.fft.in_parts`); their results
    in the order of the parts."""
    res = {}
    fft.in_parts(lambda part: res.__setitem__(part.start, kernel(part.start, part.stop)), n, n)
    return [res[k] for k in sorted(res)]


def load():
    """Load the compiled kernels now, for every precision the QP passes them, rather than at the first large cell.

    A clock started after it does not count numba's import and the load of the kernels' cached machine code (a
    fraction of a second a process, ``benchmarks/cases.py`` measures it; seconds of compilation at the first run
    after an install). Does nothing without numba.

    Returns
    -------
    bool
        Whether the compiled kernels are in use on large cells.
    """
    from .symbol import Symbol

    k = kernels(MIN_NODES)
    if k.compiled:
        x64, x32, idx = np.zeros(4), np.zeros(4, dtype=np.float32), np.arange(2)
        for u in (x64, x32):  # the iterate's product in double or in single precision
            k.gap(u, x64, np.empty(4))
            k.scan(u, x64, 0.0, x64, np.empty(4, dtype=bool))
            k.subtract_scaled(u, x32.copy(), 1.0, 2.0)
            k.add_at(u, idx, x64[:2])
        for u in (x64, x32):
            k.gap_at(u, x64, idx)
            k.gather(u, idx)
        at, flag = np.empty(1, dtype=np.intp), np.ones(2, dtype=bool)
        k.merge(idx, x64[:2], flag, idx[:1], x64[:1], np.empty(3, dtype=idx.dtype), np.empty(3), at)
        d, b = np.ones((2, 1, 3)), np.zeros((2, 1, 3), dtype=complex)
        kept = d.copy(), b.copy()
        for a in kept:  # a cell's kept symbol is read-only (bem.periodic.influence): a signature of its own
            a.setflags(write=False)
        for blocks in ((d, b), kept):
            symbol = Symbol(*blocks, inverse=True, shift=1.0)
            for cplx in (np.complex64, np.complex128):  # the spectra's precisions
                x = np.zeros((2, 2, 3), dtype=cplx)
                k.mix(x, symbol, x, True, 1)
    return k.compiled


def _compile():
    """The compiled kernels (a class of static methods with the NumPy forms' signatures), or None without numba."""
    try:
        import numba
    except ImportError:
        return None
    from numba import njit

    opts = dict(cache=True, nogil=True)  # nogil: the parts run at once on the threads of bem.fft.in_parts

    @njit(**opts)
    def _gap(u, h, g, lo, hi):
        g_min, u_max, u_min, g_nan, u_nan = np.inf, -np.inf, np.inf, False, False
        for i in range(lo, hi):
            x = u[i]
            y = x + h[i]
            g[i] = y
            g_nan |= y != y  # a NaN compares false: noted apart, as NumPy's extremes propagate it
            u_nan |= x != x
            g_min = min(g_min, y)
            u_max = max(u_max, x)
            u_min = min(u_min, x)
        return np.nan if g_nan else g_min, np.nan if u_nan else u_max, np.nan if u_nan else u_min

    @njit(**opts)
    def _scan(u, h, delta, p, out):  # a part's slices
        g_min, u_max, u_min, g_nan, u_nan = np.inf, -np.inf, np.inf, False, False
        for i in range(out.size):
            x = u[i]
            y = x + h[i]
            out[i] = (y < delta) & (p[i] == 0)
            g_nan |= y != y
            u_nan |= x != x
            g_min = min(g_min, y)
            u_max = max(u_max, x)
            u_min = min(u_min, x)
        return np.nan if g_nan else g_min, np.nan if u_nan else u_max, np.nan if u_nan else u_min

    @njit(**opts)
    def _subtract_scaled(u, r, tau, s, lo, hi):  # s = 1: the same numbers as u -= r tau (x 1.0 is exact)
        for i in range(lo, hi):
            u[i] = (u[i] - r[i] * tau) * s

    @njit(**opts)
    def _add_at(x, idx, values, times, lo, hi):  # distinct indices: the parts write disjoint entries
        for j in range(lo, hi):
            x[idx[j]] = x[idx[j]] + times * values[j]

    @njit(**opts)
    def _gather(x, idx, out, lo, hi):
        for j in range(lo, hi):
            out[j] = x[idx[j]]

    @njit(**opts)
    def _gap_at(u, h, idx, out, lo, hi):
        for j in range(lo, hi):
            out[j] = u[idx[j]] + h[idx[j]]

    @njit(error_model="numpy", **opts)
    def _mix(x, d, b, lam, inverse, shift, cast, out, rows, lo, hi, sums, even):  # blocks lo..hi of `rows` rows
        n_rows, n_cols = x.shape[0], x.shape[2]  # the symbol per entry as Symbol.rows makes it; cast: x's real type
        for k in range(lo, hi):
            total = 0.0
            for r in range(k * rows, min((k + 1) * rows, n_rows)):
                for c in range(n_cols):
                    a, br, bi = d[r, 0, c] + lam, b[r, 0, c].real, b[r, 0, c].imag
                    if inverse:
                        if r == 0 and c == 0:  # the constant mode
                            a, br = a + shift, br + shift
                        det = a * a - (br * br + bi * bi)
                        s = -1.0 / det
                        a, br, bi = a / det, br * s, bi * s
                    d0, b0r, b0i = cast(a), cast(br), cast(bi)
                    b1r, b1i = b0r, -b0i  # S_10 = conj(S_01)
                    x0, x1 = x[r, 0, c], x[r, 1, c]
                    y0r = d0 * x0.real + (b0r * x1.real - b0i * x1.imag)
                    y0i = d0 * x0.imag + (b0r * x1.imag + b0i * x1.real)
                    y1r = d0 * x1.real + (b1r * x0.real - b1i * x0.imag)
                    y1i = d0 * x1.imag + (b1r * x0.imag + b1i * x0.real)
                    out[r, 0, c] = complex(y0r, y0i)
                    out[r, 1, c] = complex(y1r, y1i)
                    if sums.size:
                        v = (np.float64(x0.real) * np.float64(y0r) + np.float64(x0.imag) * np.float64(y0i)
                             + np.float64(x1.real) * np.float64(y1r) + np.float64(x1.imag) * np.float64(y1i))
                        total += v if c == 0 or (even and c == n_cols - 1) else 2.0 * v
            if sums.size:
                sums[k] = total

    @njit(**opts)
    def _merge(idx, vals, stayed, new, new_vals, out_idx, out_vals, at):
        o = j = m = 0  # written, stayed so far, entering written
        for i in range(idx.size):
            if stayed[i]:
                v = idx[i]
                while m < new.size and new[m] < v:
                    at[m], out_idx[o], out_vals[o] = j, new[m], new_vals[m]
                    o, m = o + 1, m + 1
                out_idx[o], out_vals[o] = v, vals[i]
                o, j = o + 1, j + 1
        while m < new.size:
            at[m], out_idx[o], out_vals[o] = j, new[m], new_vals[m]
            o, m = o + 1, m + 1
        return o

    run = run_in_parts

    class Compiled:
        compiled = True

        @staticmethod
        def gap(u, h, g):
            if not all(a.flags.c_contiguous for a in (u, h, g)):  # a flat view of each is needed
                return _NumPyKernels.gap(u, h, g)
            uf, hf, gf = u.reshape(-1), h.reshape(-1), g.reshape(-1)
            e = np.array(run(lambda lo, hi: _gap(uf, hf, gf, lo, hi), uf.size))
            return g, float(e[:, 0].min()), float(e[:, 1].max()), float(e[:, 2].min())

        @staticmethod
        def scan(u, h, delta, p, out):
            if not all(a.flags.c_contiguous for a in (u, h, p, out)):
                return _NumPyKernels.scan(u, h, delta, p, out)
            uf, hf, pf, of, d = u.reshape(-1), h.reshape(-1), p.reshape(-1), out.reshape(-1), float(delta)
            e = np.array(run(lambda lo, hi: _scan(uf[lo:hi], hf[lo:hi], d, pf[lo:hi], of[lo:hi]), uf.size))
            return out, float(e[:, 0].min()), float(e[:, 1].max()), float(e[:, 2].min())

        @staticmethod
        def subtract_scaled(u, r, tau, s=1.0):
            if not (u.flags.c_contiguous and r.flags.c_contiguous):
                return _NumPyKernels.subtract_scaled(u, r, tau, s)
            u, r, tau, s = u.reshape(-1), r.reshape(-1), np.float32(tau), u.dtype.type(s)
            run(lambda lo, hi: _subtract_scaled(u, r, tau, s, lo, hi), u.size)

        @staticmethod
        def add_at(x, idx, values, times=1.0):
            if not x.flags.c_contiguous:
                return _NumPyKernels.add_at(x, idx, values, times)
            xf = x.reshape(-1)
            run(lambda lo, hi: _add_at(xf, idx, values, float(times), lo, hi), idx.size)
            return x

        @staticmethod
        def mix(spectrum, symbol, out, even, rows):
            blocks = -(-spectrum.shape[0] // rows)
            sums = np.zeros(blocks if even is not None else 0)
            s, cast = symbol, spectrum.real.dtype.type
            fft.in_parts(lambda part: _mix(spectrum, s.d, s.b, float(s.lam), bool(s.inverse), float(s.shift), cast, out,
                                           rows, part.start, part.stop, sums, bool(even)), blocks, spectrum.size)
            return out, sums

        @staticmethod
        def merge(idx, vals, stayed, new, new_vals, out_idx, out_vals, at):
            return _merge(idx, vals, stayed, new, new_vals, out_idx, out_vals, at)

        @staticmethod
        def gather(x, idx):
            x, out = x.reshape(-1), np.empty(idx.size)
            run(lambda lo, hi: _gather(x, idx, out, lo, hi), idx.size)
            return out

        @staticmethod
        def gap_at(u, h, idx):
            if not (u.flags.c_contiguous and h.flags.c_contiguous):
                return _NumPyKernels.gap_at(u, h, idx)
            uf, hf, out = u.reshape(-1), h.reshape(-1), np.empty(idx.size)
            run(lambda lo, hi: _gap_at(uf, hf, idx, out, lo, hi), idx.size)
            return out

    return Compiled
