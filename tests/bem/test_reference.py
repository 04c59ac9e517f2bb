"""Reference solutions checked against independent quadrature of the Boussinesq
integral (paper eq. 3), force integrals and the K/E form of Hertz's equation."""

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import ellipe, ellipk

from bem.checks import InputError
from bem.reference import (
    hertz_elliptic,
    hertz_sphere,
    rigid_layer_force,
    rigid_layer_paraboloid,
    rigid_layer_pressure,
)

E_STAR = 1.15e11
GAUSS_T, GAUSS_W = np.polynomial.legendre.leggauss(48)


def _gauss(lo, hi):
    """Gauss-Legendre nodes and weights on [lo, hi] (lo, hi broadcastable)."""
    lo, hi = np.asarray(lo)[..., None], np.asarray(hi)[..., None]
    return lo + (hi - lo) * (GAUSS_T + 1) / 2, (hi - lo) / 2 * GAUSS_W


def _u_inside(pressure, a, b, x0, y0, n_theta=256):
    """Boussinesq displacement (1/(pi E*)) int p/rho at a point inside the
    ellipse x^2/a^2 + y^2/b^2 < 1 carrying the pressure: polar coordinates about
    the point (rho cancels), rho = rho_max (1 - t^2) removes the square-root
    edge, Gauss in t, trapezoid (spectral for periodic) in theta."""
    th = 2 * np.pi * np.arange(n_theta) / n_theta
    c, s = np.cos(th), np.sin(th)
    g = c**2 / a**2 + s**2 / b**2
    beta = x0 * c / a**2 + y0 * s / b**2
    alpha = 1 - x0**2 / a**2 - y0**2 / b**2
    rho_max = (-beta + np.sqrt(beta**2 + g * alpha)) / g
    t, w = _gauss(np.zeros_like(th), np.ones_like(th))
    rho = rho_max[:, None] * (1 - t**2)
    f = pressure(x0 + rho * c[:, None], y0 + rho * s[:, None]) * 2 * rho_max[:, None] * t
    return (f * w).sum() * (2 * np.pi / n_theta) / (np.pi * E_STAR)


def _integral_over_ellipse(fun, a, b, n_phi=256):
    """int fun dA over the ellipse, x = a sin(psi) cos(phi), y = b sin(psi) sin(phi)."""
    phi = 2 * np.pi * np.arange(n_phi) / n_phi
    psi, w = _gauss(np.zeros_like(phi), np.full_like(phi, np.pi / 2))
    s = np.sin(psi)
    x, y = a * s * np.cos(phi)[:, None], b * s * np.sin(phi)[:, None]
    jac = a * b * s * np.cos(psi)  # dA = a b s ds dphi, ds = cos(psi) dpsi
    return (fun(x, y) * jac * w).sum() * (2 * np.pi / n_phi)


# ---------------------------------------------------------------- Hertz sphere

def test_hertz_sphere_worked_example():
    # R = 10 mm, E* = 115 GPa, P = 100 N: a^3 = 3*100*0.01/(4*1.15e11) = 6.5217e-12 m^3
    h = hertz_sphere(0.01, E_STAR, force=100.0)
    assert h.contact_radius == pytest.approx(6.521739130434783e-12 ** (1 / 3), rel=1e-14)
    assert h.p_max == pytest.approx(3 * 100.0 / (2 * math.pi * h.contact_radius**2), rel=1e-14)
    assert h.approach == pytest.approx(h.contact_radius**2 / 0.01, rel=1e-14)


def test_hertz_sphere_force_and_approach_control_agree():
    f = hertz_sphere(0.02, 2.0e9, force=7.0)
    d = hertz_sphere(0.02, 2.0e9, approach=f.approach)
    for name in ("contact_radius", "p_max", "approach", "force"):
        assert getattr(d, name) == pytest.approx(getattr(f, name), rel=1e-13)


