"""The field inside a coated body: per mode against a boundary-value solve of Navier's equations, the
surface against the closed-form compliance, equal materials against the homogeneous half-space, and
Hertz's pressure against Johnson's stresses on the axis."""

import math

import numpy as np
import pytest

from bem.coating import Coating, mode_compliance
from bem.coating_fields import axisymmetric_stress, mode_fields, von_mises

from .test_coating import _lame, navier_solution


@pytest.mark.parametrize("Ec, nuc, Es, nus", [
    (1e9, 0.3, 2e11, 0.3), (2e11, 0.25, 1e9, 0.45), (1e10, 0.2, 1e10, 0.2), (3e9, -0.5, 1e11, 0.3),
    (5e9, 0.499, 1e13, 0.3)])
def test_the_surface_sinks_by_the_closed_form_compliance(Ec, nuc, Es, nus):
    c = Coating(1e-5, Ec, nuc)
    q = np.geomspace(1e-6, 700.0, 60) / c.thickness
    f = mode_fields(q, [0.0], c, Es, nus)
    np.testing.assert_allclose(f["W"][:, 0], 2 * mode_compliance(q, Es, nus, c) / q, rtol=1e-12, atol=0)
    np.testing.assert_allclose(f["Szz"][:, 0], -1.0, rtol=0, atol=1e-13)
    np.testing.assert_allclose(f["Ssz"][:, 0], 0.0, rtol=0, atol=1e-13)


@pytest.mark.parametrize("nuc", [0.3, 0.45, 0.499])
def test_a_rigid_substrate_loses_digits_only_in_the_thinnest_layers(nuc):
    c = Coating(1e-5, 5e9, nuc)
    q = np.geomspace(1e-2, 700.0, 40) / c.thickness
    f = mode_fields(q, [0.0, c.thickness], c, math.inf, 0.3)
    np.testing.assert_allclose(f["W"][:, 0], 2 * mode_compliance(q, math.inf, 0.3, c) / q, rtol=1e-11, atol=0)
    assert np.abs(f["W"][:, 1]).max() <= 1e-12 * np.abs(f["W"][:, 0]).max()  # bonded to the rigid base


@pytest.mark.parametrize("t, Ec, nuc, Es, nus", [
    (0.3, 1.0, 0.25, 10.0, 0.3), (1.0, 10.0, 0.45, 1.0, 0.2), (2.0, 0.1, 0.3, 1.0, 0.3), (0.7, 1.0, -0.5, 3.0, 0.49)])
def test_the_field_inside_equals_a_boundary_value_solve_of_navier(t, Ec, nuc, Es, nus):
    sol = navier_solution(t, Ec, nuc, Es, nus)
    s = np.array([0.0, 0.25, 0.6, 1.0])
    coat = mode_fields([1.0], s * t, Coating(t, Ec, nuc), Es, nus, side="coating")
    depth = np.array([0.0, 0.5, 1.5, 4.0])
    sub = mode_fields([1.0], t + depth, Coating(t, Ec, nuc), Es, nus, side="substrate")
    for f, rows, (lam, mu), pts in ((coat, slice(0, 4), _lame(Ec, nuc), s), (sub, slice(4, 8), _lame(Es, nus), depth / 40.0)):
        U, dU, W, dW = sol(pts)[rows]
        expected = {"U": U, "W": W, "Szz": lam * (U + dW) + 2 * mu * dW, "Ssz": mu * (dU - W),
                    "Sss": lam * (U + dW) + 2 * mu * U, "Snn": lam * (U + dW)}
        for name, value in expected.items():
            np.testing.assert_allclose(f[name][0], value, rtol=1e-6, atol=1e-7 * np.abs(value).max(), err_msg=name)


def test_the_traction_is_continuous_at_the_interface_and_the_in_plane_stress_jumps():
    c = Coating(0.4, 1.0, 0.3)
    q = np.geomspace(0.1, 30.0, 9)
    top, bottom = (mode_fields(q, [c.thickness], c, 20.0, 0.25, side=side) for side in ("coating", "substrate"))
    for name in ("U", "W", "Szz", "Ssz"):
        np.testing.assert_allclose(top[name], bottom[name], rtol=1e-11, atol=1e-13)
    assert np.all(np.abs(top["Sss"] - bottom["Sss"]) > 1e-3 * np.abs(top["Szz"]))


