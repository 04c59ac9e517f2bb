"""Element-wise passes of a Newton step (:mod:`bem.newton`) over the lattice, as compiled kernels on the FFT threads.

With numba installed (``contactlab[fast]``) and arrays of at least :data:`bem.extremes.MIN_NODES` entries, on NumPy:

- :func:`advance`: the step ``p + t (q - p)``, clipped at 0, and ``u + t (C q - u)``, in the arrays of ``q`` and
  ``C q``, one pass over the four arrays instead of eight;
- :func:`gather`: the values of several arrays at the step's nodes, the nodes in parts;
- :func:`with_compliance`: ``u + D p`` or ``u - D p`` for the compliance ``D`` per node of a step's model (the start
  of its QP, and the elastic displacement the QP returns), one pass instead of two or three.

Each makes the operations of its NumPy form in the same order and precision at every entry: the same numbers bit for
bit (``tests/bem/test_newton_passes.py``); without numba, on a smaller lattice or another namespace the NumPy forms
run.
"""

from __future__ import annotations

import numpy as np

from . import fft
from .extremes import MIN_NODES

__all__ = ["advance", "gather", "load", "with_compliance"]

_COMPILED = []  # the compiled kernels, made at the first call on large arrays (None without numba)


def _kernels(size, *arrays):
    """The compiled kernels where ``size`` entries are enough and every array is a C-contiguous NumPy array."""
    if size < MIN_NODES or not all(isinstance(a, np.ndarray) and a.flags.c_contiguous for a in arrays):
        return None
    if not _COMPILED:
        _COMPILED.append(_compile())
    return _COMPILED[0]


def _in_parts(kernel, n):
    fft.in_parts(lambda part: kernel(part.start, part.stop), n, n)


def advance(p, q, u, uq, t):
    """``q = max(p + t (q - p), 0)`` and ``uq = u + t (uq - u)``, in place (float64 NumPy arrays of one shape), made as
    ``((q - p) t + p)`` and ``((uq - u) t + u)``."""
    k = _kernels(q.size, p, q, u, uq)
    if k is None:
        q -= p
        q *= t
        q += p
        np.maximum(q, 0.0, out=q)
        uq -= u
        uq *= t
        uq += u
        return
    pf, qf, uf, uqf, t = p.reshape(-1), q.reshape(-1), u.reshape(-1), uq.reshape(-1), float(t)
    _in_parts(lambda lo, hi: k.advance(pf, qf, uf, uqf, t, lo, hi), qf.size)


def gather(sel, *arrays):
    """The arrays (of the lattice's shape) at the flat node indices ``sel``, each a new 1-D array of its dtype."""
    k = _kernels(sel.size, sel, *arrays)
    if k is None:
        return [np.take(a.reshape(-1), sel) for a in arrays]
    flats = [a.reshape(-1) for a in arrays]
    out = [np.empty(sel.size, dtype=a.dtype) for a in arrays]

    def part(lo, hi):
        for a, o in zip(flats, out):
            k.gather(a, sel, o, lo, hi)

    _in_parts(part, sel.size)
    return out


def with_compliance(u, D, p, out, sign, scratch=None):
    """``u + sign D p`` (``sign`` +1 or -1; ``D`` per node, or uniform) into ``out`` (float64, ``u`` itself in its
    precision, or None: a new array), made in double precision and rounded to ``out``'s; ``out``. The NumPy form makes
    ``D p`` in ``out``, or where ``out`` is ``u`` in the float64 array ``scratch`` (a new array without it)."""
    k = None if out is None else _kernels(out.size, u, D, p, out)
    if k is None:
        dp = np.multiply(D, p, out=scratch if out is u else out)
        return (np.add if sign > 0 else np.subtract)(u, dp, out=out)
    uf, df, pf, of = u.reshape(-1), D.reshape(-1), p.reshape(-1), out.reshape(-1)
    kernel = k.added if sign > 0 else k.subtracted
    _in_parts(lambda lo, hi: kernel(uf, df, pf, of, lo, hi), of.size)
    return out


def load():
    """Load the compiled kernels now (numba's import and its cached machine code) for the precisions a step passes
    them; does nothing without numba.

    Returns
    -------
    bool
        Whether the compiled kernels are in use on large arrays.
    """
    if not _COMPILED:
        _COMPILED.append(_compile())
    k = _COMPILED[0]
    if k is None:
        return False
    x, x32, sel = np.zeros(4), np.zeros(4, dtype=np.float32), np.arange(2)
    k.advance(x, x.copy(), x, x.copy(), 0.5, 0, 4)
    for a in (x, x32):
        k.gather(a, sel, np.empty(2, dtype=a.dtype), 0, 2)
        for u in (x, x32):
            k.added(u, a, x, np.empty(4), 0, 4)
            k.subtracted(u, a, x, np.empty(4), 0, 4)
    return True


def _compile():
    """The compiled kernels (a namespace of functions of a part ``lo:hi``), or None without numba."""
    try:
        from numba import njit
    except ImportError:
        return None
    opts = dict(cache=True, nogil=True)

    @njit(**opts)
    def advance_part(p, q, u, uq, t, lo, hi):  # a loop an array: one loop over the four runs at a third of the speed
        for i in range(lo, hi):
            x = (q[i] - p[i]) * t + p[i]
            q[i] = 0.0 if x <= 0.0 else x  # NumPy's maximum(x, 0): -0.0 gives 0.0, NaN stays NaN
        for i in range(lo, hi):
            uq[i] = (uq[i] - u[i]) * t + u[i]

    @njit(**opts)
    def gather_part(a, sel, out, lo, hi):
        for j in range(lo, hi):
            out[j] = a[sel[j]]

    @njit(**opts)
    def added(u, d, p, out, lo, hi):
        for i in range(lo, hi):
            out[i] = u[i] + np.float64(d[i]) * p[i]

    @njit(**opts)
    def subtracted(u, d, p, out, lo, hi):
        for i in range(lo, hi):
            out[i] = u[i] - np.float64(d[i]) * p[i]

    class Kernels:
        pass

    Kernels.advance, Kernels.gather = staticmethod(advance_part), staticmethod(gather_part)
    Kernels.added, Kernels.subtracted = staticmethod(added), staticmethod(subtracted)
    return Kernels
