"""Subsurface stresses under the BEM pressure (bem.subsurface_stress, bem.boussinesq).

References are derived here, independently of the code: the point-load stresses in Johnson's
cylindrical form, adaptive quadrature of them over the pyramid, and Hertz's on-axis stresses
(Johnson 1985, Contact Mechanics, eq. 3.45, doi:10.1017/CBO9781139171731).
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad_vec
from scipy.optimize import minimize_scalar

import bem
from bem import boussinesq as bq
from bem.gaps import Paraboloid

R, E_STAR, FORCE, NU = 0.01, 2.2e11, 100.0, 0.3
A = (3 * FORCE * R / (4 * E_STAR)) ** (1 / 3)
P0 = 3 * FORCE / (2 * math.pi * A * A)
SQRT3 = math.sqrt(3.0)
HEX = [(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)) for k in range(7)]


def cylindrical_point_load(x, y, z, nu):
    """Boussinesq stresses from sigma_r, sigma_theta, sigma_z, tau_rz (Johnson sec. 3.2), rotated to x, y."""
    r = np.hypot(x, y)
    rho = np.sqrt(r * r + z * z)
    s_r = ((1 - 2 * nu) / r**2 * (1 - z / rho) - 3 * z * r * r / rho**5) / (2 * math.pi)
    s_t = -(1 - 2 * nu) * (1 / r**2 * (1 - z / rho) - z / rho**3) / (2 * math.pi)
    s_z = -3 * z**3 / (2 * math.pi * rho**5)
    t_rz = -3 * r * z * z / (2 * math.pi * rho**5)
    c, s = x / r, y / r
    return np.array([s_r * c * c + s_t * s * s, s_r * s * s + s_t * c * c, s_z, t_rz * s, t_rz * c,
                     (s_r - s_t) * c * s])


def quadrature_pyramid(px, py, z, nu, eps=1e-11):
    """The pyramid's stresses by nested adaptive quadrature (scipy quad_vec) over its six triangles."""
    total = np.zeros(6)
    for k in range(6):
        (x1, y1), (x2, y2) = HEX[k], HEX[k + 1]

        def inner(u, x1=x1, y1=y1, x2=x2, y2=y2):
            def f(w):
                xi, eta = u * (x1 + w * (x2 - x1)), u * (y1 + w * (y2 - y1))
                return (1 - u) * u * (SQRT3 / 2) * cylindrical_point_load(px - xi, py - eta, z, nu)
            return quad_vec(f, 0, 1, epsabs=0, epsrel=eps)[0]

        total += quad_vec(inner, 0, 1, epsabs=0, epsrel=eps, points=[z] if z < 1 else None)[0]
    return total


def johnson_axis(z, nu=NU):
    """Hertz on the axis: sigma_z / p0 and sigma_r / p0 = sigma_theta / p0 (Johnson eq. 3.45)."""
    zeta = np.asarray(z) / A
    s_z = -1 / (1 + zeta**2)
    s_r = -(1 + nu) * (1 - zeta * np.arctan(1 / zeta)) + 0.5 / (1 + zeta**2)
    return s_z, s_r


def hertz(n_per_radius, extent=1.4):
    return bem.solve(Paraboloid(R), E_star=E_STAR, force=FORCE, step=A / n_per_radius, extent=extent * A)


@pytest.fixture(scope="module")
def hertz_ladder():
    return {n: hertz(n) for n in (8, 16, 32)}


def test_point_load_kernel_is_johnsons_and_in_equilibrium():
    for x, y, z in [(0.3, 0.7, 0.5), (-1.2, 0.4, 2.0), (0.01, -0.02, 0.3), (3.0, 4.0, 0.1)]:
        g = bq.point_load_stress(x, y, z, NU)
        ref = cylindrical_point_load(x, y, z, NU)
        assert np.max(np.abs(g - ref)) <= 1e-13 * np.max(np.abs(ref))
        h = 1e-5  # div sigma = 0 by central differences
        d = [(bq.point_load_stress(*np.add((x, y, z), e), NU) - bq.point_load_stress(*np.subtract((x, y, z), e), NU))
             / (2 * h) for e in h * np.eye(3)]
        div = [d[0][0] + d[1][5] + d[2][4], d[0][5] + d[1][1] + d[2][3], d[0][4] + d[1][3] + d[2][2]]
        assert np.max(np.abs(div)) <= 1e-8 * np.max(np.abs(g)) / 0.1


