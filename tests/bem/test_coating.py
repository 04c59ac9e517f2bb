"""The coated body's compliance per Fourier mode (bem.coating) against its limits, the rigid-base
closed form, and an independent two-material boundary-value solve of Navier's equations."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_bvp

from bem.checks import InputError
from bem.coating import Coating, coating_factor, mode_compliance, oedometric_compliance


def _lame(E, nu):
    mu = E / (2.0 * (1.0 + nu))
    return 2.0 * mu * nu / (1.0 - 2.0 * nu), mu


def _surface_sink(t, Ec, nuc, Es, nus, depth=40.0):
    """Surface displacement W(0) of the mode q = 1 under sigma_zz(0) = -1, sigma_xz(0) = 0."""
    return float(navier_solution(t, Ec, nuc, Es, nus, depth)(0.0)[2])


def navier_solution(t, Ec, nuc, Es, nus, depth=40.0):
    """The mode q = 1 under sigma_zz(0) = -1, sigma_xz(0) = 0, solved as a boundary-value problem:
    ``sol(s)`` gives ``(U, U', W, W')`` of the coating at ``z = s t`` (rows 0-3) and of the substrate at
    ``z = t + s depth`` (rows 4-7; ``'`` is ``d/dz``), ``0 <= s <= 1``.

    Plane strain along q: u_x = U(z) sin x, u_z = W(z) cos x, z into the body; Navier's equations
    mu (U'' - U) - (lam + mu)(U + W') = 0 and (lam + 2 mu) W'' = mu W - (lam + mu) U' in the
    coating (0 < z < t) and the substrate (t < z < t + depth, clamped at the bottom: its error is
    of order e^(-2 depth)), U, W, sigma_zz, sigma_xz continuous at z = t.
    """
    mats, lengths = [_lame(Ec, nuc), _lame(Es, nus)], [t, depth]

    def rhs(s, y):
        out = np.empty_like(y)
        for j, ((lam, mu), L) in enumerate(zip(mats, lengths)):
            U, dU, W, dW = y[4 * j:4 * j + 4]
            ddU = U + (lam + mu) / mu * (U + dW)
            ddW = (mu * W - (lam + mu) * dU) / (lam + 2.0 * mu)
            out[4 * j:4 * j + 4] = L * np.array([dU, ddU, dW, ddW])
        return out

    def traction(y, j):
        lam, mu = mats[j]
        U, dU, W, dW = y[4 * j:4 * j + 4]
        return lam * (U + dW) + 2.0 * mu * dW, mu * (dU - W)

    def bc(ya, yb):
        szz0, sxz0 = traction(ya, 0)
        szz1, sxz1 = traction(yb, 0)
        szz2, sxz2 = traction(ya, 1)
        return np.array([szz0 + 1.0, sxz0, yb[4], yb[6],
                         yb[0] - ya[4], yb[2] - ya[6], szz1 - szz2, sxz1 - sxz2])

    s = np.linspace(0.0, 1.0, 401)
    sol = solve_bvp(rhs, bc, s, np.zeros((8, s.size)), tol=1e-10, max_nodes=200_000)
    assert sol.status == 0, sol.message
    return sol.sol


@pytest.mark.parametrize("t, Ec, nuc, Es, nus", [
    (0.3, 1.0, 0.25, 10.0, 0.3),     # soft coating on a stiff substrate
    (1.0, 10.0, 0.45, 1.0, 0.2),     # stiff, nearly incompressible coating on a soft substrate
    (2.0, 0.1, 0.3, 1.0, 0.3),
    (0.05, 1.0, 0.3, 100.0, 0.3),    # thin coating
    (0.7, 1.0, -0.5, 3.0, 0.49),     # auxetic coating
])
def test_mode_compliance_equals_a_boundary_value_solve_of_navier(t, Ec, nuc, Es, nus):
    expected = _surface_sink(t, Ec, nuc, Es, nus)
    got = 2.0 * mode_compliance(1.0, Es, nus, Coating(t, Ec, nuc))[()]
    assert got == pytest.approx(expected, rel=1e-9)


X = np.concatenate([[0.0], np.logspace(-8, 3, 45)])


@pytest.mark.parametrize("E, nu", [(1.0, 0.3), (7.0, 0.5), (0.2, -0.4)])
def test_equal_materials_give_the_homogeneous_half_space(E, nu):
    phi = coating_factor(X, Coating(1.0, E, nu), E, nu)
    np.testing.assert_allclose(phi, 1.0, rtol=0, atol=4e-16)


@pytest.mark.parametrize("Ec, nuc, Es, nus", [(1.0, 0.3, 10.0, 0.25), (100.0, 0.45, 1.0, 0.3),
                                              (0.01, 0.5, 1.0, 0.2)])
def test_thin_and_thick_coatings_give_the_substrate_and_the_coating(Ec, nuc, Es, nus):
    c = Coating(1.0, Ec, nuc)
    star = lambda E, nu: E / (1.0 - nu * nu)  # noqa: E731
    assert coating_factor(0.0, c, Es, nus)[()] == pytest.approx(star(Ec, nuc) / star(Es, nus), rel=1e-14)
    assert coating_factor(1e-9, c, Es, nus)[()] == pytest.approx(star(Ec, nuc) / star(Es, nus), rel=1e-7)
    np.testing.assert_allclose(coating_factor([40.0, 700.0, 1e6, 1e300, math.inf], c, Es, nus), 1.0,
                               rtol=1e-15)


@pytest.mark.parametrize("nu", [0.0, 0.25, 0.3, 0.45, 0.5])
def test_rigid_substrate_gives_the_rigid_base_stiffness(nu):
    # stiffness E*_c q / 2 (f cosh 2x + 2 x^2 + o) / (f sinh 2x - 2x), f = 3 - 4 nu, o = 5 - 12 nu + 8 nu^2
    # (in extended precision: f sinh 2x - 2x cancels to order x^3 for nu = 0.5)
    x = np.logspace(-2, np.log10(300.0), 60)
    xl = x.astype(np.longdouble)
    f, o = 3.0 - 4.0 * nu, 5.0 - 12.0 * nu + 8.0 * nu * nu
    ratio = (f * np.cosh(2 * xl) + 2 * xl * xl + o) / (f * np.sinh(2 * xl) - 2 * xl)
    phi = coating_factor(x, Coating(1.0, 3.0, nu), math.inf, 0.3)
    np.testing.assert_allclose(1.0 / phi, ratio.astype(float), rtol=2e-13)


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45])
def test_thin_coating_on_a_rigid_substrate_is_oedometric(nu):
    c0 = Coating(1.0, 2.0, nu)
    lam = oedometric_compliance(c0)
    assert lam == pytest.approx((1 + nu) * (1 - 2 * nu) / ((1 - nu) * 2.0), rel=1e-15)
    errors = []
    for q in (1e-2, 1e-3, 1e-4):
        S = 2.0 * mode_compliance(q, math.inf, 0.3, c0)[()] / q
        errors.append(abs(S / lam - 1.0))
    # at least second order in q t: the error falls at least a hundredfold per decade of q
    # (measured: 98-102x for nu = 0.3 and 0.45; 1e4x for nu = 0, where the q^2 term vanishes)
    assert errors[-1] < 3e-6
    assert errors[0] / errors[1] > 95.0 and errors[1] / errors[2] > 95.0


def test_incompressible_coating_on_a_rigid_substrate_is_not_a_winkler_layer():
    c = Coating(1.0, 2.0, 0.5)
    assert oedometric_compliance(c) == 0.0
    q = np.array([1e-3, 1e-2, 1e-1])
    S = 2.0 * mode_compliance(q, math.inf, 0.3, c) / q
    assert np.all(S > 0)
    # compliance of order t^3 q^2 / E: falls a hundredfold per decade of q
    assert S[1] / S[0] == pytest.approx(100.0, rel=0.05)


def test_homogeneous_body_and_rigid_body():
    q = np.array([0.5, 2.0])
    np.testing.assert_array_equal(mode_compliance(q, 2.0, 0.3), (1 - 0.09) / 2.0)
    np.testing.assert_array_equal(mode_compliance(q, math.inf, 0.3), 0.0)


def test_inputs_are_not_modified():
    x = np.array([0.0, 0.5, 900.0])
    keep = x.copy()
    coating_factor(x, Coating(1.0, 1.0, 0.3), 2.0, 0.3)
    mode_compliance(x, 2.0, 0.3, Coating(1.0, 1.0, 0.3))
    np.testing.assert_array_equal(x, keep)


@pytest.mark.parametrize("kwargs, name", [
    (dict(thickness=0.0, E=1.0, nu=0.3), "thickness"),
    (dict(thickness=math.inf, E=1.0, nu=0.3), "thickness"),
    (dict(thickness=math.nan, E=1.0, nu=0.3), "thickness"),
    (dict(thickness=1.0, E=-1.0, nu=0.3), "E"),
    (dict(thickness=1.0, E=1.0, nu=0.6), "nu"),
    (dict(thickness=1.0, E=1.0, nu=-1.0), "nu"),
])
def test_bad_coating_is_refused_naming_the_argument(kwargs, name):
    with pytest.raises(InputError, match=rf"^{name} = "):
        Coating(**kwargs)


@pytest.mark.parametrize("kwargs, name", [
    (dict(E1=-1.0), "E1"), (dict(nu2=0.9), "nu2"), (dict(coating1="thin"), "coating1"),
    (dict(E1=math.inf, E2=math.inf), "E1 = E2 = inf")])
def test_bodies_refuse_bad_input_naming_the_keyword(kwargs, name):
    from bem.coating import Bodies

    args = dict(E1=1.0, nu1=0.3, E2=1.0, nu2=0.3) | kwargs
    with pytest.raises(InputError, match=name):
        Bodies(**args)


def test_bodies_combine_the_compliances_and_see_the_substrates_at_long_waves():
    from bem.coating import Bodies

    c = Coating(0.1, 0.5, 0.25)
    b = Bodies(E1=2.0, nu1=0.3, E2=math.inf, nu2=0.3, coating1=c)
    q = np.array([1e-9, 1.0, 1e4])
    np.testing.assert_allclose(b.compliance(q), mode_compliance(q, 2.0, 0.3, c), rtol=1e-15)
    assert b.E_star == pytest.approx(2.0 / (1 - 0.09), rel=1e-15)
    assert b.compliance(q)[0] == pytest.approx(1 / b.E_star, rel=1e-7)
