"""A coating bonded to an elastic half-space: its surface compliance per Fourier mode.

A body of the contact may carry a coating: an elastic layer of thickness ``t`` (Young's modulus
``E_c``, Poisson's ratio ``nu_c``) bonded to the body's own material (the substrate, ``E_s``,
``nu_s``), loaded on its free surface by a normal pressure without shear. Under a pressure mode
``p(x) = P cos(q . x)`` the surface sinks by ``u(x) = S(q) P cos(q . x)`` with ::

    S(q) = 2 s(q) / q,    s(q) = (1 - nu_c**2) / E_c * phi(q t)                       (1)

the homogeneous half-space's ``2 (1 - nu**2) / (E q)`` with the coating's constants, times the
coating factor ::

    phi(x) = (1 + 4 kappa x e^(-2x) - lambda kappa e^(-4x))
             / (1 - (lambda + kappa + 4 kappa x^2) e^(-2x) + lambda kappa e^(-4x))       (2)

    lambda = 1 - 4 (1 - nu_c) / (1 + k (3 - 4 nu_s)),
    kappa  = (k - 1) / (k + 3 - 4 nu_c),          k = mu_c / mu_s

(``mu = E / (2 (1 + nu))`` the shear moduli; M. O'Sullivan and R. King, J. Tribol. 110 (1988)
235-240, doi:10.1115/1.3261575, in the notation of docs/method.md section 7, which derives it).
``phi`` tends to 1 for ``q t -> inf`` (the coating's half-space), to ``E*_c / E*_s`` for
``q t -> 0`` (the substrate's; ``E* = E / (1 - nu**2)``), and is 1 for equal materials. A rigid
substrate (``E_s = inf``) gives ``k = 0``, the layer on a rigid base.

``s(q)`` plays the part of ``(1 - nu**2) / E`` in Johnson's ``1 / E* = (1 - nu1**2)/E1 +
(1 - nu2**2)/E2``: two bodies, coated or not, have the combined symbol ``2 (s1(q) + s2(q)) / q``.

Each factor of (2) is evaluated without overflow for every ``q t >= 0`` (only ``e^(-2x)`` is
formed, and ``x`` above 350 gives ``phi = 1`` to round-off) and without cancellation of the
``x -> 0`` limit (``1 - lambda kappa``, ``1 - lambda``, ``1 - kappa`` in closed form, ``1 - e^(-2x)``
by ``expm1``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .checks import check_positive, check_range, check_scale
from .errors import InputError
from .materials import NU_MAX, NU_MIN

__all__ = ["Bodies", "Coating", "check_uncoated_body", "coating_factor", "factor_constants", "factor_taylor", "mode_compliance",
           "oedometric_compliance"]

#: Beyond this ``q t`` every exponential of (2) is below 1e-300: ``phi = 1`` to round-off.
_X_CLIP = 350.0


@dataclass(frozen=True)
class Coating:
    """An elastic coating bonded to a body (the body's own ``E``, ``nu`` are the substrate's).

    Parameters
    ----------
    thickness : float
        Coating thickness ``t`` [length], finite and ``> 0``.
    E : float
        Young's modulus of the coating [pressure], finite and ``> 0``.
    nu : float
        Poisson's ratio of the coating [-], in ``(-1, 0.5]``.
    """

    thickness: float
    E: float
    nu: float

    def __post_init__(self):
        object.__setattr__(self, "thickness", check_positive("thickness", self.thickness))
        object.__setattr__(self, "E", check_scale("E", self.E))
        object.__setattr__(self, "nu", check_range("nu", self.nu, NU_MIN, NU_MAX, low_open=True))


def _substrate(E_substrate, nu_substrate, names=("E_substrate", "nu_substrate")):
    """``(E, nu)`` of a substrate checked (``E = math.inf``: rigid), the messages naming ``names``."""
    nu_s = check_range(names[1], nu_substrate, NU_MIN, NU_MAX, low_open=True)
    if isinstance(E_substrate, (int, float)) and not isinstance(E_substrate, bool) and E_substrate == math.inf:
        return math.inf, nu_s
    return check_scale(names[0], E_substrate), nu_s


def coating_factor(x, coating, E_substrate, nu_substrate):
    """The coating factor ``phi(q t)`` of equation (2) of :mod:`bem.coating` [-].

    Parameters
    ----------
    x : array_like
        ``q t``, the wavenumber [1/length] times the coating thickness [length]; ``>= 0``.
    coating : Coating
        The coating (its ``thickness`` is not used: ``x`` carries it).
    E_substrate : float
        Young's modulus of the substrate [pressure]; ``math.inf`` for a rigid substrate.
    nu_substrate : float
        Poisson's ratio of the substrate [-], in ``(-1, 0.5]``.

    Returns
    -------
    numpy.ndarray
        ``phi`` at each ``x`` (a new array; ``x`` is not modified), between ``E*_c / E*_s`` at
        ``x = 0`` and 1 as ``x -> inf``.
    """
    shape = np.shape(x)
    x = np.minimum(np.asarray(x, dtype=float).ravel(), _X_CLIP)
    if x.size and not np.all(x >= 0):
        raise ValueError("x = q t must be >= 0 (and not NaN)")
    one_m_lam, one_m_kap, one_m_lk = factor_constants(coating, E_substrate, nu_substrate)
    lam, kap = 1.0 - one_m_lam, 1.0 - one_m_kap
    lk = lam * kap
    e = np.exp(-2.0 * x)
    one_m_e = -np.expm1(-2.0 * x)
    one_m_e2 = -np.expm1(-4.0 * x)
    num = one_m_lk + lk * one_m_e2 + 4.0 * kap * x * e
    den = one_m_lam * one_m_kap + (lam + kap) * one_m_e - lk * one_m_e2 - 4.0 * kap * x * x * e
    # Below x = 1 the numerator times e^(2x) is (1 - lambda kappa) e^(2x) + 2 lambda kappa
    # (sinh 2x - 2x) + 4 x kappa (1 + lambda): on a stiff substrate its terms cancel to order x
    # (to x^3 for an incompressible coating), which this form keeps to round-off.
    small = x < 1.0
    if np.any(small):
        xs = x[small]
        grow = np.exp(2.0 * xs)
        num_small = one_m_lk * grow + 2.0 * lk * _sinh_minus(2.0 * xs) + 4.0 * xs * kap * (2.0 - one_m_lam)
        num[small] = num_small / grow
    return (num / den).reshape(shape)


def factor_constants(coating, E_substrate, nu_substrate):
    """``(1 - lambda, 1 - kappa, 1 - lambda kappa)`` of equation (2) [-], each in closed form (no cancellation
    on a stiff substrate); the substrate's ``E_substrate`` [pressure] may be ``math.inf`` (rigid)."""
    E_s, nu_s = _substrate(E_substrate, nu_substrate)
    nu_c = coating.nu
    mu_c = coating.E / (2.0 * (1.0 + nu_c))
    k = 0.0 if E_s == math.inf else mu_c / (E_s / (2.0 * (1.0 + nu_s)))
    a_s, f = 3.0 - 4.0 * nu_s, 3.0 - 4.0 * nu_c
    one_m_lam = 4.0 * (1.0 - nu_c) / (1.0 + k * a_s)
    one_m_kap = 4.0 * (1.0 - nu_c) / (k + f)
    one_m_lk = k * (1.0 + a_s) * (1.0 + f) / ((1.0 + k * a_s) * (k + f))
    return one_m_lam, one_m_kap, one_m_lk


