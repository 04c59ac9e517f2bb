"""Persson's theory of the contact of a randomly rough surface: contact area and mean gap from the PSD.

A rough surface of isotropic PSD ``C(q)`` (normalised so that ``h_rms^2 = int d^2q C(q) =
2 pi int q C(q) dq``), pressed by the mean pressure ``p`` against a flat, with the effective
modulus ``E*`` of the pair. With the second spectral moment, the mean square slope,

    m2 = <grad z . grad z> = 2 pi int q^3 C(q) dq = h'_rms^2,

Persson's diffusion of the pressure distribution (Persson 2001, J. Chem. Phys. 115, 3840,
DOI 10.1063/1.1388626; ``G = (pi/4) (E*/p)^2 int q^3 C dq``, ``A/A0 = erf(1/(2 sqrt G))``) gives
the real contact fraction

    A/A0 = erf( p / (E* sqrt(m2/2)) ) = erf( sqrt(2) p / (E* h'_rms) ),

linear at small pressures, ``A/A0 -> sqrt(8/pi) p/(E* h'_rms)`` (``erf x -> 2x/sqrt(pi)``). The
mean gap ``ubar`` (mean-plane separation) of Persson (2007, PRL 99, 125502, DOI
10.1103/PhysRevLett.99.125502) with the correction factor of Yang & Persson (2008, J. Phys.:
Condens. Matter 20, 215214, DOI 10.1088/0953-8984/20/21/215214) is

    ubar(p) = sqrt(pi) int_{q0}^{q1} q^2 C(q) w(q) I(w(q) p/E*) dq,
    w(q)    = ( pi int_{q0}^{q} q'^3 C(q') dq' )^(-1/2),
    I(s)    = int_s^inf [gamma + 3 (1 - gamma) erf(x)^2] exp(-x^2) dx / x,
    I(s)    = gamma E1(s^2)/2 + 3 (1 - gamma) J(s),

``P(q, p) = erf(w p/E*)`` the contact fraction of the wavelengths up to ``q``, ``E1`` the
exponential integral and ``J(s) = int_s^inf erf(x)^2 exp(-x^2) dx/x`` (tabulated here by
quadrature, :func:`_erf_part`). :data:`GAMMA` = 0.42 is Yang & Persson's value; fits of
simulations give 0.4 to 0.7. At small pressures ``P -> 0`` and ``E1(s^2) ~ -2 ln s``, so

    d ubar / d ln p -> -gamma sqrt(pi) int q^2 C(q) w(q) dq,

the exponential regime ``p ~ exp(-ubar/ubar_0)``. The theory's mean gap diverges as ``p -> 0``;
a finite cell's does not (it stops at the first-touch gap ``max z - mean z``).

**The integrals.** A spectrum is a :class:`Spectrum`: wave numbers ``q_i`` and weights
``c_i = C(q_i) dq_i``, so that ``int f(q) C(q) dq = sum_i f(q_i) c_i``. :func:`psd_spectrum`
makes it from samples of ``C(q)`` (trapezoidal weights); :func:`cell_spectrum` from the heights
of one periodic cell exactly: the discrete Fourier transform gives the variance ``v_k`` of each
wave vector ``k`` (``sum_k v_k = h_rms^2``), and ``int f(q) C(q) dq = (1/2 pi) int d^2q f C/|q|
= sum_k f(|k|) v_k / (2 pi |k|)``. The inner integral ``int_{q0}^{q}`` in ``w`` takes the
points below ``q`` and half of the weight at ``q`` (the midpoint rule on the weights).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..checks import check_finite_array, check_positive, check_range, fail

__all__ = ["Spectrum", "psd_spectrum", "cell_spectrum", "contact_fraction", "mean_gap", "GAMMA"]

#: Yang & Persson's (2008) correction factor of the mean gap
GAMMA = 0.42


@dataclass(frozen=True)
class Spectrum:
    """An isotropic PSD as a quadrature rule (module docstring).

    Attributes
    ----------
    q : ndarray
        Wave numbers ``q_i > 0`` [1/length], strictly increasing.
    weight : ndarray
        ``c_i = C(q_i) dq_i >= 0`` [length^3]: ``int f(q) C(q) dq = sum_i f(q_i) c_i``.
    """

    q: np.ndarray
    weight: np.ndarray

    def moment(self, n):
        """``2 pi int q^(n+1) C(q) dq``: ``h_rms^2`` for ``n = 0``, the mean square slope ``m2`` for ``n = 2``."""
        return float(2 * np.pi * np.sum(self.q ** (n + 1) * self.weight))

    @property
    def rms_slope(self):
        """``h'_rms = sqrt(m2)`` [-]."""
        return float(np.sqrt(self.moment(2)))

    def w(self):
        """``w(q_i) = (pi int_{q0}^{q_i} q^3 C dq)^(-1/2)`` [-], the midpoint rule on the weights."""
        terms = self.q**3 * self.weight
        inner = np.pi * (np.cumsum(terms) - 0.5 * terms)
        out = np.full(self.q.size, np.inf)
        np.divide(1.0, np.sqrt(inner), out=out, where=inner > 0)
        return out


def _spectrum(q, weight):
    order = np.argsort(q, kind="stable")
    q, weight = q[order], weight[order]
    unique, first = np.unique(q, return_index=True)  # a ring of equal |k| is one point of the rule
    return Spectrum(unique, np.add.reduceat(weight, first))


