"""The constrained CG of the half-space (:func:`bem.kalker.solve_qp`) keeps its conjugate directions when nodes
enter the contact (Polak-Ribiere+): the answer of a loop written in the test that restarts them, and fewer
iterations than with restarts on a nested self-affine sphere. (On a cell whose contact moves over most iterations
the same rule takes two thirds of the restarted loop's iterations: ``tests/bem/test_periodic_qp.py``.)"""

import numpy as np

import bem
from bem.kalker import solve_qp
from bem.lattice import Lattice

from .restarted_cg import restarted_cg


def _rough_sphere(x, y, seed=3):
    """A sphere of radius 1 with 40 seeded waves of wavenumbers 20-120 (amplitude ``k^-1.8``, rms ``2e-3``)."""
    rng = np.random.default_rng(seed)
    z = np.zeros_like(x)
    for _ in range(40):
        k, angle, phase = rng.uniform(20, 120), rng.uniform(0, np.pi), rng.uniform(0, 2 * np.pi)
        z += k ** -1.8 * np.cos(k * (np.cos(angle) * x + np.sin(angle) * y) + phase)
    return (x * x + y * y) / 2 - 2e-3 * z / np.sqrt(np.mean(z * z))


def test_the_half_space_qp_reaches_the_answer_of_a_loop_that_restarts_its_directions():
    force = 3e-3
    lat = Lattice.from_extent(1 / 192, 0.3)
    op = bem.InfluenceOperator(lat, 1.0)
    h = np.where(lat.mask, _rough_sphere(lat.x, lat.y), 0.0)
    pre = op.preconditioner()
    ref, restarted = restarted_cg(op.matvec, pre, op.diagonal, h, lat.mask, force / lat.node_area)
    sol = solve_qp(op, h, force=force, preconditioner=pre)
    assert sol.converged
    assert sum(sol.history["changes"]) > 50 * sol.iterations  # nodes enter and leave over the iterations
    assert 0.05 < np.mean(ref[lat.mask] > 0) < 0.5 and not ref[lat.border].any()
    # measured 8.8e-10 of p_max, 22 iterations against 26
    assert np.abs(sol.p - ref).max() <= 1e-8 * ref.max()
    assert sol.iterations <= restarted


def _self_affine_sphere():
    """A sphere of radius 1 carrying a seeded self-affine surface (rms slope 0.05) on ``|x|, |y| <= 0.35``."""
    from scipy.interpolate import RegularGridInterpolator

    from bem.rough import self_affine

    z = self_affine((512, 512), (0.7, 0.7), hurst=0.8, rms_slope=0.05, seed=2).heights
    axis = np.linspace(-0.35, 0.35, 512)
    surface = RegularGridInterpolator((axis, axis), z)

    def gap(x, y):
        return (x * x + y * y) / 2 - surface((y, x))

    return gap


def test_the_half_space_qp_keeps_its_directions_when_nodes_enter_the_contact():
    """The nested self-affine sphere, 512 nodes across: 26 finest iterations; restarted where nodes enter, 29; with
    the step ``g.z / t.C t`` along the kept direction instead of its minimum ``g.t / t.C t``, 34."""
    res = bem.solve(_self_affine_sphere(), E_star=1.0, force=3e-3, step=0.6 / 512, extent=0.3)
    assert res.converged and 0.05 < res.contact_area / 0.36 < 0.5
    assert res.iterations <= 27


def test_without_the_preconditioner_the_loop_restarts_where_nodes_enter():
    """Polonsky and Keer's plain loop (``precondition=False``): Fletcher-Reeves directions restarted where nodes
    enter the contact. On the nested self-affine sphere, 256 nodes across, it takes 177 iterations; the directions
    kept across changes of the contact (the rule with the preconditioner) took 327."""
    res = bem.solve(_self_affine_sphere(), E_star=1.0, force=3e-3, step=0.6 / 256, extent=0.3, precondition=False)
    assert res.converged and 0.05 < res.contact_area / 0.36 < 0.5
    assert res.iterations <= 250


def test_the_direction_restarts_where_the_preconditioned_residual_grew():
    """A sphere whose contact grows from a few nodes in its first step, with and without a hardness: 16 and 11
    iterations; keeping the direction where ``g.z`` grew (nodes entered with most of it), 17 and 12."""
    from bem.gaps import Paraboloid

    R, force = 0.01, 100.0 / 115e9  # a steel sphere, lengths in m and pressures in units of E*
    a = (3 * force * R / 4) ** (1 / 3)
    p0 = 3 * force / (2 * np.pi * a * a)
    for hardness, most in ((None, 16), (0.5 * p0, 11)):
        res = bem.solve(Paraboloid(R), E_star=1.0, force=force, step=2 * a / 24, extent="auto", hardness=hardness)
        assert res.converged and res.contact_area > 0
        assert res.iterations <= most
