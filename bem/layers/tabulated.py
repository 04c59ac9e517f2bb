"""Tabulated (measured) pressure-closure law with monotone piecewise-cubic interpolation."""

from __future__ import annotations

import numpy as np

from ..checks import InputError, check_finite_array, check_nonnegative
from ._common import LawBase, as_closure, as_pressure, out
from ._solve import newton_bisect

__all__ = ["Tabulated", "beyond_table"]


def _horner(coef, k, t):
    """Evaluate the local polynomials ``sum_j coef[j, k] t**(deg-j)`` (scipy ``PPoly`` layout)."""
    val = coef[0, k]
    for row in coef[1:]:
        val = val * t + row[k]
    return val


class Tabulated(LawBase):
    """Measured pressure-closure pairs ``(p_i, w_i)``, interpolated monotonically.

    Between the points the law is a PCHIP interpolant (monotone piecewise cubic Hermite, C1):
    node slopes of ``scipy.interpolate.PchipInterpolator`` (Fritsch & Butland,
    DOI:10.1137/0905021) except at the last node, where the slope is that of the last
    segment, ``d_n = (w[-1] - w[-2]) / (p[-1] - p[-2])``. Both keep every cubic monotone
    (slopes within ``[0, 3 x segment slope]``, Fritsch & Carlson, DOI:10.1137/0717021), so the
    law is non-decreasing; interpolated values are clipped to the interval's end values so
    rounding cannot break monotonicity at the nodes. Away from ``p = 0`` and the last
    interval the error is O(h**3) for smooth laws, O(h**2) on the last interval.

    Extrapolation rule:

    - below the first point: if ``p[0] > 0`` the table is extended by the point ``(0, 0)``
      and interpolated to it (the law always satisfies ``w(0) = 0``);
    - beyond the last point: continued linearly with the end slope ``d_n`` (C1); if the last
      segment is flat the law turns rigid there and ``inverse`` is ``+inf`` for closures
      above ``w[-1]``. The table's data end there: a solve whose peak pressure exceeds
      ``p[-1]`` logs a warning (:func:`beyond_table`) and keeps its answer.

    Parameters
    ----------
    p : array_like, 1-D
        Pressures [pressure], finite, ``>= 0``, strictly increasing.
    w : array_like, 1-D
        Closures [length], finite, non-decreasing; ``w[0] = 0`` if ``p[0] = 0``, else
        ``w[0] >= 0``.

    Notes
    -----
    ``dw`` is the interpolant's derivative (finite at ``p = 0`` even if the sampled law has
    an infinite slope there), ``energy`` the exact integral of the interpolant, ``inverse``
    the smallest pressure reaching the closure (bracketed on the table, then safeguarded
    Newton, see :func:`bem.layers._solve.newton_bisect`).
    """

    law = "tabulated"
    _required = ("p", "w")

    def __init__(self, p, w):
        p = check_finite_array("p", p, ndim=1)
        w = check_finite_array("w", w, ndim=1)
        if w.size != p.size:
            raise InputError(
                f"w has {w.size} entries which is not allowed: it must have as many as p ({p.size})."
            )
        check_nonnegative("p[0]", p[0])
        bad = np.flatnonzero(np.diff(p) <= 0)
        if bad.size:
            i = bad[0] + 1
            raise InputError(
                f"p[{i}] = {float(p[i])!r} is not allowed: it must be > p[{i - 1}] = {float(p[i - 1])!r} "
                "(pressures strictly increasing)."
            )
        if p[0] == 0 and w[0] != 0:
            raise InputError(f"w[0] = {float(w[0])!r} is not allowed: it must be 0 (w(0) = 0 at p[0] = 0).")
        check_nonnegative("w[0]", w[0])
        bad = np.flatnonzero(np.diff(w) < 0)
        if bad.size:
            i = bad[0] + 1
            raise InputError(
                f"w[{i}] = {float(w[i])!r} is not allowed: it must be >= w[{i - 1}] = {float(w[i - 1])!r} "
                "(closure non-decreasing in pressure)."
            )
        self._p_in, self._w_in = p.copy(), w.copy()
        if p[0] > 0:
            p, w = np.concatenate(([0.0], p)), np.concatenate(([0.0], w))
        if p.size < 2:
            raise InputError(
                "p has 1 entries which is not allowed: it must have a point with p > 0 besides (0, 0)."
            )
        from scipy.interpolate import CubicHermiteSpline, PchipInterpolator

        slopes = PchipInterpolator(p, w).derivative()(p)
        slopes[-1] = (w[-1] - w[-2]) / (p[-1] - p[-2])  # end slope = last segment's
        spline = CubicHermiteSpline(p, w, slopes)
        self._x, self._y = p, w
        self._c = spline.c  # (4, n-1) cubic coefficients per interval
        self._dc = spline.derivative().c
        anti = spline.antiderivative()
        self._ac = anti.c
        self._d_end = float(slopes[-1])
        self._energy_end = float(anti(p[-1]))

    def _params(self):
        return {"p": self._p_in.tolist(), "w": self._w_in.tolist()}

    def __repr__(self):
        fmt = {"threshold": 6, "edgeitems": 2, "separator": ", "}
        return (
            f"Tabulated(p={np.array2string(self._p_in, **fmt)}, "
            f"w={np.array2string(self._w_in, **fmt)})"
        )

    @property
    def p_scale(self):
        return float(self._x[-1])

    def _split(self, p):
        """Interval index and local coordinate for ``p`` inside the table; mask of the rest."""
        x = self._x
        beyond = p >= x[-1]
        p = np.minimum(p, x[-1])  # keeps inf out of the cubic
        k = np.clip(np.searchsorted(x, p, side="right") - 1, 0, x.size - 2)
        return k, p - x[k], beyond

    def w(self, p):
        p = as_pressure(p)
        k, t, beyond = self._split(p)
        inside = np.clip(_horner(self._c, k, t), self._y[k], self._y[k + 1])
        tail = self._y[-1]
        if self._d_end > 0:  # skip 0 * inf
            with np.errstate(over="ignore"):
                tail = tail + self._d_end * np.maximum(p - self._x[-1], 0.0)
        return out(np.where(beyond, tail, inside))

    def dw(self, p):
        p = as_pressure(p)
        k, t, beyond = self._split(p)
        return out(np.where(beyond, self._d_end, np.maximum(_horner(self._dc, k, t), 0.0)))

    def energy(self, p):
        p = as_pressure(p)
        k, t, beyond = self._split(p)
        q = np.maximum(p - self._x[-1], 0.0)
        with np.errstate(over="ignore"):
            tail = self._energy_end + self._y[-1] * q
            if self._d_end > 0:  # skip 0 * inf
                tail = tail + 0.5 * self._d_end * q**2
        return out(np.where(beyond, tail, _horner(self._ac, k, t)))

    def inverse(self, closure):
        c = as_closure(closure)
        x, y = self._x, self._y
        res = np.where(c <= 0, 0.0, np.nan)  # NaN closures stay NaN
        if self._d_end > 0:
            with np.errstate(over="ignore"):
                tail = x[-1] + np.maximum(c - y[-1], 0.0) / self._d_end
        else:
            tail = np.inf
        res = np.where(c > y[-1], tail, res)
        inside = (c > 0) & (c <= y[-1])
        ci = c[inside]
        j = np.searchsorted(y, ci, side="left")  # first node with y_j >= c (j >= 1)
        pi = np.where(y[j] == ci, x[j], np.nan)
        solve = np.isnan(pi)
        pi[solve] = newton_bisect(self.w, self.dw, ci[solve], x[j[solve] - 1], x[j[solve]])
        res[inside] = pi
        return out(res)