@pytest.mark.slow
@pytest.mark.parametrize("x, y, z", [(0.0, 0.0, 0.02), (1.0, 0.0, 0.05), (1.5, SQRT3 / 2, 0.5),
                                     (4.0, 2 * SQRT3, 2.0), (17.0, 0.0, 1.0), (8.0, 8 * SQRT3, 6.0)])
def test_pyramid_kernel_matches_quadrature_to_1e_8(x, y, z):
    """Near offsets (semi-analytic) and far ones (point-load stencil) against adaptive quadrature."""
    kernel = bq.pyramid_stress(x, y, z, NU)
    ref = quadrature_pyramid(x + 1e-13 if x == 0 else x, y, z, NU)
    assert np.max(np.abs(kernel - ref)) <= 1e-8 * np.max(np.abs(ref))


def test_pyramid_kernel_surface_limits():
    """z -> 0: the stresses tend to their z = 0 values; at z = 0 sigma_zz = -pyramid, no shear."""
    for x, y in [(0.0, 0.0), (1.0, 0.0), (0.5, SQRT3 / 2), (3.0, 0.0)]:
        at0 = bq.pyramid_stress(x, y, 0.0, NU)
        assert at0[2] == pytest.approx(-1.0 if x == y == 0 else 0.0, abs=1e-14)
        assert np.max(np.abs(at0[3:5])) <= 1e-14
        assert np.max(np.abs(bq.pyramid_stress(x, y, 1e-9, NU) - at0)) <= 1e-6
    # at the apex, the surface stresses of any smooth load: sigma_x + sigma_y = -(1 + 2 nu) p
    assert bq.pyramid_stress(0.0, 0.0, 0.0, NU)[:2].sum() == pytest.approx(-(1 + 2 * NU), rel=1e-12)


def test_far_stencil_reproduces_the_pyramid_moments():
    i, j, x, y, w = bq.stencil()
    assert w.size == 43 and w.sum() == pytest.approx(1.0, abs=1e-14)
    # second moment of the unit pyramid: int pyr r^2 / V = 1/4 (lattice units)
    assert np.sum(w * (x * x + y * y)) == pytest.approx(0.25, abs=1e-13)


def test_fft_convolution_matches_the_dense_sum():
    res = bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=0.08, extent=1.3)
    c, load = res.step, res.p > 0
    depths = np.array([0.0, 0.01, 0.3, 1.3, 2.5])
    st = bem.subsurface_stress(res, depths, nu=NU)
    j = np.rint(res.y / (c * SQRT3 / 2)).astype(int)
    i = np.rint(res.x / c - j / 2).astype(int)
    pairs = np.stack([(i[:, None] - i[load]).ravel(), (j[:, None] - j[load]).ravel()], axis=1)
    offsets, index = np.unique(pairs, axis=0, return_inverse=True)  # each lattice offset once
    for k, z in enumerate(depths):
        kern = bq.pyramid_stress(offsets[:, 0] + offsets[:, 1] / 2, offsets[:, 1] * SQRT3 / 2, z / c, NU)
        ref = np.einsum("nmc,m->nc", kern[index.ravel()].reshape(res.p.size, -1, 6), res.p[load])
        assert np.max(np.abs(st.sigma[k] - ref)) <= 1e-12 * np.max(np.abs(ref))


def test_hertz_on_axis_within_half_percent_of_p0(hertz_ladder):
    res = hertz_ladder[16]
    z = np.linspace(0.05, 3.0, 60) * A
    st = bem.subsurface_stress(res, z, nu=NU, x=[0.0], y=[0.0])
    s_z, s_r = johnson_axis(z)
    sig = st.sigma[:, 0] / P0
    assert np.max(np.abs(sig[:, 2] - s_z)) <= 5e-3
    assert np.max(np.abs(sig[:, 0] - s_r)) <= 5e-3
    assert np.max(np.abs(sig[:, 1] - s_r)) <= 5e-3
    assert np.max(np.abs(sig[:, 3:])) <= 1e-9  # no shear on the axis (the solution is symmetric to ~1e-11)


def test_hertz_maxima_of_von_mises_and_max_shear(hertz_ladder):
    """Max von Mises ~0.62 p0 and max shear ~0.31 p0 at z ~ 0.48 a (nu = 0.3), over the whole field."""
    best = minimize_scalar(lambda t: -abs(np.subtract(*johnson_axis(t * A))), bounds=(0.2, 1.0), method="bounded",
                           options={"xatol": 1e-10})
    vm_ref, depth_ref = -best.fun, best.x
    assert vm_ref == pytest.approx(0.62, abs=0.005) and depth_ref == pytest.approx(0.48, abs=0.005)
    st = bem.subsurface_stress(hertz_ladder[16], np.linspace(0.0, 1.5, 31) * A, nu=NU)
    assert st.max_von_mises / P0 == pytest.approx(vm_ref, rel=0.01)
    assert st.max_tresca / P0 == pytest.approx(vm_ref / 2, rel=0.01)
    assert st.depth_of_max / A == pytest.approx(depth_ref, abs=0.02)
    assert st.depth_of_max_tresca / A == pytest.approx(depth_ref, abs=0.02)
    assert np.hypot(*st.location_of_max[:2]) <= 1e-12 and st.location_of_max[2] == st.depth_of_max
    assert st.max_tresca == pytest.approx(float(st.tresca.max()), rel=1e-2)


