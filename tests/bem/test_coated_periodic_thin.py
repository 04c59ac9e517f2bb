"""Thin coatings on the periodic cell: the real-space route against the alias sum, the symbol, and the thin limit."""

import math

import numpy as np
import pytest

import bem
from bem import layers
from bem.coating import mode_compliance
from bem.periodic import PeriodicCell, PeriodicOperator
from bem.periodic import coated, coated_thin
from bem.periodic.kernel import periodic_template, pyramid_transform

_SQRT3 = math.sqrt(3.0)


@pytest.fixture(autouse=True)
def _fresh_templates():
    """Each test builds its own templates: the patched route switch is not part of the cache's key."""
    coated._cached.cache_clear()
    yield
    coated._cached.cache_clear()


def _template(monkeypatch, cell, bodies, per_node):
    """The coated template with the routes' switch at ``per_node`` alias terms a node (0: real space where it holds)."""
    monkeypatch.setattr(coated, "ALIAS_PER_NODE", per_node)
    monkeypatch.setattr(coated, "ALIAS_FLOOR", 0)
    coated._cached.cache_clear()  # the second call of a test switches the routes
    return coated.coated_template(cell.n_rows, cell.n_cols, cell.step, bodies), \
        coated.routes(cell.n_rows, cell.n_cols, cell.step, bodies)


@pytest.mark.parametrize("rows, cols, bodies, images", [
    (128, 128, bem.Bodies(2.0, 0.3, math.inf, 0.0, bem.Coating(1.0, 1.0, 0.3)), (0, 0)),
    (128, 128, bem.Bodies(2.0, 0.3, math.inf, 0.0, bem.Coating(0.5, 0.02, 0.49)), (0, 0)),
    (128, 128, bem.Bodies(math.inf, 0.3, 3.0, 0.2, bem.Coating(1.0, 1.0, 0.3)), (0, 0)),
    (128, 128, bem.Bodies(2.0, 0.3, 3.0, 0.2, bem.Coating(0.7, 0.2, 0.45), bem.Coating(0.4, 6.0, 0.25)), (0, 0)),
    (64, 64, bem.Bodies(2.0, 0.3, math.inf, 0.0, bem.Coating(0.3, 0.5, 0.3)), (0, 0)),
    (16, 16, bem.Bodies(2.0, 0.3, math.inf, 0.0, bem.Coating(0.5, 1.0, 0.3)), (1, 1)),
    (8, 8, bem.Bodies(2.0, 0.3, math.inf, 0.0, bem.Coating(0.3, 0.5, 0.3)), (2, 2)),
    (12, 40, bem.Bodies(2.0, 0.3, math.inf, 0.0, bem.Coating(0.4, 0.3, 0.4)), (1, 2)),
])
def test_the_real_space_route_equals_the_alias_sum_where_both_hold(monkeypatch, rows, cols, bodies, images):
    """Both routes are exact: soft, nearly incompressible, rigid-substrate and two coated bodies, t = 0.3 .. 1 c;
    on the small cells with the images within the coating's reach ``(I, J)`` taken from the region's table."""
    cell = PeriodicCell(1.0, cols, rows)
    coated_body = 1 if bodies.coating1 is not None else 2
    assert coated_thin.images_for(rows, cols, coated_thin.reach(bodies, coated_body, 1.0)) == images
    alias, routes = _template(monkeypatch, cell, bodies, math.inf)
    assert routes[1] == ()
    real, routes = _template(monkeypatch, cell, bodies, 0.0)
    assert routes[0] == () and routes[1]
    plain = bodies.E_star * periodic_template(rows, cols) / bem.Bodies(bodies.E1, bodies.nu1, bodies.E2, bodies.nu2).E_star
    assert np.abs(real - plain).max() >= 0.1 * alias[0, 0]  # the coating matters
    assert np.abs(real - alias).max() <= 1e-13 * alias[0, 0]  # measured 1.8e-15 .. 1.0e-14


@pytest.mark.parametrize("cols, rows, coating", [(40, 48, bem.Coating(0.01, 20.0, 0.3)),
                                                 (40, 48, bem.Coating(0.01, 0.05, 0.45)),
                                                 (16, 20, bem.Coating(0.01, 20.0, 0.3))])
