"""Periodic contact (bem.solve_periodic): Westergaard, full contact of any surface, every method, an
independent solver."""

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
            "series": layers.Series(layers.Linear(0.5 * lam), layers.Root(0.5 * lam * math.sqrt(p0))),
            "custom": layers.Custom(lambda p: lam * p * (1 + p / p0), p_scale=p0)}


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
    assert not res.converged and res.status in ("stalled", "diverged")
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


@pytest.mark.parametrize("shape", ["brick", "nodes"])
@pytest.mark.parametrize("method", ["kalker", "newton"])
def test_a_callers_start_and_gap_are_not_modified(shape, method):
    """The cell's QP and Newton hold their iterate in the start they are given (``overwrite_x0``): that is a
    copy of the caller's ``x0``, which keeps its values, as does the gap array."""
    h = GAP(CELL.x, CELL.y)
    layer = layers.Root(0.3 * bem.diagonal_coefficient(CELL.step, E_STAR)) if method == "newton" else None
    kw = dict(step=CELL.step, E_star=E_STAR, mean_pressure=PBAR, method=method, layer=layer)
    first = solve_periodic(h, rtol=1e-3, **kw)
    x0 = first.p.reshape(CELL.shape) if shape == "brick" else first.p.copy()
    x0_before, h_before = x0.copy(), h.copy()
    res = solve_periodic(h, x0=x0, **kw)
    assert res.converged
    np.testing.assert_array_equal(x0, x0_before)
    np.testing.assert_array_equal(h, h_before)
    assert not np.shares_memory(res.p, x0)


def test_a_gap_array_and_a_callable_give_one_answer():
    from_callable = solve_periodic(GAP, cell=CELL, E_star=E_STAR, mean_pressure=PBAR)
    from_array = solve_periodic(GAP(CELL.x, CELL.y), step=CELL.step, E_star=E_STAR, mean_pressure=PBAR)
    np.testing.assert_allclose(from_array.p, from_callable.p, rtol=0, atol=1e-9 * from_callable.p_max)


# -- an independent periodic solver --------------------------------------------------------------

def _plain_pk(h, size, pbar, rtol=1e-10, maxiter=5000):
    """Polonsky & Keer's CG, periodic, on a square-indexed grid with the point-sampled kernel 2 / (E* |q|).

    Returns the mean gap and the contact fraction. Written independently of bem.
    """
    n0, n1 = h.shape
    qy = 2 * math.pi * np.fft.fftfreq(n0, size[1] / n0)[:, None]
    qx = 2 * math.pi * np.fft.rfftfreq(n1, size[0] / n1)[None, :]
    q = np.hypot(qx, qy)
    kernel = np.where(q > 0, 2 / (E_STAR * np.where(q > 0, q, 1.0)), 0.0)

    def conv(v):
        return np.fft.irfft2(kernel * np.fft.rfft2(v), s=h.shape)

    p = np.full(h.shape, pbar)
    t = np.zeros(h.shape)
    g_old, restart = 1.0, True
    for _ in range(maxiter):
        u = conv(p)
        s = p > 0
        g = u + h
        delta = g[s].mean()
        g -= delta
        if max(np.abs(g[s]).max(), -g[~s].min(initial=0.0)) <= rtol * np.abs(u).max():
            return float(np.mean(h) - delta), float(s.mean())
        g_norm = float(np.sum(g[s] ** 2))
        t = np.where(s, g + (0.0 if restart else g_norm / g_old) * t, 0.0)
        g_old = g_norm
        r = conv(t)
        r -= r[s].mean()
        tau = float(np.sum(g[s] * t[s]) / np.sum(r[s] * t[s]))
        p = np.where(s, np.maximum(p - tau * t, 0.0), p)
        overlap = (p == 0) & (g < 0)
        restart = bool(overlap.any())
        p[overlap] -= tau * g[overlap]
        p *= pbar * p.size / p.sum()
    raise AssertionError("the plain Polonsky-Keer solver did not converge")


def test_an_independent_periodic_solver_agrees_within_the_discretisation_difference():
    """Square grid with the point-sampled kernel against the pyramid basis on the triangular lattice,
    both periodic over the same rectangle and the same smooth seeded surface (~30 % contact)."""
    diffs = []
    for n in (32, 64, 128):
        cell = PeriodicCell(1.0 / n, n, n)
        gap, _ = _smooth_surface(cell, seed=11, modes=4)
        ours = solve_periodic(gap, cell=cell, E_star=E_STAR, mean_pressure=0.03)
        assert ours.converged
        lx, ly = cell.size
        x, y = np.meshgrid(np.arange(n) * lx / n, np.arange(n) * ly / n)
        mean_gap, fraction = _plain_pk(gap(x, y), cell.size, 0.03)
        diffs.append((abs(ours.mean_gap / mean_gap - 1), abs(ours.contact_fraction - fraction)))
    # measured: mean gap 2.9e-2, 8.9e-3, 2.2e-3 relative (orders 1.7, 2.0); contact fraction
    # 1.8e-2, 8.8e-3, 4.8e-3 absolute at a fraction of 0.29 (orders 1.0, 0.9): both discretisations
    # converge to one answer, and the difference is the discretisation error of the coarser one
    (g32, f32), (g64, f64), (g128, f128) = diffs
    assert g128 < 4e-3 and g32 / g64 > 2.5 and g64 / g128 > 3.0
    assert f128 < 7e-3 and f32 / f64 > 1.6 and f64 / f128 > 1.5


# -- input ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("kwargs, match", [
    (dict(gap=lambda x, y: np.cos(2.5 * np.pi * x), cell=CELL, mean_pressure=0.1), "^gap = .* periodic over the cell"),
    (dict(gap=GAP, cell=CELL, approach=1.0), "^approach = 1.0 is not allowed: it must be < the mean gap"),
    (dict(gap=GAP, cell=CELL, mean_pressure=-1.0), "^mean_pressure = -1.0 is not allowed"),
    (dict(gap=GAP, cell=CELL), "^\\(mean_pressure, approach\\) = \\(None, None\\) is not allowed"),
    (dict(gap=np.zeros((5, 8)), step=0.1, mean_pressure=0.1), "^n_rows = 5 is not allowed: it must be even"),
    (dict(gap=np.zeros((4, 8)), mean_pressure=0.1), "^step = None is not allowed"),
    (dict(gap=GAP, step=0.1, mean_pressure=0.1), "^cell = None is not allowed"),
    (dict(gap=GAP, cell=CELL, mean_pressure=0.1, rtol=0.5), r"^rtol = 0.5 is not allowed: it must be in \(0, 0.01\]"),
])
def test_solve_periodic_refuses_bad_input(kwargs, match):
    with pytest.raises(bem.InputError, match=match):
        solve_periodic(E_star=E_STAR, **kwargs)
