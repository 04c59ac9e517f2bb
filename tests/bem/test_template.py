"""Tests of the closed-form pyramid template ``w_t`` (paper eq. 5, docs/method.md section 2).

References are independent of the code under test:
- near the hexagon: ``scipy.integrate.dblquad`` in polar coordinates about the
  evaluation point, each triangle split at that point (the 1/rho singularity
  cancels against the polar Jacobian), tolerances 1e-13;
- from r = 2.5 outwards: a 40 x 40 Gauss-Legendre rule on each triangle in
  collapsed (Duffy) coordinates, exact up to rounding (~4e-15) for a smooth integrand;
- exact values: ``w_t(0, 0) = (3 sqrt3/2) ln 3``, volume ``sqrt3/2``, and the
  Fourier coefficients of ``P_n`` by numerical projection.
"""

import math
import sys

import numpy as np
import pytest
from scipy.integrate import dblquad

from bem.checks import InputError
from bem.template import R_SWITCH, template

tmpl_module = sys.modules["bem.template"]

S3 = math.sqrt(3.0)
VOLUME = S3 / 2
HEX = [np.array([math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)]) for k in range(6)]
HEX[1] = np.array([0.5, S3 / 2])  # same float grid as the lattice nodes (i + j/2, j sqrt3/2)
HEX[2] = np.array([-0.5, S3 / 2])
HEX[4] = np.array([-0.5, -S3 / 2])
HEX[5] = np.array([0.5, -S3 / 2])
RTOL = 1e-11  # stricter than the 1e-10 of the specification


# ----------------------------------------------------------------------------- references
def _pyramid_on_triangle(k):
    """Linear pyramid on triangle (0, v_k, v_k+1): 1 - n.xi / apothem."""
    a, b = HEX[k], HEX[(k + 1) % 6]
    n = (a + b) / np.linalg.norm(a + b)
    return lambda px, py: 1.0 - (n[0] * px + n[1] * py) / (S3 / 2)


def _polar_piece(x0, p, q, f):
    """Signed integral of f/rho over triangle (x0, p, q), polar coordinates about x0."""
    u, v = p - x0, q - x0
    cross = u[0] * v[1] - u[1] * v[0]
    if cross == 0.0:  # x0 on the line pq (or at p or q): zero area
        return 0.0
    e = q - p
    nrm = np.array([e[1], -e[0]]) / np.linalg.norm(e)
    dist = nrm @ u
    if dist < 0:
        nrm, dist = -nrm, -dist
    phi_n = math.atan2(nrm[1], nrm[0])
    a0 = math.atan2(u[1], u[0])
    sweep = math.atan2(cross, u @ v)
    sg = math.copysign(1.0, sweep)

    def integrand(r, phi):  # f/rho * rho dr dphi
        ang = a0 + sg * phi
        return f(x0[0] + r * math.cos(ang), x0[1] + r * math.sin(ang))

    val, _ = dblquad(integrand, 0.0, abs(sweep), 0.0,
                     lambda phi: dist / math.cos(a0 + sg * phi - phi_n),
                     epsabs=1e-13, epsrel=1e-13)
    return sg * val


def polar_reference(x, y):
    x0 = np.array([x, y], dtype=float)
    o = np.zeros(2)
    total = 0.0
    for k in range(6):
        f = _pyramid_on_triangle(k)
        a, b = HEX[k], HEX[(k + 1) % 6]
        for p, q in ((o, a), (a, b), (b, o)):
            total += _polar_piece(x0, p, q, f)
    return total


def _collapsed_gauss(n=40):
    g, w = np.polynomial.legendre.leggauss(n)
    g, w = 0.5 * (g + 1), 0.5 * w
    u, v = np.meshgrid(g, g, indexing="ij")
    return u, v, np.outer(w, w)


def _hexagon_points(n=40):
    """Gauss points xi, eta, weights * pyramid over the hexagon (collapsed coordinates)."""
    u, v, w = _collapsed_gauss(n)
    xs, ys, ws = [], [], []
    for k in range(6):
        a, b = HEX[k], HEX[(k + 1) % 6]
        xs.append(u * (a[0] + v * (b[0] - a[0])))
        ys.append(u * (a[1] + v * (b[1] - a[1])))
        ws.append(w * u * abs(a[0] * b[1] - a[1] * b[0]) * (1.0 - u))  # pyramid = 1 - u
    return np.ravel(xs), np.ravel(ys), np.ravel(ws)


XI, ETA, WPYR = _hexagon_points()


def gauss_reference(x, y):
    return float(np.sum(WPYR / np.hypot(x - XI, y - ETA)))


