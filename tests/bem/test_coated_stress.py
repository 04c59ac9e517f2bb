"""Stresses below a coated body (bem.coated_stress, bem.mode_sum).

References, independent of the code under test: a single Fourier mode summed directly over its
aliases with bem.coating_fields.mode_fields (no FFT, no folding), the axisymmetric Hankel sums of
bem.coating_fields.axisymmetric_stress, the homogeneous bem.subsurface_stress, and equilibrium.
"""

import dataclasses
import math

import numpy as np
import pytest

import bem
from bem.coated_subsurface import coating_of_substrate
from bem.coating_fields import axisymmetric_stress, mode_fields
from bem.gaps import Paraboloid
from bem.mode_sum import rotated_modes
from bem.periodic.kernel import pyramid_transform

SQRT3 = math.sqrt(3.0)
ES, NUS = 1.0, 0.3
COAT = bem.Coating(0.3, 4.0, 0.25)


def smooth(r):
    """An axisymmetric pressure with a continuous slope, peak 1 (radius 1)."""
    return np.where(r < 1.0, (1 - r * r) ** 2, 0.0)


@pytest.fixture(scope="module")
def cell_result():
    coat = bem.Coating(0.25, 3.0, 0.2)
    cell = bem.PeriodicCell(0.1, 32, 36)
    res = bem.solve(lambda x, y: 0.01 * (1 - np.cos(2 * np.pi * x / cell.size[0])), domain=cell, E1=ES, nu1=0.35,
                    E2=math.inf, nu2=0.0, coating1=coat, mean_pressure=0.01)
    assert res.converged
    return res


@pytest.fixture(scope="module")
def sphere():
    return bem.solve(Paraboloid(10.0), E1=ES, nu1=NUS, E2=math.inf, nu2=0.0, coating1=COAT, force=0.1, step=0.08,
                     extent=1.5)  # 43 rows: the first row is odd, the cell must keep its parity


def direct_mode(G0, x, y, depth, side, coat, Es, nus, step, n=12):
    """The nodal pressure cos(G0.x) in the pyramid basis: its modes G0 + H (H on the nodes' reciprocal
    lattice) each of amplitude hat(G0 + H) / (sqrt3/2), summed one by one with mode_fields."""
    b1, b2 = 2 * np.pi * np.array([1, -1 / SQRT3]) / step, 2 * np.pi * np.array([0, 2 / SQRT3]) / step
    out = np.zeros((x.size, 6))
    for i in range(-n, n + 1):
        for j in range(-n, n + 1):
            G = G0 + i * b1 + j * b2
            k = math.hypot(*G)
            f = mode_fields([k], [depth], coat, Es, nus, side=side)
            T = rotated_modes({nm: f[nm][0, 0] for nm in ("Szz", "Ssz", "Sss", "Snn")}, G[0] / k, G[1] / k)
            amp = pyramid_transform(G[0] * step, G[1] * step) / (SQRT3 / 2)
            out += (amp * T[None, :] * np.exp(1j * (G[0] * x + G[1] * y))[:, None]).real
    return out


def test_a_single_mode_on_a_cell_is_the_sum_of_its_aliases_by_mode_fields(cell_result):
    res = cell_result
    coat, Es, nus = res.bodies.coating1, res.bodies.E1, res.bodies.nu1
    lx, ly = res.lattice.size
    G0 = np.array([2 * np.pi * 3 / lx, -2 * np.pi * 2 / ly])
    fake = dataclasses.replace(res, p=np.cos(G0[0] * res.x + G0[1] * res.y))
    st = bem.coated_stress(fake, [0.05, 0.15, 0.25, 0.4])
    for k, (depth, side, tol) in enumerate([(0.05, "coating", 1e-7), (0.15, "coating", 1e-12),
                                            (0.25, "coating", 1e-12), (0.4, "substrate", 1e-12)]):
        ref = direct_mode(G0, res.x, res.y, depth, side, coat, Es, nus, res.step)
        assert np.abs(st.sigma[k] - ref).max() <= tol, (depth, np.abs(st.sigma[k] - ref).max())
    ref = direct_mode(G0, res.x, res.y, 0.25, "substrate", coat, Es, nus, res.step)
    assert np.abs(st.interface_substrate - ref).max() <= 1e-12