def test_a_thin_coating_has_the_symbol_of_its_compliance(cols, rows, coating):
    """A stiff (E_c = 20 E_s) and a soft coating, t = c / 100 (real space; the alias sum of the template would
    take 2.4e8 terms on 40 x 48 nodes): the discrete Fourier transform of the template at three modes against the alias sum
    of that mode alone, sum_B (2 pi / |G0 + B|) E* (s - s_inf) hat(G0 + B) over the reciprocal node
    lattice B, to k t = 40 (1.1e6 terms). On the 16 x 20 cell the stiff coating's reach (13.9 steps) takes
    the images around the nearest from the region's table, (I, J) = (1, 1)."""
    cell = PeriodicCell(1.0, cols, rows)
    bodies = bem.Bodies(1.0, 0.3, math.inf, 0.0, coating)
    assert coated.routes(cell.n_rows, cell.n_cols, cell.step, bodies) == ((), (1,))
    assert coated_thin.images_for(rows, cols, coated_thin.reach(bodies, 1, 1.0)) == ((1, 1) if cols == 16 else (0, 0))
    w = coated.coated_template(cell.n_rows, cell.n_cols, cell.step, bodies)
    s_inf = (1 - coating.nu ** 2) / coating.E
    rest = w - bodies.E_star * s_inf * periodic_template(cell.n_rows, cell.n_cols)
    lx, ly = cell.n_cols, cell.n_rows * _SQRT3 / 2
    area, nodes = lx * ly, cell.n_rows * cell.n_cols
    b1, b2 = 2 * math.pi * np.array([1.0, -1 / _SQRT3]), 2 * math.pi * np.array([0.0, 2 / _SQRT3])
    k_max = 40 / coating.thickness
    span = int(k_max / (2 * math.pi) * 1.2) + 2
    i, j = (a.ravel() for a in np.meshgrid(np.arange(-span, span + 1), np.arange(-span, span + 1)))
    for m, n in ((1, 0), (5, 3), (cell.n_cols // 2 - 1, 7)):
        g0 = np.array([2 * math.pi * m / lx, 2 * math.pi * n / ly])
        kx, ky = g0[0] + i * b1[0] + j * b2[0], g0[1] + i * b1[1] + j * b2[1]
        k = np.hypot(kx, ky)
        keep = k <= k_max
        excess = mode_compliance(k[keep], 1.0, 0.3, coating) - s_inf
        direct = np.sum(2 * math.pi / k[keep] * bodies.E_star * excess * pyramid_transform(kx[keep], ky[keep]))
        dft = area / nodes * np.sum(rest * np.exp(-1j * (g0[0] * cell.x + g0[1] * cell.y)))
        assert abs(dft - direct) <= 1e-12 * abs(direct), (m, n, abs(dft - direct) / abs(direct))  # measured 7e-16 .. 2.1e-14


def _wavy(n, rows):
    cell = PeriodicCell(1.0 / n, n, rows)
    x, y = cell.x, cell.y
    return cell, 1e-3 * (2 - np.cos(2 * math.pi * x) - np.cos(2 * math.pi * (2 * y / cell.size[1])))


def test_a_coating_a_thousandth_of_a_step_on_a_cell_is_the_substrate_with_its_thin_limit_layer():
    """A soft coating, t = c / 1000 (its alias sum would take 7e9 terms): the solve equals the substrate's
    with the linear layer of :func:`bem.periodic.coated.thin_limit` to 1e-6 of the peak pressure, at KKT 1e-10."""
    cell, h = _wavy(32, 36)
    kw = dict(domain=cell, E1=1.0, nu1=0.3, E2=1.0, nu2=0.3, mean_pressure=1e-3, rtol=1e-12)
    thin = bem.solve(h, coating2=bem.Coating(cell.step / 1000, 0.3, 0.35), **kw)
    assert coated.routes(cell.n_rows, cell.n_cols, cell.step, thin.bodies) == ((), (2,))
    assert thin.converged and thin.kkt_residual <= 1e-10  # measured 6.5e-13
    limit = bem.solve(h, layer=layers.Linear(coated.thin_limit(thin.bodies)), **kw)
    bare = bem.solve(h, **kw)
    assert 0.1 < thin.contact_fraction < 0.9
    assert np.abs(thin.p - limit.p).max() <= 1e-6 * limit.p.max()  # measured 3.0e-7
    assert np.abs(thin.p - bare.p).max() >= 1e-4 * bare.p.max()  # the coating is seen (3.8e-4)


def test_a_stiff_coating_a_thousandth_of_a_step_solves_with_kkt_against_its_dense_matrix():
    """E_c = 100 E_s, t = c / 1000 (reach 6.6 steps, the cell's images 9 away): KKT 1e-10, and the KKT
    conditions hold against the dense coated matrix."""
    cell, h = _wavy(20, 24)
    coating = bem.Coating(cell.step / 1000, 100.0, 0.3)
    kw = dict(domain=cell, E1=1.0, nu1=0.3, E2=math.inf, nu2=0.0, mean_pressure=1e-3)
    res = bem.solve(h, coating1=coating, **kw)
    assert coated.routes(cell.n_rows, cell.n_cols, cell.step, res.bodies) == ((), (1,))
    assert res.converged and res.kkt_residual <= 1e-10, res.message  # measured 4.4e-11
    op = PeriodicOperator(cell, res.bodies.E_star, bodies=res.bodies)
    p = res.grid()
    u = (op.dense() @ p.ravel()).reshape(cell.shape)
    g = u + h - res.approach
    assert np.all(g >= -1e-9 * np.abs(u).max()) and np.abs(g[p > 0]).max() <= 1e-9 * np.abs(u).max()
    bare = bem.solve(h, **kw)
    assert np.abs(res.p - bare.p).max() >= 1e-3 * bare.p.max()  # the stiff coating is seen (measured 1.5e-2)


def test_a_thin_and_a_thick_coating_take_their_own_routes():
    """Body 1 coated a thousandth of a step (real space), body 2 a thousand cell sizes (alias sum, k t = 8e4
    at the longest wave): the template of body 2 made of its coating's material, to round-off."""
    cell = PeriodicCell(1.0, 24, 28)
    thin = bem.Coating(1e-3, 0.3, 0.35)
    both = bem.Bodies(1.0, 0.3, 2.0, 0.2, thin, bem.Coating(1e3 * 24, 0.5, 0.45))
    own = bem.Bodies(1.0, 0.3, 0.5, 0.45, thin)
    assert coated.routes(cell.n_rows, cell.n_cols, cell.step, both) == ((2,), (1,))
    w = PeriodicOperator(cell, both.E_star, bodies=both).kernel
    ref = PeriodicOperator(cell, own.E_star, bodies=own).kernel
    assert np.all(np.isfinite(w))
    assert np.abs(w - ref).max() <= 1e-14 * ref[0, 0]  # measured 2.1e-16
