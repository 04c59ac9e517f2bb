"""Reference solutions in closed form, for checking the solvers.

- Hertz contact of a paraboloid (sphere) and of an elliptic paraboloid
  (H. Hertz, J. reine angew. Math. 92 (1882) 156-171,
  DOI 10.1515/crll.1882.92.156; K. L. Johnson, *Contact Mechanics*,
  Cambridge University Press, 1985, ISBN 978-0-521-34796-9, sections 3.4, 3.6
  and 4.2).
- The layer-dominated (rigid-body) limit: when both bodies are rigid the
  contact condition (paper eq. 14) reduces pointwise to
  ``w(p) = delta - h``, so ``p = w^{-1}(max(delta - h, 0))``.

All lengths, forces and pressures are in one consistent set of user units;
``E_star`` is Johnson's effective modulus (:func:`bem.materials.effective_modulus`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.special import elliprd, elliprf

from bem.checks import fail, check_callable, check_choice, check_finite_array, check_nonnegative, check_positive

__all__ = [
    "HertzSphere",
    "HertzElliptic",
    "RigidLayerParaboloid",
    "hertz_sphere",
    "hertz_elliptic",
    "rigid_layer_pressure",
    "rigid_layer_paraboloid",
    "rigid_layer_force",
]


def _load(force, approach):
    """Exactly one of ``force`` / ``approach``, validated ``> 0``: ``(name, value)``."""
    if (force is None) == (approach is None):
        fail("(force, approach)", (force, approach), "exactly one given (force control or approach control)")
    return ("force", check_positive("force", force)) if force is not None else (
        "approach", check_positive("approach", approach))


@dataclass(frozen=True)
class HertzSphere:
    """Hertz solution for ``h = r**2 / (2 R)`` (Johnson 1985, sec. 4.2).

    Attributes
    ----------
    R, E_star : float
        Effective radius [length] and modulus [pressure].
    force, delta : float
        Total force [force] and approach [length].
    a, p0 : float
        Contact radius [length] and peak pressure [pressure].
    """

    R: float
    E_star: float
    force: float
    delta: float
    a: float
    p0: float

    def pressure(self, r):
        """``p0 sqrt(1 - r**2/a**2)`` for ``r < a``, else 0 [pressure]."""
        r = np.asarray(r, dtype=float)
        return self.p0 * np.sqrt(np.maximum(1.0 - (r / self.a) ** 2, 0.0))

    def displacement(self, r):
        """Total normal surface displacement ``u(r)`` [length] (Johnson 1985, sec. 3.4).

        ``u = pi p0 (2a**2 - r**2) / (4 a E*)`` for ``r <= a``, and
        ``u = p0 [(2a**2 - r**2) asin(a/r) + a sqrt(r**2 - a**2)] / (2 a E*)``
        for ``r > a``; inside the contact ``u = delta - h``.
        """
        r = np.abs(np.asarray(r, dtype=float))
        a = self.a
        rr = np.maximum(r, a)  # the outer branch on r >= a only
        outer = ((2 * a * a - rr * rr) * np.arcsin(a / rr) + a * np.sqrt(rr * rr - a * a))
        inner = math.pi * (2 * a * a - r * r) / 2.0
        return self.p0 / (2.0 * a * self.E_star) * np.where(r <= a, inner, outer)


def hertz_sphere(R, E_star, *, force=None, approach=None):
    """Hertz contact of a sphere (paraboloid ``h = r**2/(2R)``) on a half-space.

    ``a**3 = 3 P R / (4 E*)``, ``p0 = 3 P / (2 pi a**2)``, ``delta = a**2 / R``
    (Hertz 1882, DOI 10.1515/crll.1882.92.156; Johnson 1985, ISBN
    978-0-521-34796-9, sec. 4.2).

    Parameters
    ----------
    R : float
        Effective radius [length], ``> 0``.
    E_star : float
        Effective modulus [pressure], ``> 0``.
    force, approach : float, keyword-only
        Exactly one: total force ``P`` [force] or approach ``delta`` [length], ``> 0``.

    Returns
    -------
    HertzSphere
    """
    R = check_positive("R", R)
    E_star = check_positive("E_star", E_star)
    kind, value = _load(force, approach)
    if kind == "force":
        a = (3.0 * value * R / (4.0 * E_star)) ** (1.0 / 3.0)
        force = value
    else:
        a = math.sqrt(R * value)
        force = 4.0 * E_star * a**3 / (3.0 * R)
    return HertzSphere(R=R, E_star=E_star, force=force, delta=a * a / R, a=a,
                       p0=3.0 * force / (2.0 * math.pi * a * a))


@dataclass(frozen=True)
class HertzElliptic:
    """Hertz solution for ``h = x**2/(2 Rx) + y**2/(2 Ry)``.

    Attributes
    ----------
    Rx, Ry, E_star : float
        Radii [length] and effective modulus [pressure].
    force, delta : float
        Total force [force] and approach [length].
    a, b : float
        Semi-axes of the contact ellipse along x and along y [length]; the
        longer one lies along the axis of the larger radius.
    p0 : float
        Peak pressure [pressure].
    eccentricity : float
        ``e = sqrt(1 - (minor/major)**2)`` [-].
    """

    Rx: float
    Ry: float
    E_star: float
    force: float
    delta: float
    a: float
    b: float
    p0: float
    eccentricity: float

    def pressure(self, x, y):
        """``p0 sqrt(1 - x**2/a**2 - y**2/b**2)`` inside the ellipse, else 0 [pressure]."""
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        return self.p0 * np.sqrt(np.maximum(1.0 - (x / self.a) ** 2 - (y / self.b) ** 2, 0.0))


def _axis_ratio_squared(curvature_ratio):
    """``q = (minor/major)**2`` of the Hertz ellipse for ``B/A = curvature_ratio >= 1``.

    Solves ``R_D(0, 1, q) / R_D(0, q, 1) = B/A``, the eccentricity equation
    ``B/A = (E/(1-m) - K) / (K - E)``, ``m = e**2 = 1 - q`` (Johnson 1985,
    sec. 4.2), written with Carlson's integrals ``K - E = (m/3) R_D(0, q, 1)``,
    ``E - q K = (m q/3) R_D(0, 1, q)`` (DLMF 19.25.1) so that no cancellation
    occurs near the circle. Root by Brent's method in ``ln q``, stopped when
    the bracket is below ``4 eps |ln q| + 1e-15``.
    """
    if curvature_ratio == 1.0:
        return 1.0

    def f(log_q):
        q = math.exp(log_q)
        return math.log(elliprd(0.0, 1.0, q) / elliprd(0.0, q, 1.0)) - math.log(curvature_ratio)

    low = -1.0
    while f(low) < 0.0:  # the ratio grows without bound as q -> 0
        low *= 2.0
    return math.exp(brentq(f, low, 0.0, xtol=1e-15, rtol=4.0 * np.finfo(float).eps))


def hertz_elliptic(Rx, Ry, E_star, *, force=None, approach=None):
    """Hertz contact of an elliptic paraboloid ``h = A x**2 + B y**2`` on a half-space.

    With ``A = 1/(2 Rx)``, ``B = 1/(2 Ry)``, the pressure
    ``p0 sqrt(1 - x**2/a**2 - y**2/b**2)`` gives inside the ellipse the
    displacement ``u = (L - M x**2 - N y**2)/(pi E*)`` (Johnson 1985, ISBN
    978-0-521-34796-9, sec. 3.6 and 4.2; Hertz 1882, DOI
    10.1515/crll.1882.92.156). Matching ``u = delta - h`` gives, for the
    major semi-axis ``a_M`` along the smaller curvature ``A_m = min(A, B)``,
    ``q = (a_m/a_M)**2`` from :func:`_axis_ratio_squared`, ``m = 1 - q``::

        a_M**3 = P R_D(0, q, 1) / (2 pi E* A_m)
        p0     = 3 P / (2 pi a_M a_m)
        delta  = p0 a_m K(m) / E*,      K(m) = R_F(0, q, 1)

    and, under approach control, ``a_M**2 = delta R_D(0, q, 1) / (3 A_m K(m))``.
    ``Rx == Ry`` reproduces :func:`hertz_sphere`.

    Parameters
    ----------
    Rx, Ry : float
        Radii of relative curvature in the x-z and y-z planes [length], ``> 0``.
    E_star : float
        Effective modulus [pressure], ``> 0``.
    force, approach : float, keyword-only
        Exactly one: total force [force] or approach [length], ``> 0``.

    Returns
    -------
    HertzElliptic
        ``a`` is the semi-axis along x, ``b`` along y.
    """
    Rx = check_positive("Rx", Rx)
    Ry = check_positive("Ry", Ry)
    E_star = check_positive("E_star", E_star)
    kind, value = _load(force, approach)
    A_m = 1.0 / (2.0 * max(Rx, Ry))
    q = _axis_ratio_squared(max(Rx, Ry) / min(Rx, Ry))
    rd, K = float(elliprd(0.0, q, 1.0)), float(elliprf(0.0, q, 1.0))
    if kind == "force":
        force = value
        major = (force * rd / (2.0 * math.pi * E_star * A_m)) ** (1.0 / 3.0)
    else:
        major = math.sqrt(value * rd / (3.0 * A_m * K))
        force = 2.0 * math.pi * E_star * A_m * major**3 / rd
    minor = major * math.sqrt(q)
    p0 = 3.0 * force / (2.0 * math.pi * major * minor)
    a, b = (major, minor) if Rx >= Ry else (minor, major)
    return HertzElliptic(Rx=Rx, Ry=Ry, E_star=E_star, force=force, delta=p0 * minor * K / E_star,
                         a=a, b=b, p0=p0, eccentricity=math.sqrt(1.0 - q))


def rigid_layer_pressure(layer, gap_values, approach):
    """Pressure when both bodies are rigid: ``p = w^{-1}(max(delta - h, 0))`` [pressure].

    The contact condition (paper eq. 14) with ``u = 0`` leaves
    ``w(p) = delta - h`` where ``p > 0``.

    Parameters
    ----------
    layer : object
        Any layer with ``inverse(closure)`` (:class:`bem.layers.Layer`).
    gap_values : array_like
        Gap ``h`` [length] at the points of interest, finite.
    approach : float
        Approach ``delta`` [length], ``>= 0``.

    Returns
    -------
    numpy.ndarray
        Pressure, same shape as ``gap_values``.
    """
    inverse = check_callable("layer.inverse", getattr(layer, "inverse", None))
    h = check_finite_array("gap_values", gap_values, min_size=0)
    approach = check_nonnegative("approach", approach)
    return np.asarray(inverse(np.maximum(approach - h, 0.0)), dtype=float)


_FIXED_EXPONENT = {"linear": 1.0, "root": 0.5}


def _power_parameters(law, lam, s):
    """``(lam, s)`` of ``w = lam p**s`` from a law name or a layer object."""
    if isinstance(law, str):
        law = check_choice("law", law, ("linear", "power", "root"))
        lam = check_positive("lam", lam)
        if law == "power":
            return lam, check_positive("s", s)
        fixed = _FIXED_EXPONENT[law]
        if s is not None and s != fixed:
            fail("s", s, f"left out (or {fixed}) for law={law!r}")
        return lam, fixed
    if lam is not None or s is not None:
        fail("(lam, s)", (lam, s), "left out when law is a layer object (they are read from it)")
    lam = check_positive("law.lam", getattr(law, "lam", None))
    s = getattr(law, "s", None)
    if s is None:
        s = 1.0 if getattr(law, "is_linear", False) else 0.5 if type(law).__name__ == "Root" else None
    if s is None:
        fail("law", law, "a Linear, Power or Root layer, or 'linear', 'power', 'root' with lam (and s)")
    s = check_positive("law.s", s)
    p = np.array([0.5, 2.0])
    if not np.allclose(law.w(p), lam * p**s, rtol=1e-12, atol=0.0):
        fail("law", law, f"a power law w = lam * p**s with lam = {lam}, s = {s}")
    return lam, s


@dataclass(frozen=True)
class RigidLayerParaboloid:
    """Rigid paraboloid ``h = r**2/(2R)`` pressed into a power-law layer ``w = lam p**s``.

    Attributes
    ----------
    R, lam, s : float
        Radius [length], compliance [length / pressure**s], exponent [-].
    force, delta : float
        Total force [force] and approach [length].
    contact_radius : float
        ``sqrt(2 R delta)`` [length].
    p_max : float
        ``(delta / lam)**(1/s)`` [pressure], at the centre.
    """

    R: float
    lam: float
    s: float
    force: float
    delta: float
    contact_radius: float
    p_max: float

    def pressure(self, r):
        """``((delta - r**2/(2R)) / lam)**(1/s)`` inside, 0 outside [pressure]."""
        r = np.asarray(r, dtype=float)
        closure = np.maximum(self.delta - r * r / (2.0 * self.R), 0.0)
        return (closure / self.lam) ** (1.0 / self.s)


def rigid_layer_paraboloid(law, R, *, force=None, approach=None, lam=None, s=None):
    """Layer-dominated limit for a paraboloid: closed-form force-approach law.

    With ``p = ((delta - h)/lam)**(1/s)`` and ``h = r**2/(2R)``, the
    substitution ``u = delta - r**2/(2R)`` (``r dr = -R du``) gives::

        P = 2 pi integral_0^rc p r dr = 2 pi R integral_0^delta (u/lam)**(1/s) du
          = 2 pi R delta**(1/s + 1) / (lam**(1/s) (1/s + 1))

    i.e. ``P = pi R delta**2 / lam`` (linear, ``s = 1``) and
    ``P = 2 pi R delta**3 / (3 lam**2)`` (root, ``s = 1/2``); force control
    inverts it, ``delta = (P lam**(1/s) (1/s + 1) / (2 pi R))**(s/(1 + s))``.

    Parameters
    ----------
    law : str or layer object
        ``"linear"``, ``"power"`` or ``"root"`` with ``lam`` (and ``s`` for
        ``"power"``); or a ``bem.layers`` ``Linear``/``Power``/``Root`` object,
        whose ``lam`` (and ``s``; 1 for linear, 1/2 for root) are read and
        checked against its ``w``.
    R : float
        Radius [length], ``> 0``.
    force, approach : float, keyword-only
        Exactly one, ``> 0``.
    lam, s : float, keyword-only
        Layer parameters when ``law`` is a name.

    Returns
    -------
    RigidLayerParaboloid
    """
    lam, s = _power_parameters(law, lam, s)
    R = check_positive("R", R)
    kind, value = _load(force, approach)
    k = 1.0 / s + 1.0
    scale = 2.0 * math.pi * R / (lam ** (1.0 / s) * k)  # P = scale * delta**k
    delta = value if kind == "approach" else (value / scale) ** (1.0 / k)
    return RigidLayerParaboloid(R=R, lam=lam, s=s, force=scale * delta**k, delta=delta,
                                contact_radius=math.sqrt(2.0 * R * delta), p_max=(delta / lam) ** (1.0 / s))


def rigid_layer_force(law, R, approach, *, lam=None, s=None):
    """Force [force] of the layer-dominated paraboloid at ``approach`` [length].

    Shorthand for ``rigid_layer_paraboloid(law, R, approach=approach, ...).force``.
    """
    return rigid_layer_paraboloid(law, R, approach=approach, lam=lam, s=s).force
