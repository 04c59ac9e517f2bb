"""The coated periodic operator: limits, the closed form per mode, symmetry, and coated contact solves."""

import math

import numpy as np
import pytest

import bem
from bem.coating import mode_compliance, oedometric_compliance
from bem.periodic import PeriodicCell, PeriodicOperator
from bem.periodic import coated, coated_thin
from bem.periodic.coated import MAX_TERMS, thin_limit

ES, NUS = 2.0, 0.3  # the substrate of body 1


def _op(cell, coating1=None, E2=math.inf, nu2=0.0, E1=ES, nu1=NUS, coating2=None):
    bodies = bem.Bodies(E1, nu1, E2, nu2, coating1, coating2)
    return PeriodicOperator(cell, bodies.E_star, bodies=bodies)


def _homogeneous(cell, E, nu):
    return PeriodicOperator(cell, E / (1 - nu * nu))


@pytest.mark.parametrize("coating2", [False, True])
def test_a_coating_of_the_substrate_gives_the_homogeneous_operator(coating2):
    cell = PeriodicCell(0.5, 12, 8)
    same = bem.Coating(0.7, ES, NUS)
    op = _op(cell, same, E2=3.0, nu2=0.2, coating2=bem.Coating(0.3, 3.0, 0.2) if coating2 else None)
    hom = PeriodicOperator(cell, bem.effective_modulus(ES, NUS, 3.0, 0.2))
    assert np.abs(op.kernel - hom.kernel).max() <= 1e-15 * np.abs(hom.kernel).max()  # measured 0
    assert op.diagonal == pytest.approx(hom.diagonal, rel=1e-15)


@pytest.mark.parametrize("t", [1e3 * 6.0, 1e6 * 0.5, 891.0])
def test_a_thick_coating_gives_the_coating_operator_without_overflow(t):
    # 1e3 cell sizes, 1e6 steps, and q t = 700 at the cell's longest wave (2 pi / Lx = 0.785 / step)
    cell = PeriodicCell(0.5, 12, 8)
    op = _op(cell, bem.Coating(t, 1.0, 0.45))
    coat = _homogeneous(cell, 1.0, 0.45)
    assert np.abs(op.kernel - coat.kernel).max() <= 1e-14 * np.abs(coat.kernel).max()  # measured 1.7e-16
    assert op.diagonal == pytest.approx(coat.diagonal, rel=1e-14)


@pytest.mark.parametrize("Ec, nuc", [(1.0, 0.3), (20.0, 0.45), (0.05, 0.49)])
def test_a_thin_coating_on_a_rigid_substrate_tends_to_the_oedometric_layer(Ec, nuc):
    """Body 1 is a coating on a rigid base against an elastic body 2: as t -> 0 the operator tends to
    body 2's plus the coating's oedometric compliance on the diagonal (the q -> 0 limit of 2 s / q,
    a closed form independent of the kernel), at a measured order."""
    cell = PeriodicCell(1.0, 8, 8)
    elastic = _homogeneous(cell, 3.0, 0.25)
    errors, sizes = [], (0.1, 0.05, 0.025)
    for t in sizes:
        coating = bem.Coating(t, Ec, nuc)
        op = _op(cell, coating, E1=math.inf, nu1=0.3, E2=3.0, nu2=0.25)
        rest = op.kernel - elastic.kernel
        rest[0, 0] -= oedometric_compliance(coating)
        errors.append(np.abs(rest).max() / elastic.diagonal)
    orders = [math.log2(errors[k] / errors[k + 1]) for k in range(2)]
    assert min(orders) > 1.2, (errors, orders)  # measured 1.3 .. 2.2
    assert errors[-1] < 0.05  # measured 1.3e-3, 5.2e-5, 4.5e-2 (nearly incompressible: the slowest)


@pytest.mark.parametrize("Ec, nuc, Es, nus", [(1.0, 0.3, 2.0, 0.3), (20.0, 0.45, 2.0, 0.2), (0.05, 0.49, 2.0, 0.3),
                                             (3.0, 0.0, math.inf, 0.3), (3.0, 0.5, math.inf, 0.3)])
