"""Influence coefficients of coated bodies (bem.coated_kernel) against independent integrals.

The references: the pyramid's coefficients as a 2-D Fourier integral of ``2 s(q) / q`` times the
element's transform (polar grid, written here), and the surface under a uniform disc as a Hankel
integral (``scipy.integrate.quad``, the homogeneous part in closed form); neither uses the
module's split, its tabulated remainder or its large-``r`` series.
"""

import math

import numpy as np
import pytest

from bem.coated_kernel import coated_table, point_kernel
from bem.coating import Bodies, Coating, mode_compliance
from bem.kalker import solve_qp
from bem.lattice import Lattice
from bem.operator import InfluenceOperator
from bem.periodic.kernel import pyramid_transform
from bem.reference import hertz_sphere
from bem.template import template

SQ3 = math.sqrt(3.0)


def homogeneous_table(step, shape, s):
    n = np.arange(shape[0])[:, None]
    t = np.arange(shape[1] + 1)[None, :]
    return template((2 * t + n % 2) / 2.0, n * SQ3 / 2) * step * s / math.pi


def fourier_entry(bodies, tau, x, y, s_ref):
    """``(1/4 pi^2) int 2 (s(q) - s_ref) / q * pyr^(k) cos(k.x) d^2k`` on a polar grid (step 1)."""
    q_max = 25.0 / tau  # s - s_ref falls like (q t)^2 e^(-2 q t)
    g, w = np.polynomial.legendre.leggauss(16)
    edges = np.linspace(0.0, q_max, int(q_max / 0.25) + 1)
    h = np.diff(edges)[:, None] / 2
    q, wq = ((edges[:-1, None] + h) + h * g).ravel(), (h * w).ravel()
    n_theta = 2048  # a half circle: the integrand is even in k
    theta = np.pi * np.arange(n_theta) / n_theta
    s = bodies.compliance(q) - s_ref
    total = 0.0
    for i in range(0, q.size, 256):
        kx, ky = q[i:i + 256, None] * np.cos(theta), q[i:i + 256, None] * np.sin(theta)
        ring = (pyramid_transform(kx, ky) * np.cos(kx * x + ky * y)).sum(axis=1) * (2 * np.pi / n_theta)
        total += np.sum(2 * s[i:i + 256] * ring * wq[i:i + 256])
    return total / (4 * np.pi ** 2)


CASES = [(10.0, 1.0), (10.0, 0.3), (0.1, 1.0), (math.inf, 0.5)]  # (E_substrate, t / c)


@pytest.mark.parametrize("E_s, tau", CASES)
def test_pyramid_coefficients_match_a_fourier_integral(E_s, tau):
    coating = Coating(tau, 1.0, 0.3)
    E2 = 100.0 if E_s == math.inf else math.inf  # a rigid substrate needs an elastic counter-body
    bodies = Bodies(E_s, 0.3, E2, 0.3, coating)
    table = coated_table(1.0, (6, 6), bodies)
    s_c = (1 - 0.3 ** 2) / 1.0 + (1 - 0.3 ** 2) / E2
    worst = 0.0
    for n, t in ((0, 0), (0, 1), (1, 0), (1, 1), (2, 1), (4, 3)):
        x, y = (2 * t + n % 2) / 2, n * SQ3 / 2
        ref = fourier_entry(bodies, tau, x, y, s_c) + s_c / math.pi * float(template(x, y))
        worst = max(worst, abs(table[n, t] - ref) / table[0, 0])
    assert worst <= 1e-10, worst


def hankel_disc(bodies, a, r, s_ref, q_max):
    """Surface closure at ``r`` under a unit pressure on the disc of radius ``a`` (``r < a``)."""
    from scipy.integrate import quad
    from scipy.special import ellipe, j0, j1

    def f(q):
        return 2 * (float(bodies.compliance(q)) - s_ref) * a * j1(q * a) * j0(q * r) / q

    edges = np.linspace(1e-300, q_max, max(400, int(q_max * (a + r))))  # a few oscillations a piece
    rest = sum(quad(f, lo, hi, epsabs=1e-14 * s_ref * a / edges.size, epsrel=1e-12, limit=200)[0]
               for lo, hi in zip(edges[:-1], edges[1:]))
    return 4 * s_ref * a / math.pi * ellipe((r / a) ** 2) + rest