def psd_spectrum(q, psd):
    """A :class:`Spectrum` from samples ``C(q)`` of an isotropic PSD (trapezoidal weights).

    Parameters
    ----------
    q : array_like
        Wave numbers [1/length], ``> 0``, strictly increasing, at least two.
    psd : array_like
        ``C(q)`` [length^4], ``>= 0``, normalised as ``h_rms^2 = 2 pi int q C(q) dq``.
    """
    q = check_finite_array("q", q, ndim=1, min_size=2)
    c = check_finite_array("psd", psd, ndim=1, min_size=2)
    if c.shape != q.shape:
        fail("psd.shape", c.shape, f"the shape {q.shape} of q")
    if q[0] <= 0 or np.any(np.diff(q) <= 0):
        fail("q", f"[{q[0]!r}, ..., {q[-1]!r}]", "positive and strictly increasing")
    if np.any(c < 0):
        fail("psd", float(c.min()), ">= 0 everywhere")
    dq = np.diff(q)
    trapezoid = np.r_[dq, 0.0] / 2 + np.r_[0.0, dq] / 2
    return Spectrum(q, c * trapezoid)


def cell_spectrum(heights, size):
    """The exact :class:`Spectrum` of one periodic cell ``z[i, j]`` of size ``(Lx, Ly)`` (module docstring).

    Parameters
    ----------
    heights : array_like
        ``z[i, j]`` at ``(i Lx/nx, j Ly/ny)`` [length], 2-D, finite (its mean is left out).
    size : (float, float)
        ``(Lx, Ly)`` [length].
    """
    z = check_finite_array("heights", heights, ndim=2)
    if not isinstance(size, (list, tuple, np.ndarray)) or len(size) != 2:
        fail("size", size, "a pair (Lx, Ly) of lengths")
    lx, ly = check_positive("size[0]", size[0]), check_positive("size[1]", size[1])
    nx, ny = z.shape
    v = np.abs(np.fft.fft2(z - z.mean())) ** 2 / (nx * ny) ** 2
    kx = 2 * np.pi * np.fft.fftfreq(nx, lx / nx)[:, None]
    ky = 2 * np.pi * np.fft.fftfreq(ny, ly / ny)[None, :]
    k = np.hypot(kx, ky).ravel()
    keep = (k > 0) & (v.ravel() > 0)
    return _spectrum(k[keep], v.ravel()[keep] / (2 * np.pi * k[keep]))


def _check(pressure, E_star, spectrum):
    p = check_finite_array("pressure", pressure, ndim=None)
    if np.any(p < 0):
        fail("pressure", float(p.min()), ">= 0")
    E_star = check_positive("E_star", E_star)
    if not isinstance(spectrum, Spectrum):
        fail("spectrum", type(spectrum).__name__, "a bem.rough.persson.Spectrum (psd_spectrum, cell_spectrum)")
    if spectrum.moment(2) <= 0:
        fail("spectrum", "no power", "a spectrum with a positive mean square slope")
    return p, E_star


def contact_fraction(pressure, E_star, spectrum):
    """Persson's real contact fraction ``A/A0 = erf(p/(E* sqrt(m2/2)))`` [-] (module docstring).

    Parameters
    ----------
    pressure : float or array_like
        Mean pressure(s) ``p`` [pressure], ``>= 0``.
    E_star : float
        Effective modulus [pressure], ``> 0``.
    spectrum : Spectrum
        :func:`psd_spectrum` or :func:`cell_spectrum`.
    """
    from scipy.special import erf

    p, E_star = _check(pressure, E_star, spectrum)
    return erf(p / (E_star * np.sqrt(spectrum.moment(2) / 2)))


@lru_cache(maxsize=1)
def _erf_table():
    """``(s, J(s))`` on ``0 <= s <= 8``, ``J(s) = int_s^inf erf(x)^2 exp(-x^2) dx/x`` (Simpson, 16384 intervals)."""
    from scipy.integrate import cumulative_simpson
    from scipy.special import erf

    s = np.linspace(0.0, 8.0, 16385)
    x = np.where(s > 0, s, 1.0)
    f = np.where(s > 0, erf(x) ** 2 * np.exp(-(x**2)) / x, 0.0)  # -> (4/pi) x at 0
    below = cumulative_simpson(f, x=s, initial=0.0)
    return s, below[-1] - below  # the tail beyond 8 is below exp(-64)


def _erf_part(s):
    """``J(s)``, interpolated in :func:`_erf_table` (0 beyond ``s = 8``)."""
    grid, table = _erf_table()
    return np.interp(s, grid, table, right=0.0)


def mean_gap(pressure, E_star, spectrum, *, gamma=GAMMA):
    """Persson's mean gap ``ubar(p)`` [length] (Persson 2007, Yang & Persson 2008; module docstring).

    Parameters
    ----------
    pressure : float or array_like
        Mean pressure(s) ``p`` [pressure], ``> 0`` (the mean gap diverges at ``p = 0``).
    E_star : float
        Effective modulus [pressure], ``> 0``.
    spectrum : Spectrum
        :func:`psd_spectrum` or :func:`cell_spectrum`.
    gamma : float
        The correction factor, ``0 <= gamma <= 1`` (default :data:`GAMMA`).
    """
    from scipy.special import exp1

    p, E_star = _check(pressure, E_star, spectrum)
    if np.any(p <= 0):
        fail("pressure", float(p.min()), "> 0 (the mean gap of the theory diverges at p = 0)")
    gamma = check_range("gamma", gamma, 0.0, 1.0)
    w = spectrum.w()
    ok = np.isfinite(w)
    q, c, w = spectrum.q[ok], spectrum.weight[ok], w[ok]
    factor = np.sqrt(np.pi) * q**2 * c * w
    out = np.empty(p.size)
    for k, pk in enumerate(p.ravel()):  # one pressure at a time: a large cell has a million rings
        s = pk * w / E_star
        out[k] = np.sum((gamma * exp1(s**2) / 2 + 3 * (1 - gamma) * _erf_part(s)) * factor)
    return out.reshape(p.shape)