def test_hertz_sphere_pressure_integrates_to_force():
    h = hertz_sphere(0.01, E_STAR, force=100.0)
    force, _ = quad(lambda r: 2 * np.pi * r * h.pressure(r), 0, h.contact_radius, epsabs=0, epsrel=1e-13)
    assert force == pytest.approx(100.0, rel=1e-10)
    assert h.pressure(0.0) == h.p_max and h.pressure(1.0001 * h.contact_radius) == 0.0


def test_hertz_sphere_displacement_is_boussinesq_and_closes_the_gap():
    h = hertz_sphere(0.01, E_STAR, force=100.0)
    press = lambda x, y: h.pressure(np.hypot(x, y))
    for r in (0.0, 0.3 * h.contact_radius, 0.8 * h.contact_radius):
        u = _u_inside(press, h.contact_radius, h.contact_radius, r, 0.0)
        assert u == pytest.approx(h.approach - r * r / (2 * h.R), rel=1e-9)
        assert h.displacement(r) == pytest.approx(u, rel=1e-9)
    a = h.contact_radius
    for r in (1.5 * a, 3.0 * a):  # outside: smooth kernel, quadrature over the disc
        u = _integral_over_ellipse(lambda x, y: press(x, y) / np.hypot(x - r, y), a, a) / (np.pi * E_STAR)
        assert h.displacement(r) == pytest.approx(u, rel=1e-7)
    assert h.displacement(10 * a) == pytest.approx(100.0 / (np.pi * E_STAR * 10 * a), rel=2e-3)


# ---------------------------------------------------------------- Hertz elliptic

@pytest.mark.parametrize("Rx, Ry", [(0.05, 0.01), (0.01, 0.03), (1.0, 0.0125)])
def test_hertz_elliptic_satisfies_contact_conditions_by_quadrature(Rx, Ry):
    """The real proof: the Boussinesq displacement of the returned pressure
    equals delta - h inside the ellipse, and the pressure integrates to P."""
    P = 250.0
    sol = hertz_elliptic(Rx, Ry, E_STAR, force=P)
    gap = lambda x, y: x * x / (2 * Rx) + y * y / (2 * Ry)
    for fx, fy in [(0, 0), (0.5, 0), (0, 0.5), (0.4, -0.6), (-0.7, 0.2), (0.1, 0.9)]:
        x0, y0 = fx * sol.a, fy * sol.b
        u = _u_inside(sol.pressure, sol.a, sol.b, x0, y0)
        assert u == pytest.approx(sol.approach - gap(x0, y0), rel=1e-9)
    assert _integral_over_ellipse(sol.pressure, sol.a, sol.b) == pytest.approx(P, rel=1e-10)


def test_hertz_elliptic_orientation_and_swap():
    sol = hertz_elliptic(0.05, 0.01, E_STAR, force=10.0)
    assert sol.a > sol.b  # longer axis along the larger radius (x)
    swapped = hertz_elliptic(0.01, 0.05, E_STAR, force=10.0)
    assert (swapped.a, swapped.b) == pytest.approx((sol.b, sol.a), rel=1e-14)
    assert swapped.approach == pytest.approx(sol.approach, rel=1e-14)
    assert sol.eccentricity == pytest.approx(math.sqrt(1 - (sol.b / sol.a) ** 2), rel=1e-12)


@pytest.mark.parametrize("m", [1e-6, 0.01, 0.3, 0.9, 0.999, 0.99999])
def test_eccentricity_equation_in_legendre_form(m):
    """B/A = (E/(1-m) - K)/(K - E) (Johnson 1985 sec. 4.2) with scipy's ellipk/ellipe."""
    K, E = ellipk(m), ellipe(m)
    ratio = (E / (1 - m) - K) / (K - E)
    sol = hertz_elliptic(ratio, 1.0, E_STAR, force=1.0)
    # the K/E form itself loses ~eps/m absolute to cancellation in K - E
    assert sol.eccentricity**2 == pytest.approx(m, rel=1e-10, abs=1e-15 / m)
    # delta = p0 b K / E*, with b the minor semi-axis (Johnson 1985 sec. 3.6)
    assert sol.approach == pytest.approx(sol.p_max * sol.b * K / E_STAR, rel=1e-10)


