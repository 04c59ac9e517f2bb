"""Gridded gap table (a measured surface) interpolated onto the lattice."""

from __future__ import annotations

import numpy as np

from ..checks import InputError, check_choice, check_finite_array, fail
from .base import Gap

__all__ = ["Table"]


class Table(Gap):
    """Measured gap on a rectangular grid, interpolated.

    ``h[i, j]`` is the gap at ``(x[i], y[j])``. Values come from
    :class:`scipy.interpolate.RegularGridInterpolator` (the spline systems
    of ``"cubic"``/``"quintic"`` solved to ``rtol = 1e-12``), clipped at 0
    (a spline may undershoot between nodes). Points outside the table are
    refused (no extrapolation); points within ``1e-12`` of the span outside
    an edge count as on it (round-off of lattice coordinates).

    Parameters
    ----------
    x, y : array_like
        Strictly increasing 1-D grid coordinates [length].
    h : array_like
        Gap values [length], shape ``(len(x), len(y))``, finite, ``>= 0``.
    method : {"cubic", "linear", "quintic", "pchip"}
        Interpolation method; needs at least 4 (cubic, pchip) or 6 (quintic)
        points per axis, 2 for linear.
    """

    type_name = "table"
    units = {"x": "length", "y": "length", "h": "length"}
    MIN_POINTS = {"linear": 2, "cubic": 4, "pchip": 4, "quintic": 6}

    def __init__(self, x, y, h, method="cubic"):
        self.method = check_choice("method", method, tuple(self.MIN_POINTS))
        n = self.MIN_POINTS[self.method]
        self.x = _axis("x", x, n)
        self.y = _axis("y", y, n)
        try:
            self.h = np.array(check_finite_array("h", h, ndim=2))
        except InputError as exc:
            raise InputError(str(exc).rstrip(".") + self._where_nonfinite(h) + ".") from None
        if self.h.shape != (self.x.size, self.y.size):
            fail("h.shape", self.h.shape, f"(len(x), len(y)) = {(self.x.size, self.y.size)}")
        if (self.h < 0).any():
            i, j = np.argwhere(self.h < 0)[0]
            fail(f"h[{i}, {j}] (at x = {float(self.x[i])!r}, y = {float(self.y[j])!r})", float(self.h[i, j]),
                  ">= 0 (a gap is a separation; subtract h.min() from the table)")
        self.domain = ((self.x[0], self.x[-1]), (self.y[0], self.y[-1]))
        from scipy.interpolate import RegularGridInterpolator

        kw = {"solver_args": {"rtol": 1e-12, "atol": 0.0}} if self.method in ("cubic", "quintic") else {}
        self._interp = RegularGridInterpolator((self.x, self.y), self.h, method=self.method, **kw)

    def _evaluate(self, x, y):
        x = self._inside("x", x, y)
        y = self._inside("y", y, x)
        pts = np.stack([x.ravel(), y.ravel()], axis=-1)
        return np.maximum(self._interp(pts).reshape(x.shape), 0.0)

    def _inside(self, name, v, other):
        axis = self.x if name == "x" else self.y
        lo, hi = axis[0], axis[-1]
        tol = 1e-12 * (hi - lo)
        ok = (v >= lo - tol) & (v <= hi + tol)  # NaN fails too
        if not ok.all():
            i = np.unravel_index(np.argmin(ok), ok.shape)
            pt = (v[i], other[i]) if name == "x" else (other[i], v[i])
            fail("point (x, y)", tuple(float(c) for c in pt),
                  f"inside the gap table, x in [{self.x[0]}, {self.x[-1]}] and y in [{self.y[0]}, {self.y[-1]}]")
        return np.clip(v, lo, hi)

    def _where_nonfinite(self, h):
        """`` (at x = .., y = ..)`` for the first NaN/inf of ``h``, or ``""``."""
        try:
            bad = np.argwhere(~np.isfinite(np.asarray(h, dtype=float)))
        except (TypeError, ValueError):
            return ""
        if np.shape(h) != (self.x.size, self.y.size) or not bad.size:
            return ""
        i, j = bad[0]
        return f" (at x = {float(self.x[i])!r}, y = {float(self.y[j])!r})"

    def _params(self):
        return {"x": self.x.tolist(), "y": self.y.tolist(), "h": self.h.tolist(), "method": self.method}


def _axis(name, values, min_points):
    arr = np.array(check_finite_array(name, values, ndim=1, min_size=min_points))
    if (np.diff(arr) <= 0).any():
        k = int(np.argmax(np.diff(arr) <= 0))
        fail(f"{name}[{k + 1}]", float(arr[k + 1]), f"> {name}[{k}] = {float(arr[k])!r} (strictly increasing)")
    return arr
