"""Vectorised inversion of a non-decreasing law: ``p = w^{-1}(c)`` by bracketing + safeguarded Newton.

Used by the laws without a closed-form inverse (tabulated, custom, series).
"""

from __future__ import annotations

import logging

import numpy as np

__all__ = ["invert", "bracket", "newton_bisect"]

logger = logging.getLogger(__name__)

_EPS = np.finfo(float).eps
#: Relative width at which a bracket or a Newton step counts as converged.
RTOL = 4.0 * _EPS


def invert(w, dw, c, x0, *, max_doublings=128, maxiter=200):
    """Smallest ``p >= 0`` with ``w(p) >= c`` for every entry of ``c > 0``.

    Parameters
    ----------
    w, dw : callable
        Vectorised non-decreasing law with ``w(0) = 0`` [length] and its (right) derivative
        [length/pressure]; called on 1-D arrays of pressures.
    c : ndarray, 1-D
        Closures ``> 0`` [length] (``inf`` allowed: it gives ``inf``).
    x0 : float or ndarray
        Start of the bracket search [pressure], ``> 0``.
    max_doublings : int
        A closure not reached at ``x0 * 2**max_doublings`` is unreachable: ``inf`` is returned.
    maxiter : int
        Newton/bisection steps after bracketing.

    Returns
    -------
    ndarray
        Pressures [pressure]; ``inf`` where the law cannot close that far.
    """
    lo, hi = bracket(w, c, x0, max_doublings=max_doublings)
    return newton_bisect(w, dw, c, lo, hi, maxiter=maxiter)


def bracket(w, c, x0, *, max_doublings=128):
    """Brackets ``lo < p <= hi`` with ``w(lo) < c <= w(hi)`` and ``hi <= 2 lo`` (or ``lo = 0``).

    Starting at ``x0``, the search doubles while ``w(x) < c`` and halves while ``w(x/2) >= c``.
    Returns ``(lo, hi)``; ``hi = inf`` where ``w(x0 * 2**max_doublings) < c``; ``lo = hi = 0``
    where even ``w(0) >= c`` (a law with ``w(0) > 0`` within its tolerance).
    """
    c = np.asarray(c, dtype=float)
    x = np.broadcast_to(np.asarray(x0, dtype=float), c.shape).copy()
    lo = np.zeros_like(c)
    hi = np.full_like(c, np.inf)
    up = w(x) < c

    idx, xi = np.flatnonzero(up), x[up]
    lo[idx] = xi
    for _ in range(max_doublings):
        if idx.size == 0:
            break
        with np.errstate(over="ignore"):
            xi = 2.0 * xi
        reached = w(xi) >= c[idx]
        hi[idx[reached]] = xi[reached]
        lo[idx[~reached]] = xi[~reached]
        idx, xi = idx[~reached], xi[~reached]

    idx, xi = np.flatnonzero(~up), x[~up]
    hi[idx] = xi
    while idx.size:
        xi = 0.5 * xi
        below = w(xi) < c[idx]
        lo[idx[below]] = xi[below]
        hi[idx[~below]] = xi[~below]  # at xi = 0 this is lo = hi = 0
        keep = ~below & (xi > 0.0)
        idx, xi = idx[keep], xi[keep]
    return lo, hi


def newton_bisect(w, dw, c, lo, hi, *, maxiter=200):
    """Safeguarded Newton iteration for ``w(p) = c`` inside brackets ``w(lo) < c <= w(hi)``.

    Each step updates the bracket with the sign of ``f = w(x) - c`` and takes the Newton step
    ``dx = f / w'(x)`` when ``x - dx`` is finite and strictly inside the bracket and
    ``|dx|`` is at most half the step before last; otherwise it bisects (the rule of
    ``rtsafe``, Press et al., Numerical Recipes, 3rd ed., section 9.4). Entries with
    ``hi = inf`` stay ``inf``.

    Stopping rule, per entry (``eps`` = machine epsilon)::

        |x_{k+1} - x_k| <= 4 eps x_{k+1}     (return x_{k+1})
        or  hi_k - lo_k <= 4 eps hi_k        (return hi_k)
        or  w(x_k) = c  and  w'(x_k) > 0     (return x_k)

    Entries not converged after ``maxiter`` steps return ``hi`` (logged at WARNING).
    """
    c = np.asarray(c, dtype=float)
    lo = np.array(lo, dtype=float)
    hi = np.array(hi, dtype=float)
    res = hi.copy()
    idx = np.flatnonzero(np.isfinite(hi))
    x = hi[idx]
    step = step_old = hi[idx] - lo[idx]
    for _ in range(maxiter):
        if idx.size == 0:
            break
        f = w(x) - c[idx]
        d = dw(x)
        hi_i = np.where(f >= 0, x, hi[idx])
        lo_i = np.where(f >= 0, lo[idx], x)
        hi[idx], lo[idx] = hi_i, lo_i
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            dx = f / d
        newton = x - dx
        use = np.isfinite(newton) & (newton > lo_i) & (newton < hi_i) & (np.abs(dx) <= 0.5 * step_old)
        x_new = np.where(use, newton, 0.5 * (lo_i + hi_i))
        exact = (f == 0) & (d > 0)
        narrow = hi_i - lo_i <= RTOL * hi_i
        small = np.abs(x_new - x) <= RTOL * x_new
        res[idx] = np.where(exact, x, np.where(narrow, hi_i, x_new))
        keep = ~(exact | narrow | small)
        step_old, step = step, np.abs(x_new - x)
        idx, x, step, step_old = idx[keep], x_new[keep], step[keep], step_old[keep]
    if idx.size:
        logger.warning("inverse: %d entries not converged after %d steps", idx.size, maxiter)
        res[idx] = hi[idx]
    return res