@pytest.mark.parametrize("side", ["coating", "substrate"])
def test_equal_materials_give_the_homogeneous_half_space(side):
    # Johnson, Contact Mechanics (1985), section 2.9: sigma_z = -P (1 + qz) e^-qz cos, sigma_x = -P (1 - qz) e^-qz cos,
    # tau_xz = -P qz e^-qz sin; plane strain: sigma_y = nu (sigma_x + sigma_z) = -2 nu P e^-qz cos
    c = Coating(1e-5, 1e10, 0.3)
    q = np.array([1e3, 1e5, 3e5])
    z = np.array([0.0, 3e-6, 1e-5, 2e-5, 5e-5])
    f = mode_fields(q, z, c, 1e10, 0.3, side=side)
    Q, Z = np.meshgrid(q, z, indexing="ij")
    e = np.exp(-Q * Z)
    for name, value in (("Szz", -(1 + Q * Z) * e), ("Sss", -(1 - Q * Z) * e), ("Ssz", -Q * Z * e), ("Snn", -0.6 * e),
                        ("W", 2 * (1 - 0.3**2) / 1e10 / Q * (1 + Q * Z / (2 * (1 - 0.3))) * e)):
        # a stress that vanishes (Ssz at z = 0) is the cancellation of terms of the load's order: its absolute
        # tolerance is a few ulps of the load (unit pressure amplitude); the displacement W's of its own scale
        scale = 1.0 if name.startswith("S") else np.abs(value).max()
        np.testing.assert_allclose(f[name], value, rtol=1e-12, atol=1e-15 * scale, err_msg=name)


def test_no_overflow_at_any_qt():
    c = Coating(1e-6, 1e9, 0.3)
    q = np.array([1e3, 7e8, 1e12])  # q t up to 1e6
    f = mode_fields(q, [0.0, 0.5e-6, 1e-6, 1e-3], c, 2e11, 0.3)
    assert all(np.all(np.isfinite(v)) for v in f.values())
    np.testing.assert_allclose(f["W"][1:, 0], 2 * (1 - 0.09) / 1e9 / q[1:], rtol=1e-12)  # the coating's half-space


def test_hertz_pressure_on_equal_materials_gives_johnsons_stresses_on_the_axis():
    # Johnson (1985) eq. 3.45: on the axis sigma_z = -p0 / (1 + z^2/a^2),
    # sigma_r = sigma_t = p0 [-(1 + nu)(1 - (z/a) atan(a/z)) + 1 / (2 (1 + z^2/a^2))]
    a, p0, nu = 1e-4, 1e9, 0.3
    z = np.array([0.1, 0.3, 0.48, 0.5, 0.8, 1.5, 3.0]) * a
    s = axisymmetric_stress(lambda r: p0 * np.sqrt(np.clip(1 - (r / a) ** 2, 0, None)), a, [0.0], z,
                            Coating(0.5 * a, 2e11, nu), 2e11, nu, n_q=2048)
    x = z / a
    srr = p0 * (-(1 + nu) * (1 - x * np.arctan(1 / x)) + 0.5 / (1 + x**2))
    np.testing.assert_allclose(s["szz"][0], -p0 / (1 + x**2), rtol=1e-10)
    np.testing.assert_allclose(s["srr"][0], srr, rtol=1e-10)
    np.testing.assert_allclose(s["stt"][0], srr, rtol=1e-10)
    assert np.abs(s["srz"]).max() <= 1e-12 * p0
    vm = von_mises(s["srr"][0], s["stt"][0], s["szz"][0], s["srz"][0])
    assert np.argmax(vm) == 2 and vm[2] == pytest.approx(0.62 * p0, rel=0.01)  # the maximum at z = 0.48 a
    # shallow points: the radial panels follow the shallowest depth (measured 1.7e-3 at z = 0.01 a and 9.9e-6 at
    # 0.02 a; with 16 uniform panels over [0, a/2] whatever the depth: 0.21 and 1.9e-3); a single point at
    # a / 400 with the default n_q: 2.6e-3 (with the fixed panels 23 times off)
    x = np.array([0.01, 0.02])
    s = axisymmetric_stress(lambda r: p0 * np.sqrt(np.clip(1 - (r / a) ** 2, 0, None)), a, [0.0], x * a,
                            Coating(0.5 * a, 2e11, nu), 2e11, nu, n_q=2048)
    assert np.all(np.abs(s["szz"][0] / (-p0 / (1 + x**2)) - 1.0) < [3e-3, 1e-4])
    s = axisymmetric_stress(lambda r: p0 * np.sqrt(np.clip(1 - (r / a) ** 2, 0, None)), a, [0.0], [a / 400],
                            Coating(0.5 * a, 2e11, nu), 2e11, nu)
    assert abs(s["szz"][0, 0] / (-p0 / (1 + 1 / 400**2)) - 1.0) < 5e-3