def test_hertz_error_falls_under_refinement(hertz_ladder):
    """Largest on-axis error over z in [0.05, 3] a; measured: 1.0e-3, 3.1e-4, 4.8e-5 of p0 (orders 1.7, 2.7)."""
    z = np.linspace(0.05, 3.0, 60) * A
    s_z, s_r = johnson_axis(z)
    errors = []
    for n in (8, 16, 32):
        sig = bem.subsurface_stress(hertz_ladder[n], z, nu=NU, x=[0.0], y=[0.0]).sigma[:, 0] / P0
        errors.append(max(np.max(np.abs(sig[:, 2] - s_z)), np.max(np.abs(sig[:, 0] - s_r))))
    orders = [math.log2(errors[i] / errors[i + 1]) for i in range(2)]
    assert errors[0] > errors[1] > errors[2]
    assert min(orders) > 1.5, (errors, orders)


def test_equilibrium_sigma_zz_carries_the_force():
    """int sigma_zz dA over a plane at depth z = -P (tail beyond the region ~ (z / half-width)^3)."""
    res = bem.solve(Paraboloid(R), E_star=E_STAR, force=FORCE, step=A / 6, extent=8 * A)
    z = np.array([0.1, 0.25, 0.5]) * A
    st = bem.subsurface_stress(res, z, nu=NU)
    total = st.sigma[:, :, 2].sum(axis=1) * res.lattice.node_area
    tail = (z / (8 * A * SQRT3 / 2)) ** 3  # bound on the part outside the region
    assert np.all(np.abs(total / FORCE + 1) <= 2 * tail + 1e-9)


def test_stress_is_linear_in_nu_and_sigma_zz_is_independent_of_it(hertz_ladder):
    res = hertz_ladder[8]
    z = np.array([0.2, 0.7]) * A
    s0, s1, s2 = (bem.subsurface_stress(res, z, nu=nu).sigma for nu in (0.0, 0.25, 0.5))
    assert np.max(np.abs(s1 - 0.5 * (s0 + s2))) <= 1e-12 * P0
    assert np.max(np.abs(s0[..., 2:5] - s2[..., 2:5])) <= 1e-12 * P0