def test_thin_limit_is_the_long_wave_slope_of_the_compliance(Ec, nuc, Es, nus):
    """lim 2 (s(q) - s(0)) / q: against a Richardson extrapolation of mode_compliance, and on a rigid
    substrate the oedometric compliance."""
    coating = bem.Coating(0.01, Ec, nuc)
    lam = thin_limit(bem.Bodies(Es, nus, 1.0, 0.3, coating))
    q = np.array([1e-2, 5e-3, 2.5e-3])
    slope = 2 * (mode_compliance(q, Es, nus, coating) - mode_compliance(0.0, Es, nus, coating)) / q
    assert lam == pytest.approx((8 * slope[2] - 6 * slope[1] + slope[0]) / 3, rel=1e-8, abs=1e-15)  # measured 2e-11
    if Es == math.inf:
        assert lam == pytest.approx(oedometric_compliance(coating), rel=1e-14, abs=1e-18)


def test_a_thin_coating_on_an_elastic_substrate_tends_to_the_substrate_with_its_thin_limit_layer():
    cell = PeriodicCell(1.0, 8, 8)
    sub = _homogeneous(cell, ES, NUS)
    errors = []
    for t in (0.1, 0.05, 0.025):
        bodies = bem.Bodies(ES, NUS, math.inf, 0.0, bem.Coating(t, 1.0, 0.3))
        rest = PeriodicOperator(cell, bodies.E_star, bodies=bodies).kernel - sub.kernel
        rest[0, 0] -= thin_limit(bodies)
        errors.append(np.abs(rest).max() / sub.diagonal)
    orders = [math.log2(errors[k] / errors[k + 1]) for k in range(2)]
    # measured 1.48, 1.51 (1.48 on to t = 0.0125); other coatings converge more slowly at these t:
    # E_c = 0.2: 1.49, 1.39, 1.28; E_c = 0.5, nu_c = 0.35: 0.94, 1.17, 1.21 (t = 0.1 .. 0.0125)
    assert min(orders) > 1.3, (errors, orders)
    assert errors[-1] < 3e-3  # measured 1.5e-3


def test_a_thin_coating_tends_to_the_substrate_at_first_order():
    cell = PeriodicCell(1.0, 8, 8)
    sub = _homogeneous(cell, ES, NUS)
    diff = [np.abs(_op(cell, bem.Coating(t, 1.0, 0.3)).kernel - sub.kernel).max() / sub.diagonal
            for t in (0.1, 0.05, 0.025)]
    orders = [math.log2(diff[k] / diff[k + 1]) for k in range(2)]
    assert all(0.85 < o < 1.1 for o in orders), orders  # measured 0.90 .. 0.98


def test_a_cosine_pressure_mode_gives_the_closed_form_displacement_as_the_lattice_refines():
    """u = 2 s(q) / q P cos(q x) for p = P cos(q x), q = 2 pi / Lx, on lattices of 16 .. 64 columns."""
    coating = bem.Coating(0.1, 0.4, 0.45)
    lx = 1.0
    q = 2 * math.pi / lx
    closed = 2 * float(mode_compliance(q, ES, NUS, coating) + mode_compliance(q, 3.0, 0.2)) / q
    errors = []
    for n in (16, 32, 64):
        step = lx / n
        rows = 2 * round(n / math.sqrt(3))  # any even number of rows: the mode depends on x only
        cell = PeriodicCell(step, n, rows)
        op = _op(cell, coating, E2=3.0, nu2=0.2)
        p = np.cos(q * cell.x)
        u = op.matvec(p)
        errors.append(np.abs(u - closed * p).max() / closed)
    orders = [math.log2(errors[k] / errors[k + 1]) for k in range(2)]
    assert min(orders) > 1.85, (errors, orders)  # measured 1.92, 1.96: the pyramid basis is second order
    assert errors[-1] < 1e-3  # measured 5.9e-4


@pytest.mark.parametrize("shape", [(6, 5), (8, 12)])
def test_coated_operator_is_a_symmetric_positive_semidefinite_matrix_with_zero_mean(shape):
    cell = PeriodicCell(0.3, shape[1], shape[0])
    op = _op(cell, bem.Coating(0.2, 50.0, 0.2), E2=1.0, nu2=0.4, coating2=bem.Coating(0.5, 0.1, 0.45))
    dense = op.dense()
    assert np.abs(dense - dense.T).max() <= 1e-13 * np.abs(dense).max()  # measured 9.7e-15
    p = np.random.default_rng(3).random(cell.shape)
    u = op.matvec(p)
    scale = (np.abs(dense) @ p.ravel()).max()  # the round-off of a product is relative to sum |C| p
    assert np.abs(u.ravel() - dense @ p.ravel()).max() <= 1e-14 * scale  # measured 3.5e-15
    assert abs(u.mean()) <= 1e-15 * scale
    eig = np.linalg.eigvalsh(dense)
    assert abs(eig[0]) <= 1e-14 * eig[-1] and eig[1] > 1e-3 * eig[-1]  # one zero mode: the constant


