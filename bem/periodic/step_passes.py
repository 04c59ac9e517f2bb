"""The passes of :mod:`bem.periodic.qp`'s step over its contact, and the prolongation of nested iteration, as compiled
kernels on the FFT threads.

A step of the cell's constrained CG moves the pressures of its contact along the search direction, clips them at
zero, scales them to the force and puts them back into the iterate. On NumPy that is a dozen passes over the contact's
arrays, each of them short (a fifth of the cell on a rough surface), and all of them in the calling thread. With numba
installed (``contactlab[fast]``) and a cell of at least :data:`bem.periodic.passes.MIN_NODES` nodes they run as two,
each split into :func:`bem.fft.threads` parts run at once (:func:`bem.fft.in_parts`):

- ``move``: ``p_c = max(p_c0 - tau t_c, 0)``, the mask of the clipped nodes, whether any was clipped and whether every
  ``p_c`` is positive;
- ``scale_put``: ``p_c = s p_c`` in place and ``p[idx] = p_c``;
- ``write``: the float32 brick array of the gap on the contact, then of the search direction
  (:class:`bem.periodic.qp_parts.ContactBrick`): the brick set to 0 where asked, and the values rounded to float32 put
  at the contact's nodes, each part over its own range of the cell's nodes;
- ``soft_gather``: with a compliance ``D`` per node, the preconditioned gap at the contact's nodes, ``M r`` gathered
  from its brick, but the Jacobi estimate ``r / (C_nn + D)`` at the soft nodes, one pass instead of five;
- :func:`prolong_kernel`: :meth:`bem.periodic.PeriodicCell.prolong` over parts of the coarse rows.

Each gives NumPy's numbers bit for bit (the same operations in the same precision at every node; the flags are "any"
and "all", whose value does not depend on the order; a NaN is not clipped and is not positive, as in NumPy). On a
cell of a million nodes the arrays stay in the processor's caches and the passes cost about what NumPy's do; on the
cells of 16.8M nodes and more they take a fraction of NumPy's time (``docs/performance.md``, "The step's passes
compiled"). ``tests/bem/test_periodic_step_passes.py`` compares them. Off NumPy the forms run in the backend's
namespace.
"""

from __future__ import annotations

import numpy as np

from .passes import MIN_NODES, chosen, run_in_parts

__all__ = ["load", "prolong_kernel", "step_kernels"]

_COMPILED = []  # the compiled kernels, made at the first call of step_kernels()
_PROLONG = []  # the compiled prolongation, made at the first call of prolong_kernel()


def _moved(xp, p_c0, t_c, tau):
    """``(p_c, clipped, any clipped, all p_c > 0)`` for ``p_c = max(p_c0 - tau t_c, 0)`` in the namespace ``xp``."""
    p_c = p_c0 - tau * t_c
    clipped = p_c < 0
    p_c = xp.where(clipped, 0.0, p_c)
    return p_c, clipped, bool(xp.any(clipped)), bool(xp.all(p_c > 0))


class _NumPySteps:
    """The NumPy forms (the reference of the compiled ones)."""

    compiled = False

    @staticmethod
    def move(p_c0, t_c, tau):
        """:func:`_moved` on NumPy (new arrays)."""
        return _moved(np, p_c0, t_c, tau)

    @staticmethod
    def scale_put(p, idx, p_c, s=1.0):
        """``p_c *= s`` (unless ``s`` is 1) and ``p[idx] = p_c`` at the flat indices ``idx``; ``p``."""
        if s != 1.0:
            p_c *= s
        p.reshape(-1)[idx] = p_c
        return p

    @staticmethod
    def write(brick, nodes, values, fill):
        """The float32 ``brick`` set to 0 where ``fill``, then ``values`` rounded to float32 at the sorted flat indices
        ``nodes``; the rounded values (1-D)."""
        if fill:
            brick.fill(0.0)
        last = values.astype(np.float32)
        brick.reshape(-1)[nodes] = last
        return last

    @staticmethod
    def soft_gather(x, idx, soft, r, D, diag):
        """:func:`_soft_gathered` on NumPy."""
        return _soft_gathered(np, np.take(x.reshape(-1), idx).astype(np.float64), soft, r, D, diag)