def kernel_disc(bodies, a, r, grade):
    """The same by the point kernel of bem.coated_kernel, in polar coordinates about the point."""
    n_theta = 256
    theta = 2 * np.pi * (np.arange(n_theta) + 0.5) / n_theta
    rho_max = -r * np.cos(theta) + np.sqrt(a * a - (r * np.sin(theta)) ** 2)
    edges = [0.0]
    while edges[-1] < 1.0:
        edges.append(min(1.0, max(grade, 2 * edges[-1])))
    g, w = np.polynomial.legendre.leggauss(20)
    lo, hi = np.array(edges[:-1])[:, None], np.array(edges[1:])[:, None]
    s, ws = (lo + (hi - lo) * (g + 1) / 2).ravel(), ((hi - lo) * w / 2).ravel()
    rho = rho_max[:, None] * s[None, :]
    inner = (point_kernel(rho, bodies) * rho) @ ws * rho_max
    return inner.sum() * 2 * np.pi / n_theta


@pytest.mark.parametrize("E_s, t", [(10.0, 1.0), (10.0, 0.05), (0.1, 2.0), (math.inf, 0.5)])
def test_disc_displacement_matches_a_hankel_integral(E_s, t):
    E2 = 100.0 if E_s == math.inf else math.inf  # a rigid substrate needs an elastic counter-body
    bodies = Bodies(E_s, 0.3, E2, 0.3, Coating(t, 1.0, 0.3))
    s_c = 1 - 0.3 ** 2 + (1 - 0.3 ** 2) / E2
    a = 2.0
    for r in (0.0, 0.5 * a):
        ref = hankel_disc(bodies, a, r, s_c, 60.0 / t)
        got = kernel_disc(bodies, a, r, t / 8)
        assert abs(got - ref) <= 1e-8 * abs(ref), (r, got, ref)


def test_equal_materials_give_the_homogeneous_table():
    bodies = Bodies(2.0, 0.25, 3.0, 0.3, Coating(0.7, 2.0, 0.25))
    s = (1 - 0.25 ** 2) / 2.0 + (1 - 0.3 ** 2) / 3.0
    table = coated_table(0.5, (9, 7), bodies)
    ref = homogeneous_table(0.5, (9, 7), s)
    assert np.max(np.abs(table - ref)) <= 1e-14 * ref[0, 0]


def test_thin_and_thick_coatings_reach_the_limits():
    shape, s_c, s_s = (12, 12), 1 - 0.3 ** 2, (1 - 0.25 ** 2) / 10.0
    thin = coated_table(1.0, shape, Bodies(10.0, 0.25, math.inf, 0.3, Coating(1e-7, 1.0, 0.3)))
    ref = homogeneous_table(1.0, shape, s_s)
    assert np.max(np.abs(thin - ref)) <= 1e-6 * ref[0, 0]
    thick = coated_table(1.0, shape, Bodies(10.0, 0.25, math.inf, 0.3, Coating(1e7, 1.0, 0.3)))  # 1e6 regions
    ref = homogeneous_table(1.0, shape, s_c)
    assert np.all(np.isfinite(thick))
    assert np.max(np.abs(thick - ref)) <= 1e-6 * ref[0, 0]


