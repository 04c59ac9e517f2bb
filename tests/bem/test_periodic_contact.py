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


# -- full contact of any periodic surface -------------------------------------------------------

def _smooth_surface(cell, seed=3, modes=3):
    """A seeded smooth periodic gap: a few Fourier modes of the cell, as a callable h(x, y) and its modes."""
    rng = np.random.default_rng(seed)
    lx, ly = cell.size
    m, n = np.meshgrid(np.arange(-modes, modes + 1), np.arange(-modes, modes + 1))
    keep = (m > 0) | ((m == 0) & (n > 0))  # one of each pair +-G
    gx, gy = 2 * math.pi * m[keep] / lx, 2 * math.pi * n[keep] / ly
    amp = 0.01 * rng.standard_normal(gx.size) / (1 + np.hypot(m[keep], n[keep]))
    phase = rng.uniform(0, 2 * math.pi, gx.size)

    def gap(x, y):
        x, y = np.asarray(x)[..., None], np.asarray(y)[..., None]
        return 0.05 + np.sum(amp * np.cos(gx * x + gy * y + phase), axis=-1)

    return gap, (gx, gy, amp, phase)


def _full_contact_pressure(x, y, modes, pbar, lam):
    """p = pbar - sum h_G cos(...) / (2 / (E* |G|) + lam), by the FFT of the gap (written here)."""
    gx, gy, amp, phase = modes
    k = np.hypot(gx, gy)
    return pbar - np.sum(amp / (2 / (E_STAR * k) + lam) * np.cos(gx * x[..., None] + gy * y[..., None] + phase),
                         axis=-1)


@pytest.mark.parametrize("lam", [0.0, 0.02])
def test_full_contact_of_a_smooth_surface_matches_the_continuum_at_second_order(lam):
    errors, sizes = [], [16, 32, 64]
    for n in sizes:
        cell = PeriodicCell(1.0 / n, n, n)
        gap, modes = _smooth_surface(cell)
        gx, gy, amp, _ = modes
        pbar = 1.5 * E_STAR / 2 * np.sum(np.abs(amp) * np.hypot(gx, gy))  # above the largest pressure swing
        res = solve_periodic(gap, cell=cell, E_star=E_STAR, mean_pressure=pbar,
                             layer=layers.Linear(lam) if lam else None)
        assert res.converged and res.kkt_residual <= 1e-10 and res.contact_fraction == 1.0
        exact = _full_contact_pressure(res.x, res.y, modes, pbar, lam)
        errors.append(np.abs(res.p - exact).max() / np.abs(exact - pbar).max())
    # measured, max nodal error over the pressure swing: smooth 1.0e-1, 2.6e-2, 6.9e-3 (order 1.94);
    # lam = 0.02: 8.0e-2, 2.1e-2, 5.5e-3 (1.93). The pyramid basis converges to the continuum at order 2.
    assert _order(errors, sizes) >= 1.9
    assert errors[-1] < 8e-3


# -- every method, every layer law: the KKT conditions on the dense periodic matrix ---------------

CELL = PeriodicCell(1.0 / 32, 32, 32)
GAP, _ = _smooth_surface(CELL, seed=5)
PBAR = 0.05
C_NN = bem.diagonal_coefficient(CELL.step, E_STAR)


def _laws(lam):
    p0 = 0.2
    return {"linear": layers.Linear(lam), "root": layers.Root(lam * math.sqrt(p0)),
            "power_2": layers.Power(lam / p0, 2.0), "elastic_rigid": layers.ElasticRigid(lam, 0.5 * p0),
            "bilinear": layers.Bilinear(lam, 0.3 * lam, 0.5 * p0),
            "tabulated": layers.Tabulated(np.linspace(0, 1, 11), lam * np.linspace(0, 1, 11) ** 1.5),
            "series": layers.Series(layers.Linear(0.5 * lam), layers.Root(0.5 * lam * math.sqrt(p0)))}