def _soft_gathered(xp, z, soft, r, D, diag):
    """``z`` but ``(1 / (diag + D)) r`` where ``soft`` (1-D arrays at the contact's nodes, ``z`` ``x`` gathered there in
    double precision)."""
    return xp.where(soft, 1.0 / (diag + D) * r, z)


class _NamespaceSteps:
    """The forms on another array namespace (:class:`bem.backend.Backend` ``bk``)."""

    compiled = False

    def __init__(self, bk):
        self.bk = bk

    def move(self, p_c0, t_c, tau):
        return _moved(self.bk.xp, p_c0, t_c, tau)

    def scale_put(self, p, idx, p_c, s=1.0):
        if s != 1.0:
            p_c *= s
        return self.bk.put(p, idx, p_c)

    def soft_gather(self, x, idx, soft, r, D, diag):
        xp = self.bk.xp
        return _soft_gathered(xp, xp.astype(self.bk.take(x, idx), xp.float64), soft, r, D, diag)


def step_kernels(n_nodes, bk=None):
    """The step's kernels for a cell of ``n_nodes`` nodes, in the form :func:`bem.periodic.passes.kernels` takes for
    its own (:func:`bem.periodic.passes.chosen`; ``bk`` the arrays' :class:`bem.backend.Backend`, default NumPy):
    methods ``move(p_c0, t_c, tau)``, ``scale_put(p, idx, p_c, s=1.0)``, ``soft_gather(x, idx, soft, r, D, diag)`` and,
    on NumPy, ``write(brick, nodes, values, fill)`` (the module's docstring), and the flag ``compiled``."""
    return chosen(n_nodes, bk, _NumPySteps, _NamespaceSteps, _COMPILED, _compile)


def load():
    """Load the compiled kernels now rather than at the first step on a large cell (as
    :func:`bem.periodic.passes.load`); does nothing without numba.

    Returns
    -------
    bool
        Whether the compiled kernels are in use on large cells.
    """
    k = step_kernels(MIN_NODES)
    if k.compiled:
        x, idx = np.zeros(4), np.arange(2)
        k.move(x, x, 1.0)
        k.scale_put(x, idx, x[:2].copy(), 2.0)
        k.write(np.zeros(4, dtype=np.float32), idx, x[:2], True)
        k.soft_gather(np.zeros(4, dtype=np.float32), idx, np.ones(2, dtype=bool), x[:2], x[:2] + 1.0, 1.0)
        prolong_kernel()(np.zeros((2, 2)), np.empty((4, 4)), 0, 2)
    return k.compiled