def rel_err(a, b):
    return abs(a - b) / abs(b)


# ----------------------------------------------------------------------------- values
def test_centre_value_is_exact():
    assert template(0.0, 0.0) == pytest.approx(1.5 * S3 * math.log(3.0), rel=1e-15, abs=0)


NEAR_POINTS = [
    # lattice nodes
    (0.0, 0.0), (1.0, 0.0), (0.5, S3 / 2), (-1.0, 0.0), (-0.5, -S3 / 2), (2.0, 0.0),
    (1.5, S3 / 2), (0.0, S3), (-2.5, -S3 / 2), (3.0, 3 * S3),
    # between nodes and off the lattice
    (3.0, 1.7), (0.3, 0.2), (1.3, 0.4), (2.2, -1.1), (0.9, 2.7), (-4.1, 2.2),
    # on element edges: spokes, outer sides, and their extensions
    (0.5, 0.0), (0.25, 0.25 * S3), (-0.3, 0.0), (0.75, S3 / 4), (0.0, S3 / 2),
    (1.5, 0.0), (1.25, -S3 / 4), (-2.0, S3 / 2),
    # inside the hexagon
    (0.1, -0.7), (-0.4, 0.35), (1e-9, 2e-9),
    # just inside the switch radius
    (7.5, 2.0), (0.0, 7.9), (5.6, -5.6),
]


@pytest.mark.parametrize("pt", NEAR_POINTS)
def test_near_field_matches_polar_quadrature(pt):
    assert rel_err(template(*pt), polar_reference(*pt)) < RTOL


@pytest.mark.parametrize("radius", [2.5, 8.0 + 1e-9, 8.5, 10.0, 50.0, 300.0, 2000.0, 5000.0])
def test_far_field_matches_gauss_rule(radius):
    angles = np.array([0.0, 0.3, math.pi / 6, 1.0, 2.5, 4.0, 5.5])
    x, y = radius * np.cos(angles), radius * np.sin(angles)
    got = template(x, y)
    for xi, yi, gi in zip(x, y, got):
        assert rel_err(gi, gauss_reference(xi, yi)) < RTOL


def test_references_agree_with_each_other():
    for pt in [(2.5, 0.0), (3.0, 1.7), (-2.0, 3.1)]:
        assert rel_err(polar_reference(*pt), gauss_reference(*pt)) < 1e-12


def test_six_fold_anisotropy_is_resolved():
    # the cos(6 theta) term is ~5e-9 relative at r = 10: visible in the reference and matched
    r = 10.0
    ref = [gauss_reference(r, 0.0), gauss_reference(r * S3 / 2, r / 2)]
    got = template([r, r * S3 / 2], [0.0, r / 2])
    assert rel_err(ref[0], ref[1]) > 1e-9
    assert rel_err(got[0] - got[1], ref[0] - ref[1]) < 1e-3


def test_closed_form_and_multipole_agree_at_switch():
    rng = np.random.default_rng(3)
    theta = rng.uniform(0, 2 * np.pi, 500)
    r = R_SWITCH * rng.uniform(1.0, 1.05, 500)
    x, y = r * np.cos(theta), r * np.sin(theta)
    near = tmpl_module._near_block(x, y)
    far = tmpl_module._far(x, y, x * x + y * y)
    assert np.max(np.abs(near / far - 1)) < 3e-13


# ----------------------------------------------------------------------------- far field
def test_far_field_limit_and_rate():
    second_moment = float(np.sum(WPYR * (XI**2 + ETA**2)))  # int pyr |xi|^2
    assert float(np.sum(WPYR)) == pytest.approx(VOLUME, rel=1e-14)
    for r in (30.0, 100.0, 400.0, 3000.0):
        for theta in (0.0, 0.4, math.pi / 6):
            rw = r * template(r * math.cos(theta), r * math.sin(theta))
            assert abs(rw - VOLUME) < 0.06 / r**2  # -> sqrt3/2
            # next term: (1/4) int pyr |xi|^2 / r^2 (isotropic part of P_2)
            assert abs((rw - VOLUME) * r**2 - second_moment / 4) < 0.02 / r**2


