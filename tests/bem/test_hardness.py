"""An elastic-perfectly-plastic surface, ``bem.solve(..., hardness=H)``: the pressure bounded by ``0 <= p <= H``.

Checked three ways: the KKT conditions of the bounded problem measured on an independently computed
``C p`` (``g >= 0`` open, ``g = 0`` elastic, ``g <= 0`` plastic), closed forms (a flat punch that
yields everywhere carries ``P = H A``), and an independent solver written here (L-BFGS-B on the
dense influence matrix with the bounds ``[0, H]``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import bem
from bem.gaps import Paraboloid
from bem.kkt import kkt_residual
from bem.periodic.qp_parts import ContactBrick


def _rough(cell, seed=5, modes=4):
    """A seeded smooth random surface on ``cell`` (a few Fourier modes), as a gap brick array."""
    rng = np.random.default_rng(seed)
    lx, ly = cell.size
    h = np.zeros(cell.shape)
    for m in range(1, modes):
        for n in range(-modes + 1, modes):
            amp = rng.standard_normal() / (m * m + n * n)
            h += amp * np.cos(2 * math.pi * (m * cell.x / lx + n * cell.y / ly) + rng.uniform(0, 2 * math.pi))
    return 0.02 * (h - h.min())


def _bounded_kkt(res, u, h_nodes, *, force=None):
    """The KKT residual of the bounded problem at the result's pressure, from ``u = C p`` computed by the caller,
    and the signs of the gap on each set (the rule of each set checked on its own)."""
    g = u + res.closure + h_nodes - res.approach
    H = res.hardness
    plastic, open_ = res.p >= H, res.p == 0
    elastic = ~plastic & ~open_
    scale = float(np.abs(u + res.closure).max())
    assert res.p.min() >= 0 and res.p.max() <= H
    assert np.all(g[open_] >= -1e-10 * scale) and np.all(g[plastic] <= 1e-10 * scale)
    assert np.abs(g[elastic]).max(initial=0.0) <= 1e-10 * scale
    return kkt_residual(res.p, g, displacement_scale=scale, force=force, node_area=res.lattice.node_area, hardness=H)


def _cell_kkt(res, h, force=None):
    op = bem.PeriodicOperator(res.lattice, res.E_star)
    u = op.matvec(res.p.reshape(h.shape)).ravel()
    return _bounded_kkt(res, u, h.ravel(), force=force)


CELL = bem.PeriodicCell(1.0 / 64, 64, 64)


@pytest.mark.parametrize("control", ["mean_pressure", "approach"])
def test_kkt_of_the_bounded_problem_on_a_rough_cell(control):
    h = _rough(CELL)
    elastic = bem.solve_periodic(h, step=CELL.step, E_star=1.0, mean_pressure=0.02)
    H = 0.5 * elastic.p_max
    kw = {"mean_pressure": 0.02} if control == "mean_pressure" else {"approach": elastic.approach}
    res = bem.solve_periodic(h, step=CELL.step, E_star=1.0, hardness=H, rtol=1e-10, **kw)
    assert res.status == "converged", res.message
    assert res.hardness == H and res.p_max == H
    assert 0 < res.plastic_fraction < res.contact_fraction < 1
    assert res.plastic_area == pytest.approx(res.plastic_fraction * CELL.area, rel=1e-12)
    kkt = _cell_kkt(res, h, force=res.force if control == "mean_pressure" else None)
    assert kkt <= 1e-10 and res.kkt_residual <= 1e-10
    # the bound changes the answer: the same load spreads over a larger contact
    if control == "mean_pressure":
        assert res.contact_fraction > elastic.contact_fraction


def _sphere_dense(res, gap):
    """``C p`` and ``h`` at the candidate nodes of a half-space result, ``C`` from products with unit vectors."""
    op = bem.InfluenceOperator(res.lattice, res.E_star)
    return op.matvec(res.grid())[res.lattice.mask], gap(res.x, res.y)


@pytest.mark.parametrize("control", ["force", "approach"])
def test_kkt_of_the_bounded_problem_on_a_half_space_sphere(control):
    gap = Paraboloid(1.0)
    elastic = bem.solve(gap, E_star=1.0, force=1.0, step=0.05, extent=1.3)
    H = 0.5 * elastic.p_max
    kw = {"force": 1.0} if control == "force" else {"approach": elastic.approach}
    res = bem.solve(gap, E_star=1.0, step=0.05, extent="auto", hardness=H, rtol=1e-10, **kw)
    assert res.status == "converged", res.message
    assert res.p_max == H and res.plastic_area > 0
    u, h = _sphere_dense(res, gap)
    assert _bounded_kkt(res, u, h, force=kw.get("force")) <= 1e-10


def test_a_flat_punch_that_yields_everywhere_carries_the_hardness_on_its_area():
    """A flat of N nodes (the gap 0 on it, 1 elsewhere) pressed by P = H N a: every node of the flat at H,
    none elsewhere, A = P / H exactly; the approach is undetermined in [max C p, min (C p + h) off the flat]
    and the lower end is returned."""
    H, step = 0.2, 0.05

    def gap(x, y):
        return np.where(np.hypot(x, y) <= 0.3, 0.0, 1.0)

    region = bem.HalfSpaceRegion(step, (0.6, 0.6))
    lat = region.lattice()
    flat = lat.mask & (gap(lat.x, lat.y) == 0.0)
    force = H * lat.node_area * int(flat.sum())
    res = bem.solve(gap, E_star=1.0, force=force, domain=region, hardness=H)
    assert res.status == "converged", res.message
    assert "fully plastic" in res.message
    on = flat[lat.mask]
    assert np.all(res.p[on] == H) and np.all(res.p[~on] == 0)
    assert res.contact_area == res.plastic_area == pytest.approx(force / H, rel=1e-14)
    lo, hi = res.history["approach_bracket"]
    u = res.displacement
    assert lo == pytest.approx(u[on].max(), rel=1e-12) and hi == pytest.approx((u + gap(res.x, res.y))[~on].min(), rel=1e-12)
    assert res.approach == lo < hi
    assert res.kkt_residual <= 1e-12


@pytest.mark.parametrize("layer", [None, bem.layers.Power(0.1, 0.5)], ids=["qp", "newton_power"])
@pytest.mark.parametrize("share", [1.0, 0.999])
def test_a_flat_punch_at_and_just_below_the_fully_plastic_load(layer, share):
    """At the load H N a every node of the flat yields (the approach's interval reported); just below it all but
    a few do, and the conditions hold. A step that clips many nodes at 0 and others at H carries more than
    the force at H alone: every node is scaled down then (bem.plastic.fill_force)."""
    H = 0.2

    def gap(x, y):
        return np.where(np.hypot(x, y) <= 0.3, 0.0, 1.0)

    region = bem.HalfSpaceRegion(0.05, (0.6, 0.6))
    lat = region.lattice()
    n = int((lat.mask & (gap(lat.x, lat.y) == 0.0)).sum())
    force = share * H * lat.node_area * n
    res = bem.solve(gap, E_star=1.0, force=force, domain=region, hardness=H, layer=layer)
    assert res.status == "converged", res.message
    assert res.kkt_residual <= 1e-10 and res.force == pytest.approx(force, rel=1e-14)
    if share == 1.0:
        assert "fully plastic" in res.message and len(res.history["approach_bracket"]) == 2
        assert res.plastic_area == pytest.approx(force / H, rel=1e-14)
    else:
        assert "fully plastic" not in res.message and 0 < n * lat.node_area - res.plastic_area
        assert res.contact_area == pytest.approx(n * lat.node_area, rel=1e-14)  # the flat, no more
    u, h = _sphere_dense(res, gap)
    assert _bounded_kkt(res, u, h, force=force) <= 1e-10


def test_a_plateau_on_a_cell_that_yields_everywhere():
    cell = bem.PeriodicCell(1.0 / 32, 32, 32)
    h = np.where(np.hypot(cell.x - 0.5, cell.y - 0.5 * cell.size[1]) <= 0.2, 0.0, 0.05)
    H = 0.1
    n = int((h == 0).sum())
    pbar = H * n / h.size
    res = bem.solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=pbar, hardness=H)
    assert res.status == "converged" and "fully plastic" in res.message
    assert np.all(res.p[h.ravel() == 0] == H) and np.all(res.p[h.ravel() > 0] == 0)
    assert res.plastic_fraction == res.contact_fraction == pytest.approx(pbar / H, rel=1e-14)
    # the whole cell at the hardness: mean pressure H, every node plastic
    full = bem.solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=H, hardness=H)
    assert full.status == "converged" and np.all(full.p == H) and full.plastic_fraction == 1.0


def test_a_sphere_at_large_loads_tends_to_the_fully_plastic_area():
    """A >= P / H always (p <= H); the ratio falls towards 1 as the load grows (measured)."""
    H = 0.3
    ratios = []
    for force in (1.0, 4.0, 16.0):
        res = bem.solve(Paraboloid(1.0), E_star=1.0, force=force, step=0.1, extent="auto", hardness=H)
        assert res.status == "converged", res.message
        ratios.append(res.contact_area * H / force)
        assert res.plastic_area / res.contact_area > 0.5
    assert all(r >= 1 for r in ratios)
    assert ratios[0] > ratios[1] > ratios[2]
    assert ratios[2] < 1.005  # measured: 1.031, 1.010, 1.0017


def _dense_bounded(C, b, H):
    """An independent solver: ``min 1/2 q.C q + q.b`` over ``0 <= q <= H`` by L-BFGS-B (scipy)."""
    from scipy.optimize import minimize

    def f(q):
        cq = C @ q
        return 0.5 * q @ cq + q @ b, cq + b

    q = minimize(f, np.full(b.size, 0.5 * H), jac=True, method="L-BFGS-B", bounds=[(0.0, H)] * b.size,
                 options=dict(ftol=0.0, gtol=1e-15, maxiter=20000, maxcor=50)).x
    # polished on the sets L-BFGS-B found (it stops near 1e-9 H): the free nodes solve C_ff q_f = -b_f - C_fp H
    free, plastic = (q > 1e-6 * H) & (q < (1 - 1e-6) * H), q >= (1 - 1e-6) * H
    out = np.where(plastic, H, 0.0)
    out[free] = np.linalg.solve(C[np.ix_(free, free)], -b[free] - C[np.ix_(free, plastic)] @ out[plastic])
    assert np.abs(out - q).max() <= 1e-6 * H and out.min() >= 0 and out.max() <= H  # the same sets
    return out


@pytest.mark.parametrize("control", ["mean_pressure", "approach"])
def test_a_small_cell_agrees_with_an_independent_dense_solver(control):
    cell = bem.PeriodicCell(1.0 / 12, 12, 12)
    h = _rough(cell)
    elastic = bem.solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=0.02, nested=False)
    H = 0.5 * elastic.p_max
    kw = {"mean_pressure": 0.02} if control == "mean_pressure" else {"approach": elastic.approach}
    res = bem.solve_periodic(h, step=cell.step, E_star=1.0, hardness=H, rtol=1e-12, **kw)
    assert res.status == "converged" and res.plastic_fraction > 0
    C = bem.PeriodicOperator(cell, 1.0).dense()
    q = _dense_bounded(C, h.ravel() - res.approach, H)  # the approach of bem's answer (under force control)
    assert np.abs(q - res.p).max() <= 1e-10 * H
    assert cell.node_area * q.sum() == pytest.approx(res.force, rel=1e-8)


def test_a_small_half_space_region_agrees_with_an_independent_dense_solver():
    gap = Paraboloid(1.0)
    region = bem.HalfSpaceRegion(0.1, (0.7, 0.7))
    H = 0.15
    res = bem.solve(gap, E_star=1.0, force=0.085, domain=region, hardness=H, rtol=1e-12)
    assert res.status == "converged" and res.plastic_area > 0
    lat = res.lattice
    op = bem.InfluenceOperator(lat, 1.0)
    nodes = np.flatnonzero(lat.mask.ravel())
    C = np.empty((nodes.size, nodes.size))
    for j, node in enumerate(nodes):  # the dense matrix, a column per product with a unit vector
        e = np.zeros(lat.shape)
        e.flat[node] = 1.0
        C[:, j] = op.matvec(e)[lat.mask]
    q = _dense_bounded(C, gap(res.x, res.y) - res.approach, H)
    assert np.abs(q - res.p).max() <= 1e-10 * H


def test_a_hardness_above_the_peak_pressure_gives_the_elastic_answer(monkeypatch):
    h = _rough(CELL)
    with monkeypatch.context() as m:
        # the elastic cell with the bounded step's update of C p at a change of the contact, an exact product (its
        # default, the product of the move, differs by rounding: 8.5e-11 of p_max here;
        # tests/bem/test_periodic_move_product.py), the bounded step's preconditioner, not corrected at the
        # contact's edges (bem.periodic.edge; with the correction the elastic cell takes other iterations: 8.4e-10
        # of p_max), and its full steps (bem.periodic.qp_parts.EARLY: with the first steps shortened, 5.5e-10)
        m.setattr(ContactBrick, "write_move", lambda self, *args: None)
        m.setattr("bem.periodic.edge.THETA", 0.0)
        m.setattr("bem.periodic.qp_parts.EARLY", 0)
        elastic = bem.solve_periodic(h, step=CELL.step, E_star=1.0, mean_pressure=0.02)
    capped = bem.solve_periodic(h, step=CELL.step, E_star=1.0, mean_pressure=0.02, hardness=1.01 * elastic.p_max)
    assert capped.plastic_area == 0.0 and capped.status == "converged"
    assert np.abs(capped.p - elastic.p).max() <= 1e-11 * elastic.p_max  # measured 7.2e-12 (the same iterations)
    assert capped.contact_area == elastic.contact_area
    sphere = bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=0.05, extent=1.3)
    big = bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=0.05, extent=1.3, hardness=1e6)
    # on the half-space the bounded step gives entering nodes the pressure of a preconditioned step (free of units),
    # the elastic one Polonsky-Keer's -min(tau, 1 / C_nn) g: two iterations, each at its KKT tolerance 1e-10
    assert big.status == sphere.status == "converged" and big.plastic_area == 0.0
    assert big.contact_area == sphere.contact_area
    assert np.abs(big.p - sphere.p).max() <= 1e-8 * sphere.p_max  # measured 2.1e-9


@pytest.mark.parametrize("control", ["force", "approach"])
def test_newton_with_a_nonlinear_layer_meets_the_bounded_kkt_conditions(control):
    gap, layer = Paraboloid(1.0), bem.layers.Power(0.1, 0.5)
    soft = bem.solve(gap, E_star=1.0, force=1.0, step=0.05, extent=1.5, layer=layer)
    H = 0.5 * soft.p_max
    kw = {"force": 1.0} if control == "force" else {"approach": soft.approach}
    res = bem.solve(gap, E_star=1.0, step=0.05, extent="auto", layer=layer, hardness=H, rtol=1e-10, **kw)
    assert res.status == "converged" and res.method == "newton", res.message
    assert res.plastic_area > 0 and res.p_max == H
    u, h = _sphere_dense(res, gap)
    np.testing.assert_allclose(res.closure, layer.w(res.p), rtol=1e-14)
    assert _bounded_kkt(res, u, h, force=kw.get("force")) <= 1e-10


def test_newton_settles_a_node_that_its_model_puts_at_the_hardness():
    """A node just below H whose model puts it at H: damped steps never reached it (33 Newton steps at a
    constant residual 9e-3 on this problem); moved there (bem.newton_moves.settle_plastic), 7."""
    layer = bem.layers.Power(0.1, 0.5)
    soft = bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=0.05, extent=1.5, layer=layer)
    res = bem.solve(Paraboloid(1.0), E_star=1.0, step=0.05, extent="auto", layer=layer, hardness=0.3,
                    approach=soft.approach)
    assert res.status == "converged" and res.plastic_area > 0
    assert res.iterations <= 10


def test_newton_on_a_rough_cell_with_a_layer():
    h = _rough(CELL)
    layer = bem.layers.Power(0.002, 0.5)
    soft = bem.solve_periodic(h, step=CELL.step, E_star=1.0, mean_pressure=0.02, layer=layer)
    H = 0.5 * soft.p_max
    res = bem.solve_periodic(h, step=CELL.step, E_star=1.0, mean_pressure=0.02, layer=layer, hardness=H, rtol=1e-10)
    assert res.status == "converged", res.message
    assert 0 < res.plastic_fraction < res.contact_fraction < 1
    assert _cell_kkt(res, h, force=res.force) <= 1e-10


@pytest.mark.parametrize("value", [0, -1, math.nan, math.inf, "a"])
def test_a_bad_hardness_is_refused_naming_it(value):
    with pytest.raises(bem.InputError, match="hardness"):
        bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=0.1, extent=1.0, hardness=value)


def test_the_paper_methods_refuse_a_hardness():
    with pytest.raises(bem.InputError, match=r"hardness.*augmented_gap"):
        bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=0.1, extent=1.0, layer=bem.layers.Power(0.1, 0.5),
                  method="augmented_gap", hardness=0.3)


def test_a_load_beyond_what_the_nodes_can_carry_at_the_hardness_is_refused():
    with pytest.raises(bem.InputError, match="mean_pressure.*hardness"):
        bem.solve_periodic(np.zeros((8, 8)), step=0.1, E_star=1.0, mean_pressure=0.2, hardness=0.1)
    with pytest.raises(bem.RegionTooSmallError, match="hardness"):
        bem.solve(Paraboloid(1.0), E_star=1.0, force=10.0, step=0.1, extent=0.5, hardness=0.1)


def test_plastic_area_grows_with_the_load_and_the_contact_area_as_the_hardness_falls():
    """The trend of an elastic-plastic rough contact (Persson's picture), measured here on one seeded cell:
    at a fixed hardness the plastic fraction grows with the mean pressure, and at a fixed mean pressure
    the contact fraction grows as the hardness falls."""
    h = _rough(CELL, seed=11)
    by_load = [bem.solve_periodic(h, step=CELL.step, E_star=1.0, mean_pressure=pbar, hardness=0.08)
               for pbar in (0.005, 0.01, 0.02, 0.04)]
    plastic = [r.plastic_fraction for r in by_load]
    assert all(r.status == "converged" for r in by_load)
    assert 0 < plastic[0] < plastic[1] < plastic[2] < plastic[3]
    by_hardness = [bem.solve_periodic(h, step=CELL.step, E_star=1.0, mean_pressure=0.02, hardness=H)
                   for H in (1.0, 0.1, 0.05, 0.03)]
    contact = [r.contact_fraction for r in by_hardness]
    assert contact[0] < contact[1] < contact[2] < contact[3]
    assert by_hardness[-1].contact_fraction >= 0.02 / 0.03  # A / A0 >= pbar / H


def test_result_parts_carry_the_hardness():
    h = _rough(CELL)
    res = bem.solve_periodic(h, step=CELL.step, E_star=1.0, mean_pressure=0.02, hardness=0.05)
    out = res.summary()
    assert out["hardness"] == 0.05 and out["plastic_area"] == res.plastic_area > 0
    assert out["plastic_fraction"] == res.plastic_fraction
    elastic = bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=0.1, extent=1.3).summary()
    assert elastic["hardness"] is None and elastic["plastic_area"] == 0.0


@pytest.mark.parametrize("layer", [None, bem.layers.Root(0.05)], ids=["qp", "newton_root"])
@pytest.mark.parametrize("domain", ["region", "cell"])
def test_the_bound_runs_on_a_strict_array_namespace(monkeypatch, layer, domain):
    """The bounded step on any array API namespace (``array_api_strict``, no conversion to NumPy allowed)
    gives the NumPy answer."""
    xs = pytest.importorskip("array_api_strict")
    from array_api_strict._array_object import Array

    def refuse(self, *args, **kwargs):
        raise AssertionError("an array_api_strict array was converted to NumPy")

    monkeypatch.setattr(Array, "__array__", refuse)
    if domain == "region":
        kw = dict(gap=Paraboloid(1.0), E_star=1.0, force=1.0, step=0.05, extent=1.5, hardness=0.3, layer=layer)
        solve = bem.solve
    else:
        cell = bem.PeriodicCell(1.0 / 32, 32, 32)
        kw = dict(gap=_rough(cell), step=cell.step, E_star=1.0, mean_pressure=0.01, hardness=0.04, layer=layer)
        solve = bem.solve_periodic
    ref = solve(rtol=1e-12, **kw)
    res = solve(rtol=1e-12, device=xs, **kw)
    assert ref.status == res.status == "converged" and ref.plastic_area > 0
    assert np.abs(res.p - ref.p).max() <= 1e-10 * ref.p_max
    assert res.plastic_area == ref.plastic_area


@pytest.mark.parametrize("domain", ["region", "cell"])
def test_every_level_of_nested_iteration_carries_the_bound(monkeypatch, domain):
    import sys

    driver = sys.modules["bem.solve"]
    run, levels = driver._run, []

    def spy(solver, op, h, *args):
        sol = run(solver, op, h, *args)
        levels.append((op.lattice.n_nodes, float(sol.p.max())))
        return sol

    monkeypatch.setattr(driver, "_run", spy)
    if domain == "region":
        res = bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=0.02, extent=1.3, hardness=0.3)
    else:
        cell = bem.PeriodicCell(1.0 / 128, 128, 128)
        res = bem.solve_periodic(_rough(cell), step=cell.step, E_star=1.0, mean_pressure=0.02, hardness=0.05)
    assert res.status == "converged" and len(levels) >= 2
    assert levels[0][0] < levels[-1][0]  # coarse to fine
    assert all(p_max == res.hardness for _, p_max in levels)  # each level has plastic nodes, none above H
