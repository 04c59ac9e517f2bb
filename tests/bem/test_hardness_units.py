"""The bounded constrained CG (``hardness=H``) is free of units, and carries the force on rough cells in SI units.

The same bounded problem in SI units and in units of order one (``E*``, ``h``, ``H`` and the load scaled
together) takes the same iterations and gives the same scaled answer, on the half-space region (the
general step, :func:`bem.kalker.solve_qp`) and on a periodic cell (:func:`bem.periodic.qp.solve_periodic_qp`).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import bem
from bem.gaps import Paraboloid
from bem.rough import self_affine


def _hertz(E_star, force, R):
    a = (3 * force * R / (4 * E_star)) ** (1 / 3)
    return a, 3 * force / (2 * math.pi * a * a)


@pytest.mark.parametrize("precondition", [True, False])
def test_a_bounded_sphere_on_the_half_space_does_not_depend_on_the_units(precondition):
    E, P, R = 115e9, 100.0, 0.01  # SI: a = 131 um, p0 = 2.8 GPa
    a, p0 = _hertz(E, P, R)
    si = bem.solve(Paraboloid(R), E_star=E, force=P, step=2 * a / 24, extent="auto", hardness=0.5 * p0,
                   precondition=precondition)
    one = bem.solve(Paraboloid(R), E_star=1.0, force=P / E, step=2 * a / 24, extent="auto", hardness=0.5 * p0 / E,
                    precondition=precondition)
    assert si.status == one.status == "converged", (si.message, one.message)
    assert abs(si.iterations - one.iterations) <= 1 and si.iterations <= 40  # measured 14 and 14
    assert si.plastic_area > 0
    assert np.abs(si.p / E - one.p).max() <= 1e-8 * one.p_max
    assert si.approach == pytest.approx(one.approach, rel=1e-8)


def _cell_gap():
    """The gap of a seeded self-affine 100 um cell (rms slope 0.1) on a 64-column lattice, and its step [m]."""
    lattice = self_affine((64, 64), (1e-4, 1e-4), hurst=0.8, rms_slope=0.1, seed=1).to_lattice(64)
    return lattice.heights.max() - lattice.heights, lattice.step


def test_a_bounded_rough_cell_in_si_units_converges_as_in_units_of_order_one():
    h, step = _cell_gap()
    E, H, pbar = 115e9, 3e9, 5.34e8  # 18 % of H: about a fifth of the cell flows
    si = bem.solve_periodic(h, step=step, E_star=E, mean_pressure=pbar, hardness=H, rtol=1e-8)
    one = bem.solve_periodic(h, step=step, E_star=1.0, mean_pressure=pbar / E, hardness=H / E, rtol=1e-8)
    assert si.status == one.status == "converged", (si.message, one.message)
    assert abs(si.iterations - one.iterations) <= 2 and si.iterations <= 60  # measured 19 and 19
    assert 0 < si.plastic_fraction < si.contact_fraction < 1
    assert np.abs(si.p / E - one.p).max() <= 1e-6 * one.p_max