def test_a_cell_carries_its_force_at_every_depth_and_the_traction_is_continuous(cell_result):
    res = cell_result
    st = bem.coated_stress(res, [0.0, 0.1, 0.25, 0.5, 2.0])
    area = res.lattice.node_area
    force = res.p.sum() * area
    for s in list(st.sigma) + [st.interface_coating, st.interface_substrate]:
        assert abs(s[:, 2].sum() * area + force) <= 1e-12 * force
        assert abs(s[:, 3].sum()) + abs(s[:, 4].sum()) <= 1e-12 * res.p.sum()
    c, s = st.interface_coating, st.interface_substrate
    assert np.abs(c[:, 2:5] - s[:, 2:5]).max() <= 1e-12 * res.p_max
    assert np.abs(c[:, 0] - s[:, 0]).max() > 0.1 * res.p_max  # sigma_xx jumps (stiff coating)
    assert np.array_equal(st.sigma[2], st.interface_coating)


def test_a_smooth_axisymmetric_pressure_matches_the_hankel_sums_to_second_order():
    """Coating and substrate, both sides of the interface, about a centre off the region's symmetry
    axes (points on nodes); the error of the pyramid interpolant falls like c^2."""
    x0, y0 = 0.25, 0.05 * SQRT3  # a node of both lattices, in an odd row of the coarse one
    errors = []
    for step in (0.1, 0.05):
        res = bem.solve(Paraboloid(10.0), E1=ES, nu1=NUS, E2=math.inf, nu2=0.0, coating1=COAT, force=0.1,
                        step=step, extent=1.5)
        fake = dataclasses.replace(res, p=smooth(np.hypot(res.x - x0, res.y - y0)))
        r = np.array([0.0, 0.5, 0.9])
        st = bem.coated_stress(fake, [0.15, 0.3, 0.6], x=x0 + r, y=np.full(3, y0), pad=8.0)
        ac = axisymmetric_stress(smooth, 1.0, r, [0.15, 0.3], COAT, ES, NUS, side="coating", n_q=8192)
        asub = axisymmetric_stress(smooth, 1.0, r, [0.3, 0.6], COAT, ES, NUS, side="substrate", n_q=8192)
        ours_c = st.sigma[:2]
        ours_s = np.stack([st.interface_substrate, st.sigma[2]])
        err = {}
        for key, comp in (("szz", 2), ("srr", 0), ("stt", 1), ("srz", 4)):
            err[key] = max(np.abs(ours_c[..., comp] - ac[key].T).max(), np.abs(ours_s[..., comp] - asub[key].T).max())
        errors.append(err)
    # measured: 4.2e-3 at c = 0.1, 1.06e-3 at c = 0.05 (every component: order 2.0)
    assert max(errors[0].values()) <= 5e-3 and max(errors[1].values()) <= 1.3e-3, errors
    assert all(errors[1][key] < errors[0][key] / 3.0 for key in errors[0]), errors  # second order


def test_the_bem_sphere_on_a_coated_flat_matches_the_axisymmetric_stress_of_its_binned_pressure(sphere):
    res = sphere
    r = np.hypot(res.x, res.y)
    edges = np.linspace(0.0, r.max(), 60)
    idx = np.digitize(r, edges)
    keep = [i for i in range(1, edges.size) if np.any(idx == i)]
    rb = np.array([r[idx == i].mean() for i in keep])
    pb = np.array([res.p[idx == i].mean() for i in keep])

    def p(rr):
        return np.interp(rr, rb, pb, right=0.0)

    z = np.array([0.1, 0.2, 0.45, 0.7])
    st = bem.coated_stress(res, z, x=[0.0], y=[0.0])
    r_max = 1.3 * res.contact_radius
    ac = axisymmetric_stress(p, r_max, [0.0], [0.1, 0.2, 0.3], COAT, ES, NUS, side="coating", n_q=8192)
    asub = axisymmetric_stress(p, r_max, [0.0], [0.3, 0.45, 0.7], COAT, ES, NUS, side="substrate", n_q=8192)
    ours_c = np.concatenate([st.sigma[:2, 0], st.interface_coating])
    ours_s = np.concatenate([st.interface_substrate, st.sigma[2:, 0]])
    for key, comp in (("szz", 2), ("srr", 0)):
        assert np.abs(ours_c[:, comp] - ac[key][0]).max() <= 5e-3 * res.p_max
        assert np.abs(ours_s[:, comp] - asub[key][0]).max() <= 5e-3 * res.p_max