def _assert_kkt(res, layer, rtol=1e-10):
    dense = PeriodicOperator(CELL, E_STAR).dense()  # by offsets from the kernel, not the FFT product
    closure = np.zeros_like(res.p) if layer is None else layer.w(res.p)
    u = dense @ res.p
    g = u + closure + GAP(res.x, res.y) - res.approach
    scale = np.abs(u + closure).max()
    assert res.converged, res.message
    assert res.p.min() >= 0
    assert np.abs(g[res.p > 0]).max() <= rtol * scale
    assert g[res.p == 0].min(initial=0.0) >= -rtol * scale
    assert res.mean_pressure == pytest.approx(PBAR, rel=1e-10)


INFINITE_SLOPE = ("root", "series")  # w'(0) = inf: the augmented gap map does not contract at the contact edge


@pytest.mark.parametrize("method, law", [(m, law) for m in ("newton", "augmented_gap", "variable_compliance")
                                         for law in _laws(1.0) if m != "augmented_gap" or law not in INFINITE_SLOPE])
def test_every_method_and_layer_meets_the_kkt_conditions_on_the_periodic_cell(method, law):
    lam = (0.3 if method == "augmented_gap" else 3.0) * C_NN  # augmented gap: a layer stiffer than C_nn
    layer = _laws(lam)[law]
    kw = {"relaxation": 0.5} if method == "augmented_gap" else {}
    res = solve_periodic(GAP, cell=CELL, E_star=E_STAR, mean_pressure=PBAR, layer=layer, method=method, **kw)
    assert 0.05 < res.contact_fraction < 0.95  # a partial contact
    _assert_kkt(res, layer)


@pytest.mark.parametrize("law", INFINITE_SLOPE)
def test_augmented_gap_reports_its_stall_for_an_infinite_slope_at_zero(law, caplog):
    """A rough contact has many edge nodes of tiny pressure where w' -> inf (fixed_point docstring):
    the augmented gap stalls there and says so (Newton and variable compliance converge above)."""
    layer = _laws(0.3 * C_NN)[law]
    res = solve_periodic(GAP, cell=CELL, E_star=E_STAR, mean_pressure=PBAR, layer=layer, method="augmented_gap",
                         relaxation=0.5)
    assert not res.converged and ("stalled" in res.message or "diverg" in res.message)
    assert np.all(np.isfinite(res.p)) and res.kkt_residual > 1e-10


def test_kalker_qp_meets_the_kkt_conditions_with_and_without_a_linear_layer():
    for layer in (None, layers.Linear(2 * C_NN)):
        res = solve_periodic(GAP, cell=CELL, E_star=E_STAR, mean_pressure=PBAR, layer=layer, method="kalker")
        _assert_kkt(res, layer)


def test_approach_control_gives_the_force_control_solution():
    by_force = solve_periodic(GAP, cell=CELL, E_star=E_STAR, mean_pressure=PBAR)
    by_approach = solve_periodic(GAP, cell=CELL, E_star=E_STAR, approach=by_force.approach)
    assert by_approach.converged
    assert by_approach.mean_pressure == pytest.approx(PBAR, rel=1e-8)
    assert by_approach.mean_gap == pytest.approx(by_force.mean_gap, rel=1e-8)
    assert by_force.mean_gap == pytest.approx(float(np.mean(GAP(CELL.x, CELL.y))) - by_force.approach, rel=1e-12)


def test_a_gap_array_and_a_callable_give_one_answer():
    from_callable = solve_periodic(GAP, cell=CELL, E_star=E_STAR, mean_pressure=PBAR)
    from_array = solve_periodic(GAP(CELL.x, CELL.y), step=CELL.step, E_star=E_STAR, mean_pressure=PBAR)
    np.testing.assert_allclose(from_array.p, from_callable.p, rtol=0, atol=1e-9 * from_callable.p_max)
