"""User-supplied layer law ``w(p)`` with numerical derivative, energy and inverse."""

from __future__ import annotations

import numpy as np

from ..checks import InputError, check_positive
from ._common import LawBase, as_closure, as_pressure, callable_ref, out, resolve_callable
from ._solve import invert

__all__ = ["Custom"]

_EPS = np.finfo(float).eps
#: Relative tolerance of the validation checks ``w(0) = 0`` and monotonicity on the sample.
SAMPLE_RTOL = 1e-12
#: Gauss-Legendre rule for the energy: panels x points in v, with p' = p v**2.
_PANELS, _POINTS = 16, 8


def _energy_rule():
    """Nodes ``u`` in (0, 1) and weights of ``integral_0^1 f(u) du = integral_0^1 2 v f(v**2) dv``."""
    t, wt = np.polynomial.legendre.leggauss(_POINTS)
    edges = np.linspace(0.0, 1.0, _PANELS + 1)
    half = 0.5 * np.diff(edges)
    v = (edges[:-1, None] + half[:, None] * (t[None, :] + 1.0)).ravel()
    weights = (half[:, None] * wt[None, :]).ravel() * 2.0 * v
    return v**2, weights


_U, _WU = _energy_rule()


class Custom(LawBase):
    """A law given as a vectorised Python callable ``w(p)``.

    Parameters
    ----------
    w : callable or str
        ``w(p)`` [length] for a float array ``p >= 0`` [pressure], returning an array of the same
        shape; non-decreasing with ``w(0) = 0``. A string ``"module:function"`` is imported.
    dw : callable or str, optional
        Right derivative ``w'(p)`` [length/pressure]. Default: numerical (see Notes).
    energy : callable or str, optional
        ``W(p) = integral_0^p w`` [pressure*length]. Default: numerical (see Notes).
    inverse : callable or str, optional
        Pressure from closure for closures ``> 0``. Default: numerical (see Notes).
    p_scale : float, keyword-only
        Typical pressure [pressure], ``> 0`` (default 1.0): sets the validation sample
        ``p_scale * [0, 1e-6 .. 1e3]``, the bracket start of the inverse and the probe of
        ``dw(0)``.

    Raises
    ------
    InputError
        If a callable is missing, ``w`` is not vectorised or not finite on the sample,
        ``|w(0)| > 1e-12 max|w|`` or ``w`` decreases on the sample by more than
        ``1e-12 max|w|``.

    Notes
    -----
    Numerical fall-backs (``p < 0`` is clipped to 0 before calling ``w``):

    - ``dw(p)``, ``p > 0``: central difference with step ``h = eps**(1/3) p``
      (relative error ~1e-10 for smooth laws; averages across a kink; NaN at ``p = inf``).
      ``dw(0)`` is the secant ``w(h)/h`` at ``h = p_scale 2**-40``, or ``+inf`` when the
      secant still grows as ``h`` halves (by more than 1e-6 relative; e.g. ``p**s``, ``s < 1``).
    - ``energy(p)``: ``p integral_0^1 w(p u) du`` with ``u = v**2`` and 16 x 8-point
      Gauss-Legendre in ``v`` (exact for ``sqrt``; ~1e-9 relative for smooth or power laws,
      ~1e-5 across a kink - pass ``energy`` when it is known in closed form).
    - ``inverse(c)``: smallest ``p`` with ``w(p) >= c`` by bracketing from ``p_scale`` and a
      safeguarded Newton iteration (:func:`bem.layers._solve.invert`); ``+inf`` where
      ``w(p_scale 2**128) < c``.
    """

    law = "custom"
    _required = ("w",)
    _optional = ("dw", "energy", "inverse", "p_scale")

    def __init__(self, w, dw=None, energy=None, inverse=None, *, p_scale=1.0):
        self._fw = resolve_callable("w", w)
        self._fdw = None if dw is None else resolve_callable("dw", dw)
        self._fenergy = None if energy is None else resolve_callable("energy", energy)
        self._finverse = None if inverse is None else resolve_callable("inverse", inverse)
        self._p_scale = check_positive("p_scale", p_scale)
        self._validate()
        self._dw0 = self._secant_at_zero() if self._fdw is None else None

    def _call(self, name, f, x):
        try:
            y = np.asarray(f(x), dtype=float)
            return np.broadcast_to(y, x.shape).copy()
        except (TypeError, ValueError) as exc:
            raise InputError(
                f"{name} = {f!r} is not allowed: it must map a float array of shape {x.shape} "
                f"to an array of that shape ({exc})."
            ) from None

    def _validate(self):
        sample = self._p_scale * np.concatenate(([0.0], np.geomspace(1e-6, 1e3, 181)))
        w = self._call("w", self._fw, sample)
        bad = np.flatnonzero(~np.isfinite(w))
        if bad.size:
            raise InputError(
                f"w = {self._fw!r} is not allowed: it must be finite, but w({sample[bad[0]]!r}) "
                f"= {w[bad[0]]!r}."
            )
        tol = SAMPLE_RTOL * max(np.max(np.abs(w)), np.finfo(float).tiny)
        if abs(w[0]) > tol:
            raise InputError(f"w = {self._fw!r} is not allowed: it must give w(0) = 0, not {w[0]!r}.")
        drop = np.flatnonzero(np.diff(w) < -tol)
        if drop.size:
            i = drop[0]
            raise InputError(
                f"w = {self._fw!r} is not allowed: it must be non-decreasing, but "
                f"w({sample[i + 1]!r}) = {w[i + 1]!r} < w({sample[i]!r}) = {w[i]!r}."
            )
        for name, f in (("dw", self._fdw), ("energy", self._fenergy), ("inverse", self._finverse)):
            if f is not None:
                self._call(name, f, sample[1:])

    def _secant_at_zero(self):
        h = self._p_scale * 2.0**-40
        s1, s2 = self._call("w", self._fw, np.array([h, 0.5 * h])) / np.array([h, 0.5 * h])
        return np.inf if s2 > s1 * (1.0 + 1e-6) else float(s2)

    def _params(self):
        d = {"w": callable_ref(self._fw)}
        for name, f in (("dw", self._fdw), ("energy", self._fenergy), ("inverse", self._finverse)):
            if f is not None:
                d[name] = callable_ref(f)
        d["p_scale"] = self._p_scale
        return d

    @property
    def p_scale(self):
        return self._p_scale

    def w(self, p):
        p = as_pressure(p)
        return out(self._call("w", self._fw, p))

    def dw(self, p):
        p = as_pressure(p)
        if self._fdw is not None:
            return out(self._call("dw", self._fdw, p))
        h = _EPS ** (1.0 / 3.0) * p
        w = self._fw
        with np.errstate(divide="ignore", invalid="ignore"):
            d = (self._call("w", w, p + h) - self._call("w", w, p - h)) / (2.0 * h)
        return out(np.where(p > 0, d, np.where(np.isnan(p), np.nan, self._dw0)))

    def energy(self, p):
        p = as_pressure(p)
        if self._fenergy is not None:
            return out(self._call("energy", self._fenergy, p))
        flat = p.ravel()
        res = np.empty_like(flat)
        chunk = max(1, 2**20 // _U.size)
        for start in range(0, flat.size, chunk):  # bounded memory, not a per-node loop
            q = flat[start : start + chunk]
            with np.errstate(over="ignore"):
                res[start : start + chunk] = q * (self._call("w", self._fw, q[:, None] * _U) @ _WU)
        return out(res.reshape(p.shape))

    def inverse(self, closure):
        c = as_closure(closure)
        res = np.where(c <= 0, 0.0, np.nan)
        todo = c > 0
        if self._finverse is not None:
            res[todo] = self._call("inverse", self._finverse, c[todo])
        else:
            res[todo] = invert(self.w, self.dw, c[todo], self._p_scale)
        return out(res)
