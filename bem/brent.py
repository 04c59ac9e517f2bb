"""Brent's root finder on a bracket, for the scalar line searches of the solvers.

The iteration of ``scipy.optimize.brentq`` (Brent 1973, in the form of SciPy's ``brentq.c``:
inverse quadratic interpolation or secant, safeguarded by bisection), in Python: the solvers
call it a few times per solve, on functions that cost a pass over the nodes, and it spares the
import of :mod:`scipy.optimize` (docs/performance.md) and the two end-point evaluations its caller has.
"""

from __future__ import annotations

import math

__all__ = ["brent_root"]


def brent_root(f, xa, xb, fa, fb, *, xtol, rtol, maxiter=100):
    """A root of ``f`` in ``[xa, xb]``, where ``f(xa) = fa`` and ``f(xb) = fb`` have opposite signs.

    Parameters
    ----------
    f : callable
        Scalar function of a float.
    xa, xb : float
        The bracket.
    fa, fb : float
        ``f`` at ``xa`` and ``xb`` (nonzero, of opposite signs).
    xtol, rtol : float
        The root is located to within ``xtol + rtol |x|`` (``xtol > 0``).
    maxiter : int
        Iteration limit; the last iterate is returned when it is reached.

    Returns
    -------
    float
    """
    xpre, xcur, fpre, fcur = float(xa), float(xb), float(fa), float(fb)
    xtol, rtol = float(xtol), float(rtol)  # Python floats throughout: f may take no NumPy scalar
    if fpre == 0:
        return xpre
    if fcur == 0:
        return xcur
    if math.copysign(1.0, fpre) == math.copysign(1.0, fcur):
        raise ValueError(f"(fa, fb) = ({fpre!r}, {fcur!r}) is not allowed: they must have opposite signs")
    xblk = fblk = spre = scur = 0.0
    for _ in range(maxiter):
        if fpre != 0 and fcur != 0 and math.copysign(1.0, fpre) != math.copysign(1.0, fcur):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (xtol + rtol * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:  # secant
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:  # inverse quadratic interpolation
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):  # a good short step
                spre, scur = scur, stry
            else:
                spre = scur = sbis
        else:
            spre = scur = sbis
        xpre, fpre = xcur, fcur
        xcur += scur if abs(scur) > delta else (delta if sbis > 0 else -delta)
        fcur = float(f(xcur))
    return xcur
