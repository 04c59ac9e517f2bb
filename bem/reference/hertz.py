"""Hertz contact of a paraboloid and of an elliptic paraboloid, in closed form.

H. Hertz, J. reine angew. Math. 92 (1882) 156-171, doi:10.1515/crll.1882.92.156;
K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985, ISBN
978-0-521-34796-9, sections 3.4, 3.6 and 4.2. Lengths, forces and pressures in one
consistent set of units; ``E_star`` is Johnson's effective modulus
(:func:`bem.materials.effective_modulus`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_load, check_positive

__all__ = ["HertzSphere", "HertzElliptic", "hertz_sphere", "hertz_elliptic"]


@dataclass(frozen=True)
class _ClosedForm:
    """What every closed form shares with the solver results."""

    converged = True
    is_axisymmetric = True  # HertzElliptic: only with Rx == Ry

    @property
    def message(self):
        return f"closed form ({type(self).__name__})"

    @property
    def contact_area(self):
        """Area of the contact [length^2]: ``pi contact_radius^2``."""
        return math.pi * self.contact_radius**2


@dataclass(frozen=True)
class HertzSphere(_ClosedForm):
    """Hertz solution for ``h = r**2 / (2 R)`` (Johnson 1985, sec. 4.2).

    Attributes
    ----------
    R, E_star : float
        Effective radius [length] and modulus [pressure].
    force, approach : float
        Total force [force] and approach ``delta`` [length].
    contact_radius, p_max : float
        Contact radius ``a`` [length] and peak pressure ``p0`` [pressure].
    """

    R: float
    E_star: float
    force: float
    approach: float
    contact_radius: float
    p_max: float

    def pressure(self, x, y=0.0):
        """``p0 sqrt(1 - r**2/a**2)`` for ``r = hypot(x, y) < a``, else 0 [pressure]."""
        r = np.hypot(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        return self.p_max * np.sqrt(np.maximum(1.0 - (r / self.contact_radius) ** 2, 0.0))

    def displacement(self, r):
        """Total normal surface displacement ``u(r)`` [length] (Johnson 1985, sec. 3.4).

        ``u = pi p0 (2a**2 - r**2) / (4 a E*)`` for ``r <= a``, and
        ``u = p0 [(2a**2 - r**2) asin(a/r) + a sqrt(r**2 - a**2)] / (2 a E*)``
        for ``r > a``; inside the contact ``u = delta - h``.
        """
        r = np.abs(np.asarray(r, dtype=float))
        a = self.contact_radius
        rr = np.maximum(r, a)  # the outer branch on r >= a only
        outer = ((2 * a * a - rr * rr) * np.arcsin(a / rr) + a * np.sqrt(rr * rr - a * a))
        inner = math.pi * (2 * a * a - r * r) / 2.0
        return self.p_max / (2.0 * a * self.E_star) * np.where(r <= a, inner, outer)


def hertz_sphere(R, E_star, *, force=None, approach=None):
    """Hertz contact of a sphere (paraboloid ``h = r**2/(2R)``) on a half-space.

    ``a**3 = 3 P R / (4 E*)``, ``p0 = 3 P / (2 pi a**2)``, ``delta = a**2 / R``
    (Hertz 1882, doi:10.1515/crll.1882.92.156; Johnson 1985, sec. 4.2).

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
    force, approach = check_load(force, approach)
    if force is not None:
        a = (3.0 * force * R / (4.0 * E_star)) ** (1.0 / 3.0)
    else:
        a = math.sqrt(R * approach)
        force = 4.0 * E_star * a**3 / (3.0 * R)
    return HertzSphere(R=R, E_star=E_star, force=force, approach=a * a / R, contact_radius=a,
                       p_max=3.0 * force / (2.0 * math.pi * a * a))


@dataclass(frozen=True)
class HertzElliptic(_ClosedForm):
    """Hertz solution for ``h = x**2/(2 Rx) + y**2/(2 Ry)``.

    Attributes
    ----------
    Rx, Ry, E_star : float
        Radii [length] and effective modulus [pressure].
    force, approach : float
        Total force [force] and approach ``delta`` [length].
    a, b : float
        Semi-axes of the contact ellipse along x and along y [length]; the longer one
        lies along the axis of the larger radius.
    p_max : float
        Peak pressure ``p0`` [pressure].
    eccentricity : float
        ``e = sqrt(1 - (minor/major)**2)`` [-].
    """

    Rx: float
    Ry: float
    E_star: float
    force: float
    approach: float
    a: float
    b: float
    p_max: float
    eccentricity: float

    @property
    def contact_radius(self):
        """Radius of the circle of the same area, ``sqrt(a b)`` [length] (as for the BEM)."""
        return math.sqrt(self.a * self.b)

    @property
    def is_axisymmetric(self):
        return self.Rx == self.Ry

    def pressure(self, x, y=0.0):
        """``p0 sqrt(1 - x**2/a**2 - y**2/b**2)`` inside the ellipse, else 0 [pressure]."""
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        return self.p_max * np.sqrt(np.maximum(1.0 - (x / self.a) ** 2 - (y / self.b) ** 2, 0.0))


def _axis_ratio_squared(curvature_ratio):
    """``q = (minor/major)**2`` of the Hertz ellipse for ``B/A = curvature_ratio >= 1``.

    Solves ``R_D(0, 1, q) / R_D(0, q, 1) = B/A``, the eccentricity equation
    ``B/A = (E/(1-m) - K) / (K - E)``, ``m = e**2 = 1 - q`` (Johnson 1985,
    sec. 4.2), written with Carlson's integrals ``K - E = (m/3) R_D(0, q, 1)``,
    ``E - q K = (m q/3) R_D(0, 1, q)`` (DLMF 19.25.1) so that no cancellation
    occurs near the circle. Root by Brent's method in ``ln q``, stopped when
    the bracket is below ``4 eps |ln q| + 1e-15``.
    """
    from scipy.optimize import brentq
    from scipy.special import elliprd

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
    displacement ``u = (L - M x**2 - N y**2)/(pi E*)`` (Johnson 1985, sec. 3.6
    and 4.2; Hertz 1882, doi:10.1515/crll.1882.92.156). Matching ``u = delta - h``
    gives, for the major semi-axis ``a_M`` along the smaller curvature
    ``A_m = min(A, B)``, ``q = (a_m/a_M)**2`` from :func:`_axis_ratio_squared`,
    ``m = 1 - q``::

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
    from scipy.special import elliprd, elliprf

    Rx = check_positive("Rx", Rx)
    Ry = check_positive("Ry", Ry)
    E_star = check_positive("E_star", E_star)
    force, approach = check_load(force, approach)
    A_m = 1.0 / (2.0 * max(Rx, Ry))
    q = _axis_ratio_squared(max(Rx, Ry) / min(Rx, Ry))
    rd, K = float(elliprd(0.0, q, 1.0)), float(elliprf(0.0, q, 1.0))
    if force is not None:
        major = (force * rd / (2.0 * math.pi * E_star * A_m)) ** (1.0 / 3.0)
    else:
        major = math.sqrt(approach * rd / (3.0 * A_m * K))
        force = 2.0 * math.pi * E_star * A_m * major**3 / rd
    minor = major * math.sqrt(q)
    p0 = 3.0 * force / (2.0 * math.pi * major * minor)
    a, b = (major, minor) if Rx >= Ry else (minor, major)
    return HertzElliptic(Rx=Rx, Ry=Ry, E_star=E_star, force=force, approach=p0 * minor * K / E_star,
                         a=a, b=b, p_max=p0, eccentricity=math.sqrt(1.0 - q))