def test_hertz_elliptic_circular_limit():
    s = hertz_sphere(0.01, E_STAR, force=100.0)
    for Rx in (0.01, 0.01 * (1 + 1e-9)):
        e = hertz_elliptic(Rx, 0.01, E_STAR, force=100.0)
        for name in ("a", "b"):
            assert getattr(e, name) == pytest.approx(s.contact_radius, rel=1e-8)
        assert (e.p_max, e.approach) == pytest.approx((s.p_max, s.approach), rel=1e-8)


def test_hertz_elliptic_approach_control_and_inputs_unmodified():
    f = hertz_elliptic(0.2, 0.01, E_STAR, force=40.0)
    d = hertz_elliptic(0.2, 0.01, E_STAR, approach=f.approach)
    for name in ("a", "b", "p_max", "force"):
        assert getattr(d, name) == pytest.approx(getattr(f, name), rel=1e-12)
    x, y = np.array([0.0, f.a, 2 * f.a]), np.array([0.0, 0.0, 0.0])
    x0 = x.copy()
    np.testing.assert_allclose(f.pressure(x, y), [f.p_max, 0.0, 0.0], atol=1e-9 * f.p_max)
    np.testing.assert_array_equal(x, x0)


@pytest.mark.parametrize("call, name", [
    (lambda: hertz_sphere(-1.0, E_STAR, force=1.0), "R"),
    (lambda: hertz_sphere(1.0, 0.0, force=1.0), "E_star"),
    (lambda: hertz_sphere(1.0, E_STAR), "force, approach"),
    (lambda: hertz_sphere(1.0, E_STAR, force=1.0, approach=1.0), "force, approach"),
    (lambda: hertz_sphere(1.0, E_STAR, force=-1.0), "force"),
    (lambda: hertz_elliptic(1.0, float("nan"), E_STAR, force=1.0), "Ry"),
    (lambda: hertz_elliptic(1.0, 1.0, E_STAR, approach=0.0), "approach"),
])
def test_hertz_validation(call, name):
    with pytest.raises(InputError, match="is not allowed") as info:
        call()
    assert name in str(info.value)


# ---------------------------------------------------------------- rigid layer limit

class _Law:
    """Stand-in for the bem.layers laws, w = lam p**exponent."""

    is_linear = False
    exponent = None

    def w(self, p):
        return self.lam * np.asarray(p, dtype=float) ** self.exponent

    def inverse(self, closure):
        return (np.maximum(closure, 0.0) / self.lam) ** (1.0 / self.exponent)


class _PowerStub(_Law):
    def __init__(self, lam, s):
        self.lam, self.s, self.exponent = lam, s, s


class _LinearStub(_Law):  # like bem.layers.Linear: no ``s``, ``is_linear`` True
    is_linear = True
    exponent = 1.0

    def __init__(self, lam):
        self.lam = lam


class Root(_Law):  # named like bem.layers.Root, without an ``s`` attribute
    exponent = 0.5

    def __init__(self, lam):
        self.lam = lam


def _quad_force(R, lam, s, delta):
    """2 pi int_0^rc r p(r) dr with p = ((delta - r^2/(2R))/lam)^(1/s)."""
    rc = math.sqrt(2 * R * delta)
    p = lambda r: (max(delta - r * r / (2 * R), 0.0) / lam) ** (1 / s)
    return quad(lambda r: 2 * math.pi * r * p(r), 0, rc, epsabs=0, epsrel=1e-13, limit=200)[0]


@pytest.mark.parametrize("law, s", [("linear", 1.0), ("root", 0.5), ("power", 0.3), ("power", 0.7), ("power", 2.0)])
def test_rigid_layer_force_matches_quadrature(law, s):
    R, lam, delta = 0.01, 3e-9, 2e-6
    kw = {"lam": lam, "s": s} if law == "power" else {"lam": lam}
    assert rigid_layer_force(law, R, delta, **kw) == pytest.approx(_quad_force(R, lam, s, delta), rel=1e-10)