def test_equal_materials_give_the_homogeneous_stress():
    res = bem.solve(Paraboloid(10.0), E1=ES, nu1=NUS, E2=math.inf, nu2=0.0, coating1=bem.Coating(0.3, ES, NUS),
                    force=0.1, step=0.1, extent=1.4)
    z = np.array([0.0, 0.1, 0.3, 0.6])
    st = bem.coated_stress(res, z)
    plain = dataclasses.replace(res, bodies=None)  # the same pressure, read as a homogeneous body's
    hom = bem.subsurface_stress(plain, np.concatenate([z, [0.3]]), nu=NUS)
    assert np.abs(st.sigma - hom.sigma[:4]).max() <= 1e-12 * res.p_max
    assert np.abs(st.interface_coating - hom.sigma[4]).max() <= 1e-12 * res.p_max
    assert np.abs(st.interface_substrate - hom.sigma[4]).max() <= 1e-12 * res.p_max
    assert st.in_coating.tolist() == [True, True, True, False]


def test_a_half_space_carries_its_force_and_the_traction_is_continuous():
    res = bem.solve(Paraboloid(10.0), E1=ES, nu1=NUS, E2=math.inf, nu2=0.0, coating1=COAT, force=0.1, step=0.15,
                    extent=6.0)
    z = np.array([0.1, 0.3, 0.6])
    st = bem.coated_stress(res, z)
    area = res.lattice.node_area
    half_width = 6.0 * SQRT3 / 2
    for depth, s in zip(z, st.sigma):
        tail = (depth / half_width) ** 3  # bound on the part of the homogeneous field outside the region
        assert abs(s[:, 2].sum() * area / res.force + 1) <= 2 * tail + 2e-3
    c, s = st.interface_coating, st.interface_substrate
    assert np.abs(c[:, 2:5] - s[:, 2:5]).max() <= 1e-12 * res.p_max  # the remainders' traction parts are equal
    assert np.abs(c[:, 0] - s[:, 0]).max() > 0.1 * res.p_max


def test_the_coating_map_keeps_the_in_plane_strain():
    rng = np.random.default_rng(3)
    sig = rng.normal(size=(5, 6))
    out = coating_of_substrate(sig, COAT, ES, NUS)

    def strain(s, E, nu):
        xx, yy, zz, yz, xz, xy = s.T
        return np.stack([xx - nu * (yy + zz), yy - nu * (xx + zz), (1 + nu) * xy]) / E

    assert np.allclose(strain(out, COAT.E, COAT.nu), strain(sig, ES, NUS), atol=1e-14)
    assert np.array_equal(out[:, 2:5], sig[:, 2:5])