def test_thin_coating_is_the_substrate_plus_a_local_compliance():
    """Thin coatings: the substrate's table plus ``2 s'(0)`` on the diagonal, the rest of order ``(t/c)^2``."""
    shape, s_s = (8, 8), (1 - 0.25 ** 2) / 10.0
    ref = homogeneous_table(1.0, shape, s_s)
    misses = []
    for t in (2e-3, 1e-3):
        coating = Coating(t, 1.0, 0.3)
        table = coated_table(1.0, shape, Bodies(10.0, 0.25, math.inf, 0.3, coating))
        dq = 1e-2
        s = [float(mode_compliance(k * dq, 10.0, 0.25, coating)) for k in range(3)]
        local = ref.copy()
        local[0, 0] += 2 * (-3 * s[0] + 4 * s[1] - s[2]) / (2 * dq)  # 2 s'(0), error O(dq^2 t^3)
        assert np.max(np.abs(table - ref)) > 1e-4 * ref[0, 0]  # the coating is seen
        misses.append(np.max(np.abs(table - local)) / ref[0, 0])
    assert misses[1] <= 1e-5  # measured 5.3e-6 at t = 1e-3 c
    assert 3.5 <= misses[0] / misses[1] <= 4.5  # order 2 in t


def _hertz(bodies, E_star, extent=12.0, step=1.0, R=100.0, force=2.0):
    lat = Lattice.from_extent(step, extent)
    op = InfluenceOperator(lat, E_star, bodies=bodies)
    h = (lat.x ** 2 + lat.y ** 2) / (2 * R)
    sol = solve_qp(op, h, force=force, rtol=1e-11, preconditioner=op.preconditioner())
    return lat, sol


def test_coated_sphere_contact_converges_and_meets_its_limits():
    E_s, nu_s, E_c, nu_c = 10.0, 0.25, 1.0, 0.3
    soft = (1 - nu_c ** 2) / E_c
    thick = Bodies(E_s, nu_s, math.inf, 0.3, Coating(1e6, E_c, nu_c))
    lat, sol = _hertz(thick, thick.E_star)
    assert sol.converged and sol.kkt_residual <= 1e-10
    _, ref = soft_ref = _hertz(None, 1 / soft)
    assert abs(sol.approach / ref.approach - 1) <= 1e-5
    assert np.max(np.abs(sol.p - ref.p)) <= 1e-5 * np.max(ref.p)
    hertz = hertz_sphere(100.0, 1 / soft, force=2.0)
    assert abs(np.max(sol.p) / hertz.p_max - 1) <= 0.05
    thin = Bodies(E_s, nu_s, math.inf, 0.3, Coating(1e-6, E_c, nu_c))
    _, sol = _hertz(thin, thin.E_star)
    assert sol.converged and sol.kkt_residual <= 1e-10
    _, ref = _hertz(None, thin.E_star)
    assert abs(sol.approach / ref.approach - 1) <= 1e-5
    mid = Bodies(E_s, nu_s, math.inf, 0.3, Coating(1.5, E_c, nu_c))
    _, sol = _hertz(mid, mid.E_star)
    assert sol.converged and sol.kkt_residual <= 1e-10
    assert ref.approach < sol.approach < soft_ref[1].approach  # between the substrate and the coating


def test_operator_with_coated_bodies_applies_its_table():
    bodies = Bodies(10.0, 0.25, math.inf, 0.3, Coating(0.8, 1.0, 0.3))
    lat = Lattice.from_extent(1.0, 6.0)
    op = InfluenceOperator(lat, bodies.E_star, bodies=bodies)
    assert op.diagonal == coated_table(1.0, lat.shape, bodies)[0, 0]
    p = np.where(lat.mask, np.random.default_rng(3).random(lat.shape), 0.0)
    dense = op.dense()
    assert np.max(np.abs(op.matvec(p)[lat.mask] - dense @ p[lat.mask])) <= 1e-13 * np.max(np.abs(dense @ p[lat.mask]))
    x, y = lat.x[lat.mask], lat.y[lat.mask]  # one entry against the Fourier integral
    i, j = 0, int(np.argmin(np.hypot(x - x[0] - 2.0, y - y[0])))
    ref = fourier_entry(bodies, 0.8, x[j] - x[i], y[j] - y[i], 1 - 0.3 ** 2) + (1 - 0.3 ** 2) / math.pi * float(
        template(x[j] - x[i], y[j] - y[i]))
    assert abs(dense[i, j] - ref) <= 1e-10 * op.diagonal
    assert InfluenceOperator(lat, bodies.E_star, bodies=Bodies(10.0, 0.25, math.inf, 0.3)).diagonal == pytest.approx(
        InfluenceOperator(lat, bodies.E_star).diagonal, rel=1e-15)


