"""A coated body with a hardness: the bounded problem's KKT conditions on both domains, checked on a
displacement recomputed here by the coated operator."""

import numpy as np

import bem
from bem.gaps import Paraboloid
from bem.kkt import kkt_residual

STEEL = dict(E1=200e9, nu1=0.3, E2=200e9, nu2=0.3)


def test_a_coated_sphere_with_a_hardness_meets_the_bounded_kkt_conditions():
    coating = bem.Coating(2e-4, 20e9, 0.3)
    kw = dict(STEEL, coating2=coating, force=20.0, step=2e-5, extent="auto")
    elastic = bem.solve(Paraboloid(0.01), **kw)
    H = 0.5 * elastic.p_max
    res = bem.solve(Paraboloid(0.01), hardness=H, **kw)
    assert res.status == "converged" and res.kkt_residual <= 1e-10
    assert res.p.max() <= H and res.plastic_area > 0 and res.contact_area > elastic.contact_area
    op = bem.InfluenceOperator(res.lattice, res.E_star, bodies=bem.Bodies(coating2=coating, **STEEL))
    grid = np.zeros(res.lattice.shape)
    grid[res.lattice.mask] = res.p
    u = op.matvec(grid)[res.lattice.mask]
    g = u + Paraboloid(0.01)(res.x, res.y) - res.approach
    kkt = kkt_residual(res.p, g, displacement_scale=float(np.abs(u).max()), force=20.0,
                       node_area=res.lattice.node_area, hardness=H)
    assert kkt <= 1e-9


def test_a_coated_periodic_cell_with_a_hardness_meets_the_bounded_kkt_conditions():
    cell = bem.PeriodicCell(1.0 / 64, 64, 64)
    h = 0.01 * (2 - np.cos(2 * np.pi * cell.x) - np.cos(2 * np.pi * cell.y / cell.size[1]))
    coating = bem.Coating(0.05, 20e9, 0.3)
    H = 2e9
    res = bem.solve(h, domain=cell, mean_pressure=4e8, coating2=coating, hardness=H, **STEEL)
    assert res.status == "converged" and res.kkt_residual <= 1e-10
    assert 0 < res.plastic_fraction < res.contact_fraction < 1
    op = bem.PeriodicOperator(cell, res.E_star, bodies=bem.Bodies(coating2=coating, **STEEL))
    p = res.p.reshape(cell.shape)
    u = op.matvec(p)
    g = u + h - res.approach
    kkt = kkt_residual(p.ravel(), g.ravel(), displacement_scale=float(np.abs(u).max()), force=res.force,
                       node_area=cell.node_area, hardness=H)
    assert kkt <= 1e-9