def test_points_between_nodes_and_at_nodes(hertz_ladder):
    res = hertz_ladder[8]
    z = np.array([0.0, 0.5 * A])
    full = bem.subsurface_stress(res, z, nu=NU)
    pick = np.array([0, 17, res.p.size // 2])
    at_nodes = bem.subsurface_stress(res, z, nu=NU, x=res.x[pick], y=res.y[pick])
    assert np.array_equal(at_nodes.sigma, full.sigma[:, pick]) and not at_nodes.on_nodes
    assert np.allclose(full.sigma[0, :, 2], -res.p, atol=1e-12 * P0, rtol=0)  # surface: sigma_zz = -p
    n = full.nearest()
    mid = bem.subsurface_stress(res, z, nu=NU, x=[0.5 * res.step], y=[0.0]).sigma[:, 0]
    right = full.nearest(res.step, 0.0)
    assert np.allclose(mid, 0.5 * (full.sigma[:, n] + full.sigma[:, right]))


def test_result_helpers(hertz_ladder):
    res = hertz_ladder[8]
    st = bem.subsurface_stress(res, np.linspace(0, 1.5, 16) * A, nu=NU)
    pr = st.principal()
    assert np.all(pr[..., 0] >= pr[..., 1]) and np.all(pr[..., 1] >= pr[..., 2])
    assert np.allclose(pr.sum(axis=-1), st.sigma[..., :3].sum(axis=-1), atol=1e-9 * P0)
    assert np.allclose(st.tresca, 0.5 * (pr[..., 0] - pr[..., 2]))
    s1, s2, s3 = pr[..., 0], pr[..., 1], pr[..., 2]
    vm = np.sqrt(0.5 * ((s1 - s2) ** 2 + (s2 - s3) ** 2 + (s3 - s1) ** 2))
    assert np.allclose(st.von_mises, vm, atol=1e-9 * P0)
    row = st.section(0.0)
    assert np.all(st.y[row] == 0.0) and np.all(np.diff(st.x[row]) > 0)
    summary = st.summary()
    assert summary["max_von_mises"] == st.max_von_mises and summary["n_depths"] == 16


def test_inputs_are_not_modified(hertz_ladder):
    res = hertz_ladder[8]
    p, x, y = res.p.copy(), res.x.copy(), res.y.copy()
    z = np.array([0.3, 0.1]) * A
    z0 = z.copy()
    px, py = np.array([0.0, A / 3]), np.array([0.0, 0.0])
    bem.subsurface_stress(res, z, nu=NU, x=px, y=py)
    assert np.array_equal(res.p, p) and np.array_equal(res.x, x) and np.array_equal(res.y, y)
    assert np.array_equal(z, z0) and np.array_equal(px, [0.0, A / 3]) and np.array_equal(py, [0.0, 0.0])


@pytest.mark.parametrize("kwargs, match", [
    ({"nu": 0.7}, "nu = 0.7"), ({"nu": -1.0}, "nu = -1.0"), ({"nu": float("nan")}, "nu"), ({"nu": "0.3"}, "nu"),
    ({"z": -1e-6}, "z = -1e-06"), ({"z": [1.0, -2.0]}, r"z\[1\] = -2.0"), ({"z": [0.0, float("nan")]}, "z"),
    ({"z": [[0.0]]}, "z has shape"),
    ({"x": [0.0]}, "give both x and y"), ({"x": [0.0, 1e-5], "y": [0.0]}, "x has shape"),
    ({"x": [1.0], "y": [0.0]}, r"x\[0\], y\[0\]"), ({"result": "p"}, "result = str"),
])
def test_bad_input_raises_input_error_naming_the_argument(hertz_ladder, kwargs, match):
    args = {"result": hertz_ladder[8], "z": [0.0, A], "nu": NU, **kwargs}
    with pytest.raises(bem.InputError, match=match):
        bem.subsurface_stress(args.pop("result"), args.pop("z"), **args)


def test_a_periodic_cell_is_refused_by_name():
    """The sum over one candidate region lacks the images of the other cells: refused, not summed wrongly."""
    from bem.periodic import PeriodicCell, solve_periodic

    res = solve_periodic(lambda x, y: 0.01 * (1 - np.cos(2 * np.pi * x)), cell=PeriodicCell(1 / 16, 16, 16),
                         E_star=1.0, mean_pressure=0.01)
    assert res.converged
    with pytest.raises(bem.InputError, match="^result = PeriodicContactResult is not allowed: it must be a bounded"):
        bem.subsurface_stress(res, [0.01], nu=0.3)


@pytest.mark.parametrize("z, name", [(1e308, "z"), ([0.1, 1e308], r"z\[1\]"), (float("inf"), "z")])
def test_a_depth_too_deep_for_float64_is_refused_by_name(hertz_ladder, z, name):
    res = hertz_ladder[8]
    with pytest.raises(bem.InputError, match=f"{name}.* is not allowed"):
        bem.subsurface_stress(res, z, nu=0.3)


def test_the_deepest_allowed_depth_gives_the_point_force_stress(hertz_ladder):
    """At Z_MAX_STEPS lattice steps sigma_zz is the point force's -3 P / (2 pi z^2)."""
    res = hertz_ladder[8]
    z = bem.stress.Z_MAX_STEPS * res.lattice.step
    st = bem.subsurface_stress(res, z, nu=0.3, x=[0.0], y=[0.0])
    assert np.all(np.isfinite(st.von_mises))
    assert st.sigma[0, 0, 2] == pytest.approx(-3 * res.force / (2 * math.pi * z**2), rel=1e-6)


def test_von_mises_voigt_of_closed_form_states():
    """Uniaxial stress s: von Mises |s|; pure shear t in any plane: sqrt(3) t; a hydrostatic state: 0."""
    from bem.stress import von_mises_voigt

    states = np.array([[2.5, 0, 0, 0, 0, 0], [0, 0, -4.0, 0, 0, 0], [0, 0, 0, 1.5, 0, 0], [0, 0, 0, 0, 0, -2.0],
                       [3.0, 3.0, 3.0, 0, 0, 0]])
    np.testing.assert_allclose(von_mises_voigt(states), [2.5, 4.0, math.sqrt(3) * 1.5, math.sqrt(3) * 2.0, 0.0],
                               rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(von_mises_voigt(states.T, axis=0), von_mises_voigt(states), rtol=0, atol=0)