def beyond_table(layer, p_max):
    """The note for a peak pressure beyond the last pressure of a tabulated law, or ``None``.

    A :class:`Tabulated` law holds data up to its last pressure ``p[-1]`` and continues linearly
    beyond it (class docstring); a solve that loads the layer beyond ``p[-1]`` uses that
    continuation, not data. The laws of a :class:`bem.layers.Series` are looked at each.

    Parameters
    ----------
    layer : bem.layers.Layer or None
        The layer of the solve.
    p_max : float
        The peak pressure the solve reached [pressure].

    Returns
    -------
    str or None
        ``"the peak pressure p_max = ... exceeds the tabulated layer law's range 0 <= p <= ...: ..."``
        when ``p_max > p[-1]`` of a tabulated law of ``layer``, else ``None``.
    """
    from .series import Series

    laws = [layer]
    while laws:
        law = laws.pop(0)
        if isinstance(law, Tabulated) and p_max > law._x[-1]:
            last = float(law._x[-1])
            return (f"the peak pressure p_max = {float(p_max):.6g} exceeds the tabulated layer law's range "
                    f"0 <= p <= {last:.6g} ({float(p_max) / last:.3g} times its last pressure): beyond it the law "
                    "is the linear continuation of its last interval, not data; extend the table (a layer law "
                    "file: its pressure ladder) to cover the peak pressure.")
        if isinstance(law, Series):
            laws += [law.a, law.b]
    return None
