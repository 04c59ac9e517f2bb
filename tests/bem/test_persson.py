"""Persson's theory from a PSD (bem.rough.persson): the spectral moments of a cell and of a sampled power law
against their closed forms, the contact fraction's small-pressure limit, the mean gap against an independent
quadrature of its integral, and its exponential regime at small pressures."""

import math

import numpy as np
import pytest
from scipy import integrate, special

from bem import InputError
from bem.rough import persson

H, Q0, Q1, C0 = 0.8, 2 * math.pi * 4, 2 * math.pi * 32, 1e-6  # power law C = C0 q^(-2-2H) on [Q0, Q1]


def _power_law_inner(q):
    """``int_{Q0}^{q} q'^3 C(q') dq'`` of the power law, closed form."""
    return C0 * (q ** (2 - 2 * H) - Q0 ** (2 - 2 * H)) / (2 - 2 * H)


def _power_law_spectrum(n=20001):
    q = np.geomspace(Q0, Q1, n)
    return persson.psd_spectrum(q, C0 * q ** (-2 - 2 * H))


def _cell(seed=0, n=128):
    """Seeded normal heights with a smooth spectrum on a 1 x 0.5 periodic cell."""
    from scipy import ndimage

    z = ndimage.gaussian_filter(np.random.default_rng(seed).standard_normal((n, n // 2)), 3.0, mode="wrap")
    return z, (1.0, 0.5)


def test_cell_spectrum_moments_are_the_cells_rms_height_and_slope():
    z, (lx, ly) = _cell()
    spectrum = persson.cell_spectrum(z, (lx, ly))
    nx, ny = z.shape
    kx = 2 * np.pi * np.fft.fftfreq(nx, lx / nx)[:, None]
    ky = 2 * np.pi * np.fft.fftfreq(ny, ly / ny)[None, :]
    f = np.fft.fft2(z)
    slope2 = np.mean(np.abs(np.fft.ifft2(1j * kx * f)) ** 2 + np.abs(np.fft.ifft2(1j * ky * f)) ** 2)
    assert spectrum.moment(0) == pytest.approx(np.var(z), rel=1e-12)  # Parseval
    assert spectrum.moment(2) == pytest.approx(slope2, rel=1e-12)  # the spectral derivative
    assert np.all(np.diff(spectrum.q) > 0)  # rings of equal |k| merged


def test_sampled_power_law_moment_against_its_closed_form():
    assert _power_law_spectrum().moment(2) == pytest.approx(2 * math.pi * _power_law_inner(Q1), rel=1e-7)


def test_contact_fraction_small_pressure_limit_and_full_contact():
    spectrum = _power_law_spectrum()
    slope, E = spectrum.rms_slope, 2.0
    p = np.array([1e-6, 1e-4]) * E * slope
    kappa = persson.contact_fraction(p, E, spectrum) / (p / (E * slope))
    assert kappa == pytest.approx(math.sqrt(8 / math.pi), rel=1e-6)  # A/A0 -> sqrt(8/pi) p/(E* h'_rms)
    # erf(sqrt(2) p/(E* h'_rms)) at p = E* h'_rms/sqrt(2): erf(1)
    assert persson.contact_fraction(E * slope / math.sqrt(2), E, spectrum) == pytest.approx(math.erf(1.0), rel=1e-12)
    assert persson.contact_fraction(10 * E * slope, E, spectrum) == pytest.approx(1.0, abs=1e-12)


def _independent_mean_gap(p, E, gamma):
    """``sqrt(pi) int q^2 C w I(w p/E) dq`` for the power law, by adaptive quadrature (scipy.integrate.quad)."""
    def inner(s):
        erf_part = integrate.quad(lambda x: special.erf(x) ** 2 * math.exp(-x * x) / x, s, np.inf)[0]
        return gamma * special.exp1(s * s) / 2 + 3 * (1 - gamma) * erf_part

    a, b = 2 - 2 * H, Q0 ** (2 - 2 * H)

    def outer(t):  # t = sqrt(q^(2-2H) - Q0^(2-2H)) takes out the singularity w ~ (q - Q0)^(-1/2)
        q = (t * t + b) ** (1 / a)
        w = (math.pi * C0 * t * t / a) ** -0.5
        dq_dt = 2 * t / (a * q ** (1 - 2 * H))
        return q**2 * C0 * q ** (-2 - 2 * H) * w * inner(w * p / E) * dq_dt

    return math.sqrt(math.pi) * integrate.quad(outer, 0.0, math.sqrt(Q1**a - b), limit=200, epsrel=1e-10)[0]


@pytest.mark.parametrize("gamma", [1.0, 0.0, persson.GAMMA])
def test_mean_gap_against_an_independent_quadrature(gamma):
    spectrum, E = _power_law_spectrum(), 1.0
    # the trapezoidal rule meets w's (q - Q0)^(-1/2) at Q0, which only small pressures feel (measured 8e-5 for
    # gamma = 1, 3.7e-4 for gamma = 0 at 1e-3, 3e-7 at 0.1 and 1)
    for rel, tol in ((1e-3, 1e-3), (0.1, 2e-6), (1.0, 2e-6)):
        p = rel * E * spectrum.rms_slope
        got = float(persson.mean_gap(p, E, spectrum, gamma=gamma))
        assert got == pytest.approx(_independent_mean_gap(p, E, gamma), rel=tol)


def test_mean_gap_exponential_regime_at_small_pressures():
    z, size = _cell(seed=1)
    spectrum, E = persson.cell_spectrum(z, size), 1.0
    p = 1e-9 * E * spectrum.rms_slope
    u = persson.mean_gap(np.array([p, 2 * p]), E, spectrum)
    w = spectrum.w()
    slope = -persson.GAMMA * math.sqrt(math.pi) * np.sum(spectrum.q**2 * spectrum.weight * w)
    assert (u[1] - u[0]) / math.log(2) == pytest.approx(slope, rel=1e-6)
    assert np.all(np.diff(persson.mean_gap(np.geomspace(p, E, 20), E, spectrum)) < 0)  # closes as p grows


def test_bad_arguments_are_named():
    spectrum = _power_law_spectrum(101)
    with pytest.raises(InputError, match="pressure = 0.0"):
        persson.mean_gap(0.0, 1.0, spectrum)
    with pytest.raises(InputError, match="E_star = -1"):
        persson.contact_fraction(1.0, -1, spectrum)
    with pytest.raises(InputError, match="gamma = 2"):
        persson.mean_gap(1.0, 1.0, spectrum, gamma=2)
    with pytest.raises(InputError, match="q = "):
        persson.psd_spectrum([2.0, 1.0], [1.0, 1.0])
