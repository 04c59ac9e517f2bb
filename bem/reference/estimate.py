"""A-priori estimate of the contact radius of an axisymmetric gap, before any solve.

The BEM candidate region and the FEM mesh are sized from the expected contact radius.
:func:`estimate_contact_radius` gives it from closed forms, for any axisymmetric gap
``h(r) = gap(r, 0)``:

- smooth bodies (Hertz, Johnson 1985, ISBN 978-0-521-34796-9, eq. 4.22-4.23):
  the paraboloid of the same gap at the contact edge, ``R_eq(a) = a^2 / (2 h(a))``,
  in ``a^3 = 3 P R / (4 E*)``, i.e. the root of ``8 E* a h(a) = 3 P``
  (force control) or of ``h(a) = delta / 2`` (approach control, ``delta = a^2/R``);
- layer alone (rigid bodies on the layer, Winkler-type): pressure
  ``p(r) = w^{-1}(delta - h(r))``, contact where ``h(r) < delta``:
  ``h(a_L) = delta`` with ``delta`` from ``P = 2 pi integral r w^{-1}(delta - h) dr``
  under force control.

With a layer, the bodies and the layer act in series and both spread the contact: under
force control the estimate is ``(a_H^3 + a_L^3)^(1/3)`` (a heuristic that reduces to each
limit); under approach control the contact cannot pass ``a_L`` (the closure
``delta - h - u`` is positive only where ``h < delta``), so ``a_L`` is used.

The gap is evaluated ONCE, vectorised, on a geometric grid of radii (32 per octave over
``2**-200 .. 2**200``, inside the gap's domain); between the samples it is interpolated
linearly in ``(ln r, ln h)``, which is exact for power-law profiles ``h = k r^n`` (the
paraboloid among them), and linearly in ``(r, h)`` next to a zero sample (a flat). Every
root is then found on that interpolant: a scene is sized without evaluating its gap more
than once per estimate.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..checks import InputError, check_callable, check_load, check_positive

__all__ = ["RadialProfile", "estimate_contact_radius", "hertz_radius", "layer_radius"]

_OCTAVES, _PER_OCTAVE = 200, 32


class RadialProfile:
    """The radial gap profile ``h(r) = gap(r, 0)`` from one vectorised evaluation (module docstring).

    Parameters
    ----------
    gap : callable
        Initial gap ``h(x, y)`` [length] (axisymmetric); a ``domain`` attribute, if any,
        bounds the radii sampled.
    """

    def __init__(self, gap):
        check_callable("gap", gap)
        r = np.exp2(np.arange(-_OCTAVES * _PER_OCTAVE, _OCTAVES * _PER_OCTAVE + 1) / _PER_OCTAVE)
        domain = getattr(gap, "domain", None)
        if domain is not None:
            (x0, x1), (y0, y1) = domain
            r = r[r < min(-x0, x1, -y0, y1) * (1 - 1e-12)]
        with np.errstate(all="ignore"):
            h = np.asarray(gap(r, np.zeros_like(r)), dtype=float)
        keep = np.isfinite(h) & (h >= 0)
        r, h = r[keep], h[keep]
        # the profile must grow with r: keep the samples up to its first decrease
        grows = np.concatenate(([True], np.diff(h) >= 0))
        end = int(np.argmin(grows)) if not grows.all() else r.size
        self.r, self.h = r[:end], h[:end]
        positive = self.h > 0
        self._log_r = np.log(self.r[positive])
        self._log_h = np.log(self.h[positive])
        self._r_first = float(self.r[positive][0]) if positive.any() else math.inf

    def __call__(self, r):
        """``h(r)`` [length] by the interpolation of the module docstring."""
        r = np.asarray(r, dtype=float)
        if not math.isfinite(self._r_first):
            return np.zeros_like(r)
        with np.errstate(divide="ignore"):
            loglog = np.exp(np.interp(np.log(r), self._log_r, self._log_h))
        linear = np.interp(r, self.r, self.h)
        return np.where(r >= self._r_first, loglog, linear)

    def radius_at(self, level):
        """The radius where ``h`` reaches ``level`` [length] (inverse of the interpolant)."""
        if level <= 0 or self.h.size == 0 or level > self.h[-1]:
            raise InputError(f"a_est could not be estimated from the gap: it does not reach h = {level:.6g} "
                             "within the radii 2**-200 .. 2**200 (or its domain). Pass a_est (the expected "
                             "contact radius) explicitly.")
        return float(np.exp(np.interp(math.log(level), self._log_h, self._log_r)))

    def root(self, f, name="a_est"):
        """Root of ``f(a)``, increasing in ``a`` (negative near 0), over the sampled radii."""
        from scipy.optimize import brentq

        with np.errstate(over="ignore", invalid="ignore"):
            values = f(self.r)
        above = np.flatnonzero(values >= 0)
        if above.size == 0 or above[0] == 0 or np.any(np.diff(values[np.isfinite(values)]) < 0):
            raise InputError(f"{name} could not be estimated from the gap: the gap does not grow with r over "
                             "2**-200 .. 2**200 length units. Pass a_est (the expected contact radius) explicitly.")
        lo, hi = self.r[above[0] - 1], self.r[above[0]]
        return brentq(lambda a: float(f(np.array(a))), lo, hi, xtol=1e-14 * hi, rtol=1e-12)


def _profile(gap):
    return gap if isinstance(gap, RadialProfile) else RadialProfile(gap)


def hertz_radius(gap, *, E_star, force=None, approach=None):
    """Hertz contact radius of the paraboloid that matches the gap at the contact edge [length].

    Parameters
    ----------
    gap : callable or RadialProfile
        Initial gap ``h(x, y)`` [length]; only ``h(r, 0)`` is used.
    E_star : float
        Effective modulus [pressure].
    force, approach : float
        Exactly one: total force ``P`` [force] or approach ``delta`` [length].

    Returns
    -------
    float
        Root ``a`` of ``8 E* a h(a) = 3 P`` (force) or ``h(a) = delta / 2`` (approach);
        for ``h = r^2/(2R)`` these are Hertz's ``a^3 = 3PR/(4E*)`` and ``a^2 = R delta``.
    """
    h = _profile(gap)
    E_star = check_positive("E_star", E_star)
    force, approach = check_load(force, approach)
    if force is not None:
        return h.root(lambda a: 8.0 * E_star * a * h(a) / (3.0 * force) - 1.0)
    return h.radius_at(0.5 * approach)


@functools.lru_cache(maxsize=1)
def _gauss(n):
    return np.polynomial.legendre.leggauss(n)


def _layer_force(h, layer, delta, n=200):
    """``P(delta) = 2 pi integral_0^{a_L} r w^{-1}(delta - h(r)) dr`` (Gauss-Legendre, ``n`` points)."""
    a_L = h.radius_at(delta)
    x, wq = _gauss(n)
    r = 0.5 * a_L * (x + 1.0)
    p = np.asarray(layer.inverse(delta - h(r)), dtype=float)
    if not np.all(np.isfinite(p)):
        return math.inf
    return float(np.pi * a_L * np.sum(wq * r * p))


def layer_radius(gap, layer, *, force=None, approach=None):
    """Contact radius when the layer alone deforms (rigid bodies) [length].

    Parameters
    ----------
    gap : callable or RadialProfile
        Initial gap ``h(x, y)`` [length].
    layer : bem.layers.Layer
        Interface law ``w(p)``.
    force, approach : float
        Exactly one: total force [force] or approach [length].

    Returns
    -------
    float or None
        ``a_L`` with ``h(a_L) = delta``; ``delta`` from the force balance under force control.
        ``None`` when the layer alone cannot carry the force (a rigid branch is reached).
    """
    from scipy.optimize import brentq

    h = _profile(gap)
    force, approach = check_load(force, approach)
    if approach is not None:
        return h.radius_at(approach)

    def excess(delta):
        value = _layer_force(h, layer, delta)
        return 1.0 if not math.isfinite(value) else value / force - 1.0

    top = float(h.h[-1]) if h.h.size else 0.0
    if top <= 0:
        raise InputError("a_est could not be estimated from the gap: it is flat. Pass a_est explicitly.")
    # bracket the approach by doubling or halving from 1 length unit, within the sampled gap
    delta = min(1.0, 0.5 * top)
    with np.errstate(over="ignore", invalid="ignore"):
        f = excess(delta)
        for _ in range(800):
            other = 0.5 * delta if f >= 0 else min(2.0 * delta, top)
            g = excess(other) if other != delta else f
            if (g >= 0) != (f >= 0):
                break
            if other == delta:
                raise InputError("a_est could not be estimated from the gap: the layer alone carries the force "
                                 "at no approach the sampled gap reaches. Pass a_est explicitly.")
            delta, f = other, g
    lo, hi = sorted((delta, other))
    delta = brentq(excess, lo, hi, xtol=1e-14 * hi, rtol=1e-12)
    if not math.isfinite(_layer_force(h, layer, delta * (1.0 - 1e-9))):
        return None
    return h.radius_at(delta)


def estimate_contact_radius(gap, *, E_star, force=None, approach=None, layer=None):
    """Expected contact radius ``a_est`` [length] that sizes the BEM region and the FEM mesh.

    Parameters
    ----------
    gap : callable or RadialProfile
        Initial gap ``h(x, y)`` [length], axisymmetric (evaluated once, module docstring).
    E_star : float
        Effective modulus [pressure].
    force, approach : float
        Exactly one: total force ``P`` [force] or approach ``delta`` [length].
    layer : bem.layers.Layer, optional
        Interface law; ``None`` for smooth bodies.

    Returns
    -------
    float
        ``a_H`` without a layer; with a layer ``(a_H^3 + a_L^3)^(1/3)`` under force control
        and ``a_L`` under approach control (see the module docstring).
    """
    force, approach = check_load(force, approach)
    h = _profile(gap)
    a_H = hertz_radius(h, E_star=E_star, force=force, approach=approach)
    if layer is None:
        return a_H
    a_L = layer_radius(h, layer, force=force, approach=approach)
    if a_L is None:
        return a_H
    if approach is not None:
        return a_L
    return (a_H**3 + a_L**3) ** (1.0 / 3.0)
