"""Periodic contact (bem.solve_periodic): Westergaard, full contact of any surface, every method, an independent solver."""

import math

import numpy as np
import pytest
from scipy import integrate

import bem
from bem import layers
from bem.periodic import PeriodicCell, PeriodicOperator, solve_periodic
from bem.reference import westergaard

LAM, DELTA, E_STAR = 1.0, 0.01, 1.0
P_WFC = math.pi * E_STAR * DELTA / LAM


def _wavy(x, y):
    return DELTA * (1 - np.cos(2 * math.pi * x / LAM))


def _order(errors, sizes):
    """Least-squares slope of -log(error) against log(size)."""
    return float(-np.polyfit(np.log(sizes), np.log(errors), 1)[0])


# -- Westergaard --------------------------------------------------------------------------------

@pytest.mark.parametrize("ratio", [0.1, 0.5, 0.9, 1.5])
def test_westergaard_closed_form_carries_the_mean_pressure_and_closes_the_gap(ratio):
    """Quadrature: the mean of p(x) is pbar, and the periodic plane-strain displacement
    u(x) = -(2 / (pi E*)) int p(s) ln|sin(pi (x - s) / lambda)| ds closes the gap, u + h = const,
    in the contact and leaves it open outside."""
    ref = westergaard(DELTA, LAM, E_STAR, ratio * P_WFC)
    a = ref.contact_half_width
    mean = integrate.quad(ref.pressure, -a, a, epsabs=0, epsrel=1e-12)[0] / LAM
    assert mean == pytest.approx(ref.mean_pressure, rel=1e-9)

    def u(x):
        def f(s):
            return ref.pressure(s) * np.log(abs(math.sin(math.pi * (x - s) / LAM)))
        return -2 / (math.pi * E_STAR) * integrate.quad(f, -a, a, points=[x] if abs(x) < a else None,
                                                       epsabs=1e-15, epsrel=1e-11, limit=200)[0]

    inside = [u(x) + _wavy(x, 0.0) for x in np.linspace(-0.9 * a, 0.9 * a, 5)]
    assert np.ptp(inside) <= 1e-7 * DELTA
    if ratio < 1:
        outside = [u(x) + _wavy(x, 0.0) for x in np.linspace(a + 0.05 * (LAM / 2 - a), LAM / 2, 4)]
        assert min(outside) > np.mean(inside)


def _westergaard_errors(ratio, n):
    ref = westergaard(DELTA, LAM, E_STAR, ratio * P_WFC)
    res = solve_periodic(_wavy, cell=PeriodicCell(LAM / n, n, 2), E_star=E_STAR, mean_pressure=ref.mean_pressure)
    assert res.converged and res.kkt_residual <= 1e-10
    x = np.where(res.x > LAM / 2, res.x - LAM, res.x)
    return {"p_max": abs(res.p_max / ref.p_max - 1),
            "a": abs(res.contact_fraction / ref.contact_fraction - 1),
            "l2": math.sqrt(np.mean((res.p - ref.pressure(x)) ** 2)) / ref.mean_pressure}


# measured orders (least squares over 64 .. 512 nodes per wavelength) at pbar / p_wfc = 0.1 / 0.5 / 0.9:
# p_max 1.93 / 2.00 / 2.00; contact half-width (from the contact fraction) 1.23 / 1.00 / 1.23, the
# edge resolved to a node; L2 pressure error 1.43 / 0.97 / 0.46, limited by the square-root edge
# (0.83 on 64 .. 1024 at 0.9). At 512: p_max 2.1e-5 / 6.3e-6 / 4.8e-6, a 3.6e-3 / 2.0e-3 / 9.2e-4,
# L2 2.2e-3 / 6.8e-4 / 2.1e-4.
@pytest.mark.parametrize("ratio, p_max_order, a_order, l2_order",
                         [(0.1, 1.8, 0.9, 1.3), (0.5, 1.9, 0.9, 0.9), (0.9, 1.9, 0.9, 0.4)])
def test_westergaard_partial_contact_converges_with_measured_orders(ratio, p_max_order, a_order, l2_order):
    sizes = [64, 128, 256, 512]
    errs = [_westergaard_errors(ratio, n) for n in sizes]
    assert _order([e["p_max"] for e in errs], sizes) >= p_max_order
    assert _order([e["a"] for e in errs], sizes) >= a_order
    assert _order([e["l2"] for e in errs], sizes) >= l2_order
    assert errs[-1]["p_max"] < 3e-5 and errs[-1]["a"] < 4e-3 and errs[-1]["l2"] < 3e-3


def test_westergaard_full_contact_is_second_order():
    sizes = [64, 128, 256]
    errs = [_westergaard_errors(1.5, n) for n in sizes]
    assert all(e["a"] == 0 for e in errs)  # every node in contact
    assert _order([e["p_max"] for e in errs], sizes) >= 1.95  # measured 1.99
    assert _order([e["l2"] for e in errs], sizes) >= 1.95  # measured 1.99
    assert errs[-1]["l2"] < 2e-5  # measured 1.8e-5