@pytest.mark.parametrize("n, m", [(0, 0), (2, 0), (4, 0), (6, 0), (6, 1), (8, 1), (10, 1), (12, 2)])
def test_multipole_coefficients_match_numerical_moments(n, m):
    # Fourier coefficient of P_n(cos g) on cos(6 m g), by projection on an exact grid
    g = np.linspace(0, 2 * np.pi, 4 * n + 8, endpoint=False)
    pn = np.polynomial.legendre.legval(np.cos(g), [0] * n + [1])
    a = np.mean(pn * np.cos(6 * m * g)) * (1 if m == 0 else 2)
    moment = np.sum(WPYR * np.hypot(XI, ETA) ** n * np.cos(6 * m * np.arctan2(ETA, XI)))
    exact = float(tmpl_module._multipole_coefficient(n, m)) / S3
    assert exact == pytest.approx(a * moment, rel=1e-12)


# ----------------------------------------------------------------------------- structure
def test_six_fold_and_mirror_symmetry():
    rng = np.random.default_rng(7)
    r = np.concatenate([rng.uniform(0, 12, 400), rng.uniform(12, 3000, 100)])
    theta = rng.uniform(0, 2 * np.pi, r.size)
    x, y = r * np.cos(theta), r * np.sin(theta)
    w = template(x, y)
    for k in range(1, 6):
        c, s = math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)
        np.testing.assert_allclose(template(c * x - s * y, s * x + c * y), w, rtol=1e-12, atol=0)
    np.testing.assert_allclose(template(x, -y), w, rtol=1e-12, atol=0)
    np.testing.assert_allclose(template(-x, y), w, rtol=1e-12, atol=0)


def test_grid_through_vertices_and_edges_is_finite_positive_and_peaks_at_centre():
    i, j = np.meshgrid(np.arange(-48, 49), np.arange(-48, 49))
    x, y = i / 4 + j / 8, j * S3 / 8  # contains the centre, all vertices, edge points
    w = template(x, y)
    assert w.shape == x.shape
    assert np.all(np.isfinite(w))
    assert np.all(w > 0)
    assert np.max(w) == template(0.0, 0.0)


def test_decreasing_along_rays():
    # Anderson's theorem: pyramid and 1/rho are symmetric with convex level sets,
    # so w_t is non-increasing along every ray from the centre
    s = np.linspace(0.0, 20.0, 4001)
    for theta in (0.0, 0.2, math.pi / 6, math.pi / 3, 2.0):
        w = template(s * math.cos(theta), s * math.sin(theta))
        assert np.all(np.diff(w) < 0)


# ----------------------------------------------------------------------------- interface
def test_input_not_modified_and_readonly_accepted():
    x = np.array([[0.0, 1.0, 9.0], [0.5, -3.0, 100.0]])
    y = np.array([0.0, S3 / 2, 2.0])
    x0, y0 = x.copy(), y.copy()
    x.flags.writeable = False
    y.flags.writeable = False
    w = template(x, y)
    np.testing.assert_array_equal(x, x0)
    np.testing.assert_array_equal(y, y0)
    assert w.shape == (2, 3) and w.dtype == np.float64
    assert not np.shares_memory(w, x) and not np.shares_memory(w, y)


def test_broadcasting_scalar_and_empty():
    xs = np.linspace(-12, 12, 7)
    ys = np.linspace(-3, 9, 5)
    grid = template(xs[:, None], ys[None, :])
    assert grid.shape == (7, 5)
    for a, xa in enumerate(xs):
        for b, yb in enumerate(ys):
            assert grid[a, b] == template(float(xa), float(yb))
    scalar = template(1, 2)  # ints accepted
    assert np.ndim(scalar) == 0 and isinstance(float(scalar), float)
    assert template(np.empty(0), np.empty(0)).shape == (0,)


def test_huge_offsets_give_one_over_r():
    r = 1e200 * math.sqrt(2.0)
    assert template(1e200, 1e200) == pytest.approx(VOLUME / r, rel=1e-15)


@pytest.mark.parametrize("x, y", [(np.nan, 0.0), (0.0, np.inf), ([1.0, 2.0], [1.0, 2.0, 3.0]), ("a", 1.0)])
def test_bad_input_raises(x, y):
    with pytest.raises(InputError):
        template(x, y)


def test_the_lattice_table_is_the_template_at_every_offset():
    # bem.template.lattice_table, the table of bem.InfluenceOperator: the template at the offsets (m / 2, n sqrt3 / 2),
    # m = 2 t + n mod 2, times c / (pi E*); its entries against the template at points made here one by one
    from bem.template import lattice_table

    table = lattice_table((7, 5), 0.03, 2.5)
    assert table.shape == (7, 6)
    for n in range(7):
        for t in range(6):
            x, y = t + (n % 2) / 2.0, n * math.sqrt(3.0) / 2
            assert table[n, t] == pytest.approx(0.03 / (math.pi * 2.5) * float(template(x, y)), rel=1e-15)