def test_a_stiff_coating_carries_the_load_in_bending_and_a_soft_one_passes_it_through():
    # a plate-like stiff coating spreads the load: below the centre the interface sees less than the
    # homogeneous body's 1 / (1 + 0.2^2) p0; a soft coating passes on more of it (the same pressure, a load
    # on a stiffer foundation)
    a, p0 = 1.0, 1.0
    p = lambda r: p0 * np.sqrt(np.clip(1 - r**2, 0, None))  # noqa: E731
    stiff = axisymmetric_stress(p, a, [0.0], [0.2], Coating(0.2, 100.0, 0.3), 1.0, 0.3, side="substrate")
    soft = axisymmetric_stress(p, a, [0.0], [0.2], Coating(0.2, 0.01, 0.3), 1.0, 0.3, side="substrate")
    same = axisymmetric_stress(p, a, [0.0], [0.2], Coating(0.2, 1.0, 0.3), 1.0, 0.3, side="substrate")
    assert same["szz"][0, 0] == pytest.approx(-p0 / 1.04, rel=1e-10)
    assert -stiff["szz"][0, 0] < 0.7 * -same["szz"][0, 0] and -same["szz"][0, 0] < -soft["szz"][0, 0] < p0


@pytest.mark.parametrize("kwargs, name", [
    (dict(coating=None), "coating"), (dict(nu_substrate=0.7), "nu_substrate"), (dict(E_substrate=-1.0), "E_substrate"),
    (dict(coating=Coating(1.0, 1.0, 0.5)), "coating.nu")])
def test_bad_input_is_refused_naming_the_argument(kwargs, name):
    args = dict(coating=Coating(1.0, 1.0, 0.3), E_substrate=1.0, nu_substrate=0.3) | kwargs
    with pytest.raises(ValueError, match=name):
        mode_fields([1.0], [0.5], args["coating"], args["E_substrate"], args["nu_substrate"])


def test_inputs_are_not_modified():
    q, z = np.array([1.0, 2.0]), np.array([0.0, 0.5])
    q0, z0 = q.copy(), z.copy()
    mode_fields(q, z, Coating(1.0, 1.0, 0.3), 1.0, 0.3)
    np.testing.assert_array_equal(q, q0)
    np.testing.assert_array_equal(z, z0)


@pytest.mark.parametrize("z", [0.1, 0.35, 0.7])
def test_the_axisymmetric_stresses_are_in_equilibrium_off_the_axis(z):
    # d(srr)/dr + d(srz)/dz + (srr - stt)/r = 0 and d(srz)/dr + d(szz)/dz + srz/r = 0, by central differences,
    # in the coating (z < 0.4) and in the substrate of a stiff coating under Hertz's pressure
    p = lambda r: np.sqrt(np.clip(1 - r**2, 0, None))  # noqa: E731
    r = np.array([0.3, 0.8, 1.2])
    h = 1e-3
    args = (Coating(0.4, 20.0, 0.25), 1.0, 0.3)

    def at(rr, zz):
        return axisymmetric_stress(p, 1.0, rr, [zz], *args, n_q=4096)

    c = at(r, z)
    dr = [at(r + s * h, z) for s in (1, -1)]
    dz = [at(r, z + s * h) for s in (1, -1)]
    f1 = (dr[0]["srr"] - dr[1]["srr"]) / (2 * h) + (dz[0]["srz"] - dz[1]["srz"]) / (2 * h) + (c["srr"] - c["stt"]) / r[:, None]
    f2 = (dr[0]["srz"] - dr[1]["srz"]) / (2 * h) + (dz[0]["szz"] - dz[1]["szz"]) / (2 * h) + c["srz"] / r[:, None]
    scale = np.abs(c["srr"] - c["stt"]).max() / r.min()
    assert np.abs(f1).max() <= 1e-4 * scale and np.abs(f2).max() <= 1e-4 * scale