def factor_taylor(coating, E_substrate, nu_substrate, *, order):
    """Taylor coefficients ``phi_m`` of ``phi(x) = sum_m phi_m x^m`` at ``x = 0``, ``m <= order`` [-].

    By the Cauchy integral (the trapezoidal rule on ``8 (order + 1)`` points, equation (2) at complex
    ``x``) on a circle of radius ``0.6 r0``: ``r0`` is the largest radius of the ladder ``2 * 0.8**j``
    whose circle encloses no zero of the denominator of (2) (a pole of ``phi``), counted by the
    winding number of the denominator on 2048 points.

    Parameters
    ----------
    coating, E_substrate, nu_substrate
        As for :func:`coating_factor`.
    order : int
        Highest power kept, ``>= 0``.

    Returns
    -------
    coefficients : numpy.ndarray
        ``phi_0 .. phi_order`` (real); coefficient ``m`` carries a rounding error of about
        ``1e-16 max|phi| / radius**m``.
    radius : float
        The radius of the circle used [-], below the radius of convergence of the series.
    """
    one_m_lam, one_m_kap, _ = factor_constants(coating, E_substrate, nu_substrate)
    lam, kap = 1.0 - one_m_lam, 1.0 - one_m_kap

    def parts(x):
        e = np.exp(-2.0 * x)
        return 1.0 + 4.0 * kap * x * e - lam * kap * e * e, 1.0 - (lam + kap + 4.0 * kap * x * x) * e + lam * kap * e * e

    ring = np.exp(2j * np.pi * np.arange(2048) / 2048)
    radius = 2.0
    for _ in range(80):  # down to 2 * 0.8**80 = 3e-8
        den = parts(radius * ring)[1]
        winding = np.sum(np.angle(np.roll(den, -1) / den)) / (2.0 * np.pi)
        if abs(winding) < 0.5:
            break
        radius *= 0.8
    else:
        raise ArithmeticError("phi has a pole within 3e-8 of x = 0: no Taylor series")
    radius *= 0.6
    n = 8 * (int(order) + 1)
    num, den = parts(radius * np.exp(2j * np.pi * np.arange(n) / n))
    coeffs = np.fft.fft(num / den)[: int(order) + 1].real / n
    return coeffs / radius ** np.arange(int(order) + 1), radius


def _sinh_minus(y):
    """``sinh(y) - y`` for ``0 <= y < 2`` to round-off (its Taylor series below 1)."""
    out = np.sinh(y) - y
    low = y < 1.0
    yl = y[low]
    term, total = yl ** 3 / 6.0, np.zeros_like(yl)
    for n in range(1, 11):  # y^(2n+1) / (2n+1)!, the last term below 1e-22
        total += term
        term = term * yl * yl / ((2 * n + 2) * (2 * n + 3))
    out[low] = total
    return out