def test_rigid_layer_force_special_cases():
    R, lam, d = 0.02, 1e-8, 3e-6
    assert rigid_layer_force("linear", R, d, lam=lam) == pytest.approx(math.pi * R * d**2 / lam, rel=1e-14)
    assert rigid_layer_force("root", R, d, lam=lam) == pytest.approx(2 * math.pi * R * d**3 / (3 * lam**2), rel=1e-14)


def test_rigid_layer_paraboloid_fields_and_force_control():
    sol = rigid_layer_paraboloid("power", 0.01, approach=2e-6, lam=3e-9, s=0.6)
    assert sol.contact_radius == pytest.approx(math.sqrt(2 * 0.01 * 2e-6), rel=1e-15)
    assert sol.p_max == pytest.approx((2e-6 / 3e-9) ** (1 / 0.6), rel=1e-14)
    assert sol.pressure(sol.contact_radius * 1.001) == 0.0
    back = rigid_layer_paraboloid("power", 0.01, force=sol.force, lam=3e-9, s=0.6)
    assert back.approach == pytest.approx(2e-6, rel=1e-13)


@pytest.mark.parametrize("layer, s", [(_PowerStub(3e-9, 0.4), 0.4), (_LinearStub(3e-9), 1.0), (Root(3e-9), 0.5)])
def test_rigid_layer_pressure_and_layer_objects(layer, s):
    R, delta = 0.01, 2e-6
    r = np.linspace(0, 1.2 * math.sqrt(2 * R * delta), 7)
    h = r * r / (2 * R)
    h0 = h.copy()
    p = rigid_layer_pressure(layer, h, delta)
    np.testing.assert_array_equal(h, h0)
    expected = (np.maximum(delta - h, 0) / 3e-9) ** (1 / s)
    np.testing.assert_allclose(p, expected, rtol=1e-14)
    force = quad(lambda r: 2 * math.pi * r * float(rigid_layer_pressure(layer, r * r / (2 * R), delta)),
                 0, math.sqrt(2 * R * delta), epsabs=0, epsrel=1e-12)[0]
    assert rigid_layer_force(layer, R, delta) == pytest.approx(force, rel=1e-9)


def test_rigid_layer_force_of_bem_layers_objects_is_the_quadrature_force():
    from bem import layers

    R, lam, d = 0.01, 3e-9, 2e-6
    for obj, s in [(layers.Linear(lam), 1.0), (layers.Power(lam, 0.4), 0.4), (layers.Root(lam), 0.5)]:
        assert rigid_layer_force(obj, R, d) == pytest.approx(_quad_force(R, lam, s, d), rel=1e-10)


@pytest.mark.parametrize("call, name", [
    (lambda: rigid_layer_force("cubic", 0.01, 1e-6, lam=1.0), "law"),
    (lambda: rigid_layer_force("power", 0.01, 1e-6, lam=1.0), "s"),
    (lambda: rigid_layer_force("linear", 0.01, 1e-6, lam=1.0, s=0.5), "s"),
    (lambda: rigid_layer_force("root", 0.01, 1e-6), "lam"),
    (lambda: rigid_layer_force("linear", -0.01, 1e-6, lam=1.0), "R"),
    (lambda: rigid_layer_force(_PowerStub(1.0, 0.5), 0.01, 1e-6, lam=1.0), "lam, s"),
    (lambda: rigid_layer_force(object(), 0.01, 1e-6), "law.lam"),
    (lambda: rigid_layer_paraboloid("linear", 0.01, lam=1.0), "force, approach"),
    (lambda: rigid_layer_pressure(object(), [0.0], 1e-6), "layer.inverse"),
    (lambda: rigid_layer_pressure(_PowerStub(1.0, 1.0), [0.0, np.nan], 1e-6), "gap_values"),
])
def test_rigid_layer_validation(call, name):
    with pytest.raises(InputError, match="not allowed") as info:
        call()
    assert name in str(info.value)


def test_layer_object_whose_w_is_not_its_parameters_is_refused():
    class Liar(_PowerStub):
        def w(self, p):
            return 2 * self.lam * np.asarray(p) ** self.s

    with pytest.raises(InputError, match="a power law w = lam"):
        rigid_layer_force(Liar(1e-9, 0.5), 0.01, 1e-6)
