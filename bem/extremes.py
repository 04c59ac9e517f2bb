"""The extremes of :func:`bem.kkt.kkt_residual` in one pass, as a compiled kernel on the FFT threads.

The residual of a state without a hardness reads four extremes of the pressure ``p`` and the deformed gap ``g``:
``min p``, ``max p``, ``max |g|`` where ``p > 0`` and ``min g`` where ``p <= 0``. On NumPy they take seven passes over
the two arrays and two compressions; with numba installed (``contactlab[fast]``) and at least
:data:`MIN_NODES` entries they take one, split into :func:`bem.fft.threads` parts run at once
(:func:`bem.fft.in_parts`). Extremes do not depend on the order in which they are taken: the same numbers as NumPy's
(``tests/bem/test_kkt_state.py``). The arrays must be finite, as the residual has checked them to be.
"""

from __future__ import annotations

import numpy as np

from . import fft

__all__ = ["MIN_NODES", "load", "residual_extremes"]

MIN_NODES = 1 << 18  # entries below which NumPy's passes are used (the threads' start costs more than they save)
_COMPILED = []  # the compiled kernel, made at the first call on a large array


def _numpy_extremes(p, gap):
    contact = p > 0
    gap_c, gap_o = gap[contact], gap[~contact]
    return (float(p.min()), float(p.max()), float(np.abs(gap_c).max()) if gap_c.size else 0.0,
            float(gap_o.min()) if gap_o.size else np.inf)


def residual_extremes(p, gap):
    """``(min p, max p, max |g| where p > 0, min g where p <= 0)`` of two finite NumPy arrays of one shape.

    Parameters
    ----------
    p, gap : numpy.ndarray
        Pressure [pressure] and deformed gap [length], finite, any shape (the same).

    Returns
    -------
    tuple of float
        The four extremes; ``max |g|`` is 0 where no node has ``p > 0`` and ``min g`` is ``inf`` where every node has.
    """
    if p.size < MIN_NODES or not (p.flags.c_contiguous and gap.flags.c_contiguous):
        return _numpy_extremes(p, gap)
    if not _COMPILED:
        _COMPILED.append(_compile())
    kernel = _COMPILED[0]
    if kernel is None:
        return _numpy_extremes(p, gap)
    pf, gf, parts = p.reshape(-1), gap.reshape(-1), []
    fft.in_parts(lambda part: parts.append(kernel(pf, gf, part.start, part.stop)), pf.size, pf.size)
    return (min(e[0] for e in parts), max(e[1] for e in parts), max(e[2] for e in parts), min(e[3] for e in parts))


def load():
    """Load the compiled kernel now (numba's import and its cached machine code), rather than at the first large
    state; does nothing without numba.

    Returns
    -------
    bool
        Whether the compiled kernel is in use on large arrays.
    """
    if not _COMPILED:
        _COMPILED.append(_compile())
    if _COMPILED[0] is None:
        return False
    x = np.zeros(4)
    _COMPILED[0](x, x, 0, 4)
    return True


def _compile():
    """The compiled kernel ``(p, gap, lo, hi) -> extremes`` of a part, or None without numba."""
    try:
        from numba import njit
    except ImportError:
        return None

    @njit(cache=True, nogil=True)
    def extremes(p, gap, lo, hi):
        p_min, p_max, g_abs, g_open = np.inf, -np.inf, 0.0, np.inf
        for i in range(lo, hi):
            x, g = p[i], gap[i]
            p_min = min(p_min, x)
            p_max = max(p_max, x)
            if x > 0:
                g_abs = max(g_abs, abs(g))
            else:
                g_open = min(g_open, g)
        return p_min, p_max, g_abs, g_open

    return extremes