def test_maxima_summary_and_inputs_not_modified(sphere):
    res = sphere
    p, x, y = res.p.copy(), res.x.copy(), res.y.copy()
    z = np.array([0.6, 0.1, 0.2])
    z0 = z.copy()
    st = bem.coated_stress(res, z)
    assert np.array_equal(res.p, p) and np.array_equal(res.x, x) and np.array_equal(res.y, y)
    assert np.array_equal(z, z0)
    xx, yy, zz, yz, xz, xy = st.interface_coating.T
    vm_iface = np.sqrt(0.5 * ((xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2) + 3 * (yz * yz + xz * xz + xy * xy))
    vm_c = max(st.von_mises[1:].max(), vm_iface.max())
    assert st.max_von_mises_coating >= st.von_mises[1:].max() and st.max_von_mises_coating == vm_c
    assert st.location_of_max_substrate[2] in (0.3, 0.6)
    s = st.summary()
    assert s["body"] == 1 and s["max_von_mises_coating"] == st.max_von_mises_coating
    tr = st.interface_traction("coating")
    assert np.allclose(tr["shear"], np.hypot(st.interface_coating[:, 4], st.interface_coating[:, 3]))


@pytest.mark.parametrize("kwargs, match", [
    ({"body": 2}, "body = 2 is not allowed: that body is not coated"), ({"body": 3}, "body = 3"),
    ({"z": [-1.0]}, r"z\[0\] = -1.0"), ({"z": [[0.1]]}, "z has shape"), ({"pad": 1.0}, "pad = 1.0"),
    ({"x": [0.0]}, "give both x and y"), ({"x": [0.0, 0.1], "y": [0.0]}, "x has shape"),
    ({"result": "p"}, "result = str"),
])
def test_bad_input_is_refused_naming_the_argument(sphere, kwargs, match):
    args = {"result": sphere, "z": [0.1], **kwargs}
    with pytest.raises(bem.InputError, match=match):
        bem.coated_stress(args.pop("result"), args.pop("z"), **args)


def test_uncoated_and_rigid_substrates_are_refused_by_name():
    plain = bem.solve(Paraboloid(10.0), E_star=1.0, force=0.1, step=0.1, extent=1.4)
    with pytest.raises(bem.InputError, match="neither body is coated"):
        bem.coated_stress(plain, [0.1])
    rigid = bem.solve(Paraboloid(10.0), E1=math.inf, nu1=0.3, E2=ES, nu2=NUS, coating1=COAT, force=0.1, step=0.1,
                      extent=1.4)
    st = bem.coated_stress(rigid, [0.0, 0.2])  # the coating on a rigid substrate has stresses
    assert st.interface_substrate is None and np.isfinite(st.sigma).all()
    with pytest.raises(bem.InputError, match=r"z\[1\] = 0.5 is not allowed: body 1's substrate is rigid"):
        bem.coated_stress(rigid, [0.1, 0.5])


def test_the_coated_body_is_found_on_either_side():
    kw = dict(force=0.1, step=0.1, extent=1.4)
    one = bem.solve(Paraboloid(10.0), E1=ES, nu1=NUS, E2=math.inf, nu2=0.0, coating1=COAT, **kw)
    two = bem.solve(Paraboloid(10.0), E1=math.inf, nu1=0.0, E2=ES, nu2=NUS, coating2=COAT, **kw)
    a, b = bem.coated_stress(one, [0.1, 0.5]), bem.coated_stress(two, [0.1, 0.5])
    assert (a.body, b.body) == (1, 2)
    assert np.abs(a.sigma - b.sigma).max() <= 1e-12 * one.p_max
    both = bem.solve(Paraboloid(10.0), E1=ES, nu1=NUS, E2=ES, nu2=NUS, coating1=COAT, coating2=COAT, **kw)
    with pytest.raises(bem.InputError, match="body = None is not allowed: both bodies are coated"):
        bem.coated_stress(both, [0.1])


def test_the_homogeneous_stress_refuses_a_coated_body_and_takes_the_uncoated_one():
    res = bem.solve(Paraboloid(10.0), E1=ES, nu1=NUS, E2=2.0, nu2=0.3, coating1=COAT, force=0.1, step=0.15,
                    extent=3.0)
    with pytest.raises(bem.InputError, match=r"^body = None is not allowed for this result: body 1 is coated"):
        bem.subsurface_stress(res, 0.1, nu=NUS)
    with pytest.raises(bem.InputError, match=r"^body = 1 is not allowed: that body is coated"):
        bem.subsurface_stress(res, 0.1, nu=NUS, body=1)
    with pytest.raises(bem.InputError, match=r"^body = 3 is not allowed"):
        bem.subsurface_stress(res, 0.1, nu=0.3, body=3)
    lower = bem.subsurface_stress(res, [0.1, 0.3], nu=0.3, body=2)
    plain = bem.subsurface_stress(dataclasses.replace(res, bodies=None), [0.1, 0.3], nu=0.3)
    assert np.array_equal(lower.sigma, plain.sigma)