def test_full_contact_of_a_wavy_coated_surface_gives_the_closed_form_pressure():
    """h = h0 (1 - cos q x) pressed to full contact: p = pbar + h0 / (2 s(q) / q) cos(q x)."""
    coating = bem.Coating(0.15, 0.5, 0.4)
    q, h0, pbar = 2 * math.pi, 1e-3, 0.05
    amplitude = h0 / (2 * float(mode_compliance(q, ES, NUS, coating)) / q)
    assert amplitude < pbar  # full contact
    errors = []
    for n in (16, 32, 64):
        cell = PeriodicCell(1.0 / n, n, 2 * round(n / math.sqrt(3)))
        h = h0 * (1 - np.cos(q * cell.x))
        res = bem.solve(h, domain=cell, E1=ES, nu1=NUS, E2=math.inf, nu2=0.0, coating1=coating, mean_pressure=pbar)
        assert res.converged and res.kkt_residual <= 1e-10
        p = res.grid()
        errors.append(np.abs(p - (pbar + amplitude * np.cos(q * cell.x))).max() / amplitude)
    orders = [math.log2(errors[k] / errors[k + 1]) for k in range(2)]
    assert min(orders) > 1.85, (errors, orders)  # measured 1.94, 1.97 (KKT 2e-13 .. 5e-12)
    assert errors[-1] < 1e-3  # measured 5.9e-4


@pytest.mark.parametrize("method", ["newton", "kalker"])
def test_westergaard_contact_of_a_body_coated_with_its_own_material_is_the_homogeneous_one(method):
    cell = PeriodicCell(1.0 / 32, 32, 36)
    h = 1e-3 * (1 - np.cos(2 * math.pi * cell.x))
    kw = dict(domain=cell, mean_pressure=2e-3, method=method)
    plain = bem.solve(h, E1=ES, nu1=NUS, E2=math.inf, nu2=0.0, **kw)
    coated = bem.solve(h, E1=ES, nu1=NUS, E2=math.inf, nu2=0.0, coating1=bem.Coating(0.05, ES, NUS), **kw)
    assert 0.1 < coated.contact_fraction < 0.9
    assert coated.converged and coated.kkt_residual <= 1e-10
    assert np.abs(coated.p - plain.p).max() <= 1e-10 * plain.p_max
    assert coated.bodies.coating1.thickness == 0.05 and plain.bodies is None
    assert coated.summary()["coating1"] == {"thickness": 0.05, "E": ES, "nu": NUS}


@pytest.mark.parametrize("layer, load, method", [
    (None, {"mean_pressure": 1e-3}, "newton"),
    (bem.layers.Root(lam=2e-3), {"mean_pressure": 1e-3}, "newton"),
    (bem.layers.Linear(lam=0.01), {"mean_pressure": 1e-3}, "kalker"),
    (None, {"approach": 1.5e-3}, "newton"),
    (bem.layers.Root(lam=2e-3), {"approach": 1.5e-3}, "variable_compliance"),
    (bem.layers.Root(lam=2e-3), {"force": 1e-3}, "variable_compliance"),
])  # the augmented gap stalls on this root layer with and without the coating (KKT 1e-2 .. 2e-1)
def test_coated_rough_contact_converges_with_kkt_on_nested_levels(layer, load, method):
    """A two-mode surface on a soft coating over a stiff substrate, every load control and method: KKT <= 1e-10
    on the coated operator, and the KKT conditions hold against the dense coated matrix (an independent product)."""
    cell = PeriodicCell(1.0 / 32, 32, 36)
    x, y = cell.x, cell.y
    h = 1e-3 * (2 - np.cos(2 * math.pi * x) - np.cos(2 * math.pi * (2 * y / (cell.size[1]))))
    coating = bem.Coating(0.08, 0.2, 0.45)
    res = bem.solve(h, domain=cell, E1=ES, nu1=NUS, E2=5.0, nu2=0.3, coating1=coating, layer=layer, nested=True,
                    method=method, **load)
    assert res.converged and res.kkt_residual <= 1e-10, res.message
    op = _op(cell, coating, E2=5.0, nu2=0.3)
    p = res.grid()
    u = (op.dense() @ p.ravel()).reshape(cell.shape)
    closure = 0.0 if layer is None else layer.w(p)
    g = u + closure + h - res.approach
    scale = np.abs(u + closure).max()
    assert np.all(g >= -1e-9 * scale)
    assert np.abs(g[p > 0]).max() <= 1e-9 * scale