def test_point_kernel_matches_a_hankel_integral_near_and_far():
    """``(1/pi) int (s(q) - s_c) J0(q r) dq`` by quad between the zeros of ``J0`` (the table's ``G``)."""
    from scipy.integrate import quad
    from scipy.special import j0, jn_zeros

    t = 0.7
    bodies = Bodies(10.0, 0.25, math.inf, 0.3, Coating(t, 1.0, 0.3))
    s_c = 1 - 0.3 ** 2
    for r in (0.07, 0.7, 7.0, 70.0, 700.0):
        q_max = 25.0 / t
        zeros = jn_zeros(0, int(q_max * r / math.pi) + 2) / r
        edges = np.concatenate([[0.0], zeros[zeros < q_max], [q_max]]) if r > 1 else np.linspace(0, q_max, 200)
        ref = sum(quad(lambda q: (float(bodies.compliance(q)) - s_c) * j0(q * r), a, b, epsabs=1e-16, epsrel=1e-12, limit=200)[0]
                  for a, b in zip(edges[:-1], edges[1:])) / math.pi
        got = float(point_kernel(np.array([r]), bodies)[0]) - s_c / (math.pi * r)
        assert abs(got - ref) <= 1e-10 * s_c / t, (r, got, ref)


def test_far_coefficients_match_a_fine_element_rule():
    """Offsets beyond 8 steps (box-spline rules): the element integral of ``G`` by 16 x 16 Gauss points
    on each of the six triangles, ``G = pi K - s_c / r`` from :func:`point_kernel`."""
    bodies = Bodies(10.0, 0.25, math.inf, 0.3, Coating(0.7, 1.0, 0.3))
    s_c = 1 - 0.3 ** 2
    table = coated_table(1.0, (300, 300), bodies)
    g, w = np.polynomial.legendre.leggauss(16)
    g, w = (g + 1) / 2, w / 2
    s, u = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    ws = np.outer(w, w).ravel() * s * (1 - s) * SQ3 / 2
    hexv = [np.array([math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)]) for k in range(7)]
    pts = np.concatenate([s[:, None] * ((1 - u)[:, None] * hexv[k] + u[:, None] * hexv[k + 1]) for k in range(6)])
    wts = np.tile(ws, 6)
    for n, col in ((10, 3), (12, 20), (50, 30), (290, 150)):
        x, y = (2 * col + n % 2) / 2, n * SQ3 / 2
        r = np.hypot(x - pts[:, 0], y - pts[:, 1])
        G = math.pi * point_kernel(r, bodies) - s_c / r
        ref = s_c / math.pi * float(template(x, y)) + wts @ G / math.pi
        assert abs(table[n, col] - ref) <= 1e-11 * table[0, 0], (n, col)


def test_bad_input_is_refused():
    from bem.errors import InputError

    bodies = Bodies(10.0, 0.25, math.inf, 0.3, Coating(0.7, 1.0, 0.3))
    with pytest.raises(InputError, match="bodies"):
        coated_table(1.0, (4, 4), (10.0, 0.25))
    with pytest.raises(InputError, match="shape"):
        coated_table(1.0, (0, 4), bodies)
    with pytest.raises(InputError, match="step"):
        coated_table(-1.0, (4, 4), bodies)
    with pytest.raises(InputError, match="bodies"):
        point_kernel([1.0], "steel")


@pytest.mark.parametrize("E_s", [10.0, 0.1, 0.01, math.inf])
def test_factor_taylor_sums_to_the_factor_inside_its_radius(E_s):
    from bem.coating import coating_factor, factor_taylor

    coating = Coating(1.0, 1.0, 0.3)
    coeffs, radius = factor_taylor(coating, E_s, 0.3, order=40)
    x = np.array([0.0, 0.1, 0.3, 0.5]) * radius
    phi = coating_factor(x, coating, E_s, 0.3)
    assert np.max(np.abs(np.polyval(coeffs[::-1], x) - phi)) <= 1e-12 * np.max(np.abs(phi))
