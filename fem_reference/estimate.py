"""A priori estimate of the contact radius: it sizes the FEM mesh before any solve.

The mesh is refined around the contact zone, so its sizes need the contact
radius before the problem is solved. :func:`estimate_contact_radius` gives it
from closed forms, for any axisymmetric gap ``h(r) = gap(r, 0)``:

- smooth bodies (Hertz, Johnson 1985, ISBN 978-0-521-34796-9, eq. 4.22-4.23):
  the paraboloid of the same gap at the contact edge, ``R_eq(a) = a^2 / (2 h(a))``,
  in ``a^3 = 3 P R / (4 E*)``, i.e. the root of ``8 E* a h(a) = 3 P``
  (force control) or of ``h(a) = delta / 2`` (approach control, ``delta = a^2/R``);
- layer alone (rigid bodies on the layer, Winkler-type): pressure
  ``p(r) = w^{-1}(delta - h(r))``, contact where ``h(r) < delta``:
  ``h(a_L) = delta`` with ``delta`` from ``P = 2 pi integral r w^{-1}(delta - h) dr``
  under force control.

With a layer, the bodies and the layer act in series and both spread the
contact: under force control the estimate is ``(a_H^3 + a_L^3)^(1/3)`` (a
heuristic that reduces to each limit); under approach control the contact
cannot pass ``a_L`` (the closure ``delta - h - u`` is positive only where
``h < delta``), so ``a_L`` is used. The solver checks the computed radius
against the refined zone and re-meshes once when the estimate was off
(:func:`fem_reference.solve`).
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy.optimize import brentq

from bem.checks import InputError, check_callable, check_positive

__all__ = ["estimate_contact_radius", "hertz_radius", "layer_radius"]

_MAX_DECADES = 60  # bracketing range: 2**+-200 times the starting scale


def _profile(gap):
    """Radial profile ``h(r) = gap(r, 0)`` as a vectorised function."""
    check_callable("gap", gap)

    def h(r):
        r = np.asarray(r, dtype=float)
        return np.asarray(gap(r, np.zeros_like(r)), dtype=float)

    return h


def _root_increasing(f, name):
    """Root of a function increasing in ``a > 0`` (negative near 0), by bracketing + Brent."""
    a = 1.0
    fa = f(a)
    for _ in range(4 * _MAX_DECADES):
        if fa < 0:
            b, fb = 2.0 * a, f(2.0 * a)
            if fb >= 0:
                return brentq(f, a, b, xtol=1e-14 * b, rtol=1e-12)
            a, fa = b, fb
        else:
            b, fb = 0.5 * a, f(0.5 * a)
            if fb < 0:
                return brentq(f, b, a, xtol=1e-14 * a, rtol=1e-12)
            a, fa = b, fb
    raise InputError(
        f"{name} could not be estimated from the gap: the gap does not grow with r over 2**+-200 "
        "length units. Pass a_est (the expected contact radius) explicitly."
    )


def hertz_radius(gap, *, E_star, force=None, approach=None):
    """Hertz contact radius of the paraboloid that matches the gap at the contact edge [length].

    Parameters
    ----------
    gap : callable
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
    if force is not None:
        P = check_positive("force", force)
        return _root_increasing(lambda a: 8.0 * E_star * a * float(h(a)) / (3.0 * P) - 1.0, "a_est")
    delta = check_positive("approach", approach)
    return _root_increasing(lambda a: float(h(a)) / (0.5 * delta) - 1.0, "a_est")


@functools.lru_cache(maxsize=1)
def _gauss(n):
    return np.polynomial.legendre.leggauss(n)


def _layer_force(h, layer, delta, n=200):
    """``P(delta) = 2 pi integral_0^{a_L} r w^{-1}(delta - h(r)) dr`` (Gauss-Legendre, ``n`` points)."""
    a_L = _root_increasing(lambda a: float(h(a)) / delta - 1.0, "a_est")
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
    gap : callable
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
    h = _profile(gap)
    if approach is not None:
        delta = check_positive("approach", approach)
        return _root_increasing(lambda a: float(h(a)) / delta - 1.0, "a_est")
    P = check_positive("force", force)

    def excess(delta):
        value = _layer_force(h, layer, delta)
        return 1.0 if not math.isfinite(value) else value / P - 1.0

    delta = _root_increasing(excess, "a_est")
    if not math.isfinite(_layer_force(h, layer, delta * (1.0 - 1e-9))):
        return None
    return _root_increasing(lambda a: float(h(a)) / delta - 1.0, "a_est")


def estimate_contact_radius(gap, *, E_star, force=None, approach=None, layer=None):
    """Expected contact radius ``a_est`` [length] used to size the mesh.

    Parameters
    ----------
    gap : callable
        Initial gap ``h(x, y)`` [length], axisymmetric.
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
    if (force is None) == (approach is None):
        raise InputError(f"force = {force!r}, approach = {approach!r} is not allowed: give exactly one of them.")
    a_H = hertz_radius(gap, E_star=E_star, force=force, approach=approach)
    if layer is None:
        return a_H
    a_L = layer_radius(gap, layer, force=force, approach=approach)
    if a_L is None:
        return a_H
    if approach is not None:
        return a_L
    return (a_H**3 + a_L**3) ** (1.0 / 3.0)