def test_a_coating_needs_the_substrate_and_a_coating_object():
    cell = PeriodicCell(0.1, 8, 8)
    h = np.zeros(cell.shape)
    with pytest.raises(bem.InputError, match=r"^coating1 is not allowed without E1, nu1, E2, nu2"):
        bem.solve(h, domain=cell, E_star=1.0, coating1=bem.Coating(0.1, 1.0, 0.3), mean_pressure=1.0)
    with pytest.raises(bem.InputError, match=r"^coating2 = \{'thickness': 1\} is not allowed: it must be a bem"):
        bem.solve(h, domain=cell, E1=1.0, nu1=0.3, E2=1.0, nu2=0.3, coating2={"thickness": 1}, mean_pressure=1.0)


def test_periodic_operator_refuses_bodies_of_another_modulus_and_too_thin_coatings(monkeypatch):
    cell = PeriodicCell(1.0, 8, 8)
    bodies = bem.Bodies(ES, NUS, math.inf, 0.0, coating1=bem.Coating(0.5, 1.0, 0.3))
    with pytest.raises(bem.InputError, match=r"^E_star = 1.0 is not allowed with bodies"):
        PeriodicOperator(cell, 1.0, bodies=bodies)
    with pytest.raises(bem.InputError, match=r"^bodies = 3 is not allowed"):
        PeriodicOperator(cell, 1.0, bodies=3)
    thin = bem.Bodies(ES, NUS, math.inf, 0.0, coating1=bem.Coating(1e-4, 1.0, 0.3))
    assert coated.routes(8, 8, 1.0, thin) == ((), (1,))  # accepted by its real-space route
    assert PeriodicOperator(cell, thin.E_star, bodies=thin).diagonal > 0
    monkeypatch.setattr(coated_thin, "MAX_OFFSETS", 100)
    coated._cached.cache_clear()
    with pytest.raises(bem.InputError, match=r"^thickness = 0.0001 is not allowed with step = 1.0") as err:
        PeriodicOperator(cell, thin.E_star, bodies=thin)
    assert f"{MAX_TERMS:.0e}" in str(err.value) and f"lam = {thin_limit(thin):.6g} (bem.layers.Linear" in str(err.value)
    assert "real-space route would tabulate 1.7e+02 region coefficients (at most 1e+02: the images within 8 " in str(err.value)
    stiff = bem.Bodies(ES, NUS, math.inf, 0.0, coating1=bem.Coating(1e-4, 10.0, 0.3))
    with pytest.raises(bem.InputError, match=r"stiffens the substrate's surface by the compliance -"):
        PeriodicOperator(cell, stiff.E_star, bodies=stiff)
    coated._cached.cache_clear()


def test_both_domains_take_the_bodies():
    """The half-space region's operator gets the same bodies (its coated kernel: bem.InfluenceOperator(bodies=))."""
    import inspect

    if "bodies" not in inspect.signature(bem.InfluenceOperator).parameters:
        pytest.skip("the coated half-space kernel (bem.InfluenceOperator(bodies=)) is not in this build")
    gap = bem.gaps.Paraboloid(R=10.0)
    kw = dict(step=0.02, extent=1.0, E1=ES, nu1=NUS, E2=math.inf, nu2=0.0, force=0.05)
    plain = bem.solve(gap, **kw)
    same = bem.solve(gap, coating1=bem.Coating(0.2, ES, NUS), **kw)
    soft = bem.solve(gap, coating1=bem.Coating(0.2, 0.3, 0.4), **kw)
    assert same.bodies is not None and soft.converged and soft.kkt_residual <= 1e-10
    assert abs(same.p_max / plain.p_max - 1) <= 1e-12  # measured 1.1e-14
    assert soft.p_max < 0.9 * plain.p_max  # measured 0.86: the soft coating spreads the contact