def prolong_kernel():
    """:meth:`bem.periodic.PeriodicCell.prolong` as a compiled kernel ``(values, out, lo, hi)`` that writes the fine
    rows ``2 lo .. 2 hi`` of the coarse rows ``lo .. hi`` (each mean rounded as the method's slices round it), or None
    without numba."""
    if not _PROLONG and (jit := _jit()) is None:
        _PROLONG.append(None)
    elif not _PROLONG:

        @jit
        def prolong_rows(v, out, lo, hi):
            n_rows, n_cols = v.shape
            for k in range(lo, hi):
                nxt = k + 1 if k + 1 < n_rows else 0
                for q in range(n_cols):
                    right, left = v[k, q + 1 if q + 1 < n_cols else 0], v[k, q - 1 if q > 0 else n_cols - 1]
                    out[2 * k, 2 * q + k % 2] = v[k, q]  # the coarse node, then the midpoint along e1 beside it
                    out[2 * k, 2 * q + 1 - k % 2] = 0.5 * (v[k, q] + (right if k % 2 == 0 else left))
                for c in range(2 * n_cols):  # midpoints between coarse rows k and k + 1
                    d = c + 1 if c + 1 < 2 * n_cols else 0
                    a = v[k, c // 2] if c % 2 == k % 2 else v[nxt, c // 2]
                    b = v[k, d // 2] if d % 2 == k % 2 else v[nxt, d // 2]
                    out[2 * k + 1, c] = 0.5 * (a + b)

        _PROLONG.append(prolong_rows)
    return _PROLONG[0]


def _jit():
    """numba's ``njit`` with the kernels' options (the machine code cached; no GIL: the parts run at once on the
    threads of :func:`bem.fft.in_parts`), or None without numba."""
    try:
        from numba import njit
    except ImportError:
        return None
    return njit(cache=True, nogil=True)


def _compile():
    """The compiled kernels (a class of static methods with the NumPy forms' signatures), or None without numba."""
    if (jit := _jit()) is None:
        return None
    from numba import njit

    @jit
    def _move(p_c0, t_c, tau, p_c, clipped, lo, hi):
        any_clipped, positive = False, True
        for j in range(lo, hi):
            v = p_c0[j] - tau * t_c[j]
            c = v < 0
            if c:
                v = 0.0
            clipped[j] = c
            p_c[j] = v
            any_clipped |= c
            positive &= v > 0
        return any_clipped, positive

    @jit
    def _scale_put(p, idx, p_c, s, scale, lo, hi):  # distinct indices: the parts write disjoint entries
        for j in range(lo, hi):
            v = p_c[j] * s if scale else p_c[j]
            p_c[j] = v
            p[idx[j]] = v

    @jit
    def _write(brick, nodes, values, last, fill, lo, hi, j_lo, j_hi):  # nodes j_lo..j_hi lie in lo..hi
        if fill:
            brick[lo:hi] = 0.0
        for j in range(j_lo, j_hi):
            v = np.float32(values[j])
            last[j] = v
            brick[nodes[j]] = v

    @njit(cache=True, nogil=True, error_model="numpy")  # a zero divisor gives inf, as NumPy's
    def _soft_gather(x, idx, soft, r, D, diag, out, lo, hi):
        for j in range(lo, hi):
            out[j] = 1.0 / (diag + D[j]) * r[j] if soft[j] else np.float64(x[idx[j]])

    run = run_in_parts

    class Compiled:
        compiled = True

        @staticmethod
        def move(p_c0, t_c, tau):
            if not (p_c0.dtype == np.float64 and t_c.dtype == np.float64):
                return _NumPySteps.move(p_c0, t_c, tau)
            p_c, clipped, tau = np.empty(p_c0.size), np.empty(p_c0.size, dtype=bool), float(tau)
            flags = run(lambda lo, hi: _move(p_c0, t_c, tau, p_c, clipped, lo, hi), p_c0.size)
            return p_c, clipped, any(f[0] for f in flags), all(f[1] for f in flags)

        @staticmethod
        def scale_put(p, idx, p_c, s=1.0):
            if not (p.flags.c_contiguous and p.dtype == np.float64 and p_c.dtype == np.float64):
                return _NumPySteps.scale_put(p, idx, p_c, s)
            pf, s = p.reshape(-1), float(s)
            run(lambda lo, hi: _scale_put(pf, idx, p_c, s, s != 1.0, lo, hi), idx.size)
            return p

        @staticmethod
        def write(brick, nodes, values, fill):
            if not (brick.flags.c_contiguous and values.dtype == np.float64):
                return _NumPySteps.write(brick, nodes, values, fill)
            flat, last, fill = brick.reshape(-1), np.empty(values.size, dtype=np.float32), bool(fill)

            def part(lo, hi):  # the part's nodes of the cell and the contact's nodes among them
                j_lo, j_hi = np.searchsorted(nodes, (lo, hi))
                _write(flat, nodes, values, last, fill, lo, hi, j_lo, j_hi)

            run(part, flat.size)
            return last

        @staticmethod
        def soft_gather(x, idx, soft, r, D, diag):
            if not (x.flags.c_contiguous and D.dtype == np.float64 and r.dtype == np.float64):
                return _NumPySteps.soft_gather(x, idx, soft, r, D, diag)
            out, flat, diag = np.empty(idx.size), x.reshape(-1), float(diag)
            run(lambda lo, hi: _soft_gather(flat, idx, soft, r, D, diag, out, lo, hi), idx.size)
            return out

    return Compiled