def mode_compliance(q, E, nu, coating=None):
    """A body's compliance ``s(q)`` per Fourier mode, equation (1) of :mod:`bem.coating` [1/pressure].

    Parameters
    ----------
    q : array_like
        Wavenumbers ``|q|`` [1/length], ``>= 0``.
    E, nu : float
        The body's Young's modulus [pressure] (``math.inf``: rigid) and Poisson's ratio [-]; with a
        coating, the substrate's.
    coating : Coating, optional
        The coating bonded to the body; ``None`` for a homogeneous body.

    Returns
    -------
    numpy.ndarray
        ``s(q)``: ``(1 - nu**2) / E`` at every ``q`` without a coating; the surface sinks by
        ``2 s(q) / q`` per unit pressure amplitude of the mode ``q``.
    """
    q = np.asarray(q, dtype=float)
    if coating is None:
        E_s, nu_s = _substrate(E, nu)
        return np.full(q.shape, 0.0 if E_s == math.inf else (1.0 - nu_s * nu_s) / E_s)
    base = (1.0 - coating.nu ** 2) / coating.E
    return base * coating_factor(q * coating.thickness, coating, E, nu)


def oedometric_compliance(coating):
    """The coating's oedometric (laterally confined) compliance ``t (1 + nu)(1 - 2 nu) / ((1 - nu) E)`` [length/pressure].

    The limit of ``2 s(q) / q`` on a rigid substrate as ``q t -> 0``: the compliance ``lam`` of
    the linear Winkler layer ``w = lam p`` that a thin coating on a stiff substrate stands for
    (0 for an incompressible coating, ``nu = 0.5``).
    """
    nu = coating.nu
    return coating.thickness * (1.0 + nu) * (1.0 - 2.0 * nu) / ((1.0 - nu) * coating.E)


@dataclass(frozen=True)
class Bodies:
    """The two bodies of a contact whose compliance is not one ``E*``: a coating on either or both.

    Parameters
    ----------
    E1, nu1, E2, nu2 : float
        Young's moduli [pressure] (``math.inf``: rigid) and Poisson's ratios [-] of the bodies; of
        the substrates where a body is coated.
    coating1, coating2 : Coating, optional
        The coating of each body; ``None`` for a homogeneous body.

    Notes
    -----
    The combined compliance of mode ``q`` is ``2 (s1(q) + s2(q)) / q`` [length/pressure per
    wavenumber] (:func:`mode_compliance`); :attr:`E_star` is that of the substrates, the limit
    ``q -> 0`` (long waves see through the coatings).
    """

    E1: float
    nu1: float
    E2: float
    nu2: float
    coating1: Coating | None = None
    coating2: Coating | None = None

    def __post_init__(self):
        for i, (E, nu) in enumerate(((self.E1, self.nu1), (self.E2, self.nu2)), start=1):
            _substrate(E, nu, (f"E{i}", f"nu{i}"))
            coating = getattr(self, f"coating{i}")
            if coating is not None and not isinstance(coating, Coating):
                raise InputError(f"coating{i} = {coating!r} is not allowed: it must be a bem.Coating or None.")
        if self.E1 == math.inf and self.E2 == math.inf:
            raise InputError("E1 = E2 = inf is not allowed: at least one body must be elastic.")

    @property
    def is_coated(self):
        """Whether either body carries a coating."""
        return self.coating1 is not None or self.coating2 is not None

    @property
    def E_star(self):
        """The effective modulus of the substrates ``1 / (s1(0) + s2(0))`` [pressure]."""
        return 1.0 / float(mode_compliance(0.0, self.E1, self.nu1) + mode_compliance(0.0, self.E2, self.nu2))

    def compliance(self, q):
        """``s1(q) + s2(q)`` [1/pressure] at the wavenumbers ``q`` [1/length]; the surface closure of mode
        ``q`` is ``2 (s1 + s2) / q`` per unit pressure amplitude."""
        return (mode_compliance(q, self.E1, self.nu1, self.coating1)
                + mode_compliance(q, self.E2, self.nu2, self.coating2))


def check_uncoated_body(result, body):
    """Refuse ``body`` of ``result`` for a homogeneous body's stresses (:func:`bem.subsurface_stress`): a
    coated body, or no body named where one of the two is coated; ``body`` must be 1, 2 or None."""
    bodies = getattr(result, "bodies", None)
    coated = [] if bodies is None else [i for i in (1, 2) if getattr(bodies, f"coating{i}") is not None]
    if body is not None and body not in (1, 2):
        raise InputError(f"body = {body!r} is not allowed: it must be 1, 2 or None.")
    if not coated:
        return
    if body is None:
        raise InputError(f"body = None is not allowed for this result: body {coated[0]} is coated, so the body must be "
                         "named (its stresses, in the coating and the substrate: bem.coated_stress).")
    if body in coated:
        raise InputError(f"body = {body!r} is not allowed: that body is coated, and its stresses are those of "
                         "bem.coated_stress (in the coating and the substrate), not of a homogeneous half-space.")
