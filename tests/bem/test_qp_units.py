"""The constrained CG of the half-space (:func:`bem.kalker.solve_qp`) takes the same path in every system of units.

A rough sphere on a half-space region, solved in SI units and in units of order one (lengths, ``E*`` and the force
scaled together), with and without the FFT preconditioner, and with a root layer (Newton's model QPs, a compliance per
node): the same iterations and the same scaled pressure to round-off. Nodes enter the contact in the first iterations
of each lattice (53, 22, 8 and 6 nodes in four of the finest lattice's 14), so the rule that gives them their pressure
(:func:`bem.cg_rules.entering_pressure`) is what this checks: a rule that mixed a length with a pressure would give
the two runs different paths, and answers that differ by the tolerance rather than by round-off. Newton's runs are in
units that are powers of two, where the two paths of a rule that is the same in every system of units are equal bit
for bit.
"""

from __future__ import annotations

import numpy as np
import pytest

import bem


def _rough_sphere(L):
    """A sphere of radius ``L`` with two ripples of amplitude ``2e-4 L`` on it: a gap in the units of ``L``."""
    def gap(x, y):
        xs, ys = x / L, y / L
        ripples = np.cos(2 * np.pi * xs / 0.05 + 1) * np.cos(2 * np.pi * ys / 0.07) + np.sin(2 * np.pi * xs / 0.031)
        return L * ((xs * xs + ys * ys) / 2 + 2e-4 * ripples)

    return gap


def _solve(L, E, precondition):
    return bem.solve(_rough_sphere(L), E_star=E, force=3e-3 * E * L * L, step=L / 96, extent=(L, L),
                     precondition=precondition)


@pytest.mark.parametrize("precondition", [True, False])
def test_a_rough_sphere_takes_the_same_path_in_si_units_and_in_units_of_order_one(precondition):
    one = _solve(1.0, 1.0, precondition)
    si = _solve(1e-3, 115e9, precondition)  # a 1 mm sphere of steel on steel
    assert one.status == si.status == "converged", (one.message, si.message)
    assert one.iterations == si.iterations
    assert one.n_matvec == si.n_matvec
    assert 0.02 < one.contact_area < 0.5  # a fraction of the region (side 1)
    # the same path: the scaled pressures agree to round-off (measured 1.3e-14 and 2.1e-14 of p_max), far below the
    # tolerance's 1e-10; entering pressures of -tau g in the preconditioned step (a length for a pressure) gave 1.9e-11
    assert np.abs(si.p / 115e9 - one.p).max() <= 1e-12 * one.p_max


@pytest.mark.parametrize("k", [1e-3, 1e-2])
def test_newton_on_a_root_layer_takes_the_same_path_in_si_units_and_in_units_of_order_one(k):
    # the model QPs have a compliance per node: their entering nodes take their whole Jacobi estimate. The units are
    # powers of two near SI (a sphere of 2^-10 m, about 1 mm, of carbide on carbide, E* = 2^38 Pa, about 275 GPa), in
    # which every length, pressure and compliance of the two runs scale exactly: a rule that is the same in every
    # system of units gives the same path bit for bit, and one that mixes a length with a pressure a path that
    # differs by whole factors. With factors that are not powers of two the path at k = 1e-3 amplifies round-off
    # to the size such a rule gave when it was found (2.9e-12 of p_max): the gap times 1 + 2^-52, 1 - 2^-53 or
    # 1 + 2^-50 moves the answer of the order-one run by 2.4e-11 to 4.6e-11 of p_max, the same iterations
    # (docs/performance.md)
    L, E = 2.0**-10, 2.0**38

    def solve(L, E):
        return bem.solve(_rough_sphere(L), E_star=E, force=3e-3 * E * L * L, step=L / 96, extent=(L, L),
                         layer=bem.layers.Root(k * L / np.sqrt(E)))  # w = k L sqrt(p / E*)

    one, si = solve(1.0, 1.0), solve(L, E)
    assert one.status == si.status == "converged", (one.message, si.message)
    assert one.history["inner_iterations"] == si.history["inner_iterations"]
    assert one.n_matvec == si.n_matvec
    np.testing.assert_array_equal(si.p / E, one.p)
    np.testing.assert_array_equal(si.approach / L, one.approach)
