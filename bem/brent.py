"""Brent's root finder on a bracket, for the scalar line searches of the solvers.

Brent's method (R. P. Brent, *Algorithms for Minimization without Derivatives*, 1973, ch. 4,
the procedure ``zero``): inverse quadratic interpolation or the secant where they make good
progress, bisection otherwise, so that the bracket always holds the root and shrinks at least
as fast as bisection every few steps. It reuses the end-point values its caller has and needs
no import of :mod:`scipy.optimize`.
"""

from __future__ import annotations

import math

__all__ = ["brent_root"]


def brent_root(f, xa, xb, fa, fb, *, xtol, rtol, maxiter=100):
    """A root of ``f`` in ``[xa, xb]``, where ``fa = f(xa)`` and ``fb = f(xb)`` have opposite signs.

    Parameters
    ----------
    f : callable
        Scalar function of a float.
    xa, xb : float
        The ends of the bracket.
    fa, fb : float
        ``f(xa)`` and ``f(xb)``, of opposite signs (or one of them zero).
    xtol, rtol : float
        The root is located to within ``xtol + rtol |x|`` (``xtol > 0``).
    maxiter : int
        Limit on the evaluations of ``f``; the best point so far is returned when it is reached.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        ``fa`` and ``fb`` of the same sign.
    """
    a, b, fa, fb = float(xa), float(xb), float(fa), float(fb)  # Python floats: f may take no NumPy scalar
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    if (fa > 0) == (fb > 0):
        raise ValueError(f"(fa, fb) = ({fa!r}, {fb!r}) is not allowed: they must have opposite signs.")
    # b: the best point so far; a: the previous one; c: the end of the bracket opposite b
    c, fc = a, fa
    d = e = b - a
    for _ in range(maxiter):
        if (fb > 0) == (fc > 0):  # the root left [b, c]: a is the other end
            c, fc = a, fa
            d = e = b - a
        if abs(fc) < abs(fb):  # keep the smaller value at b
            a, b, c = b, c, b
            fa, fb, fc = fb, fc, fb
        tol = 0.5 * (xtol + rtol * abs(b))
        m = 0.5 * (c - b)
        if abs(m) <= tol or fb == 0.0:
            return b
        if abs(e) < tol or abs(fa) <= abs(fb):
            d = e = m  # bisection: the last steps were too small or did not improve
        else:
            s = fb / fa
            if a == c:  # two points: the secant
                p, q = 2.0 * m * s, 1.0 - s
            else:  # three points: inverse quadratic interpolation
                q, r = fa / fc, fb / fc
                p = s * (2.0 * m * q * (q - r) - (b - a) * (r - 1.0))
                q = (q - 1.0) * (r - 1.0) * (s - 1.0)
            if p > 0:
                q = -q
            else:
                p = -p
            if 2.0 * p < 3.0 * m * q - abs(tol * q) and p < abs(0.5 * e * q):
                e, d = d, p / q  # the interpolation step, well inside the bracket
            else:
                d = e = m
        a, fa = b, fb
        b += d if abs(d) > tol else math.copysign(tol, m)
        fb = float(f(b))
    return b
