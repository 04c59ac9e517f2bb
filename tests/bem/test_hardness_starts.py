"""The starts of a bounded solve (``hardness=H``): a warm start whose loaded nodes cannot carry the new load
below ``H`` is helped by the nodes of smallest gap, and gives the answer of a cold start."""

from __future__ import annotations

import numpy as np
import pytest

import bem
from .test_hardness import CELL, _rough


@pytest.fixture(scope="module")
def layered():
    h, layer = _rough(CELL), bem.layers.Power(0.1, 0.5)
    soft = bem.solve_periodic(h, step=CELL.step, E_star=1.0, mean_pressure=0.02, layer=layer)
    H = 0.5 * soft.p_max
    low = bem.solve_periodic(h, step=CELL.step, E_star=1.0, mean_pressure=2e-4, hardness=H, layer=layer)
    assert low.status == "converged" and np.count_nonzero(low.p) * H / low.p.size < 0.0098  # cannot carry 0.0098
    return h, layer, H, low


@pytest.mark.parametrize("pbar", [0.0098, 0.02])
def test_a_warm_start_that_cannot_carry_the_load_below_the_hardness(layered, pbar):
    h, layer, H, low = layered
    cold = bem.solve_periodic(h, step=CELL.step, E_star=1.0, mean_pressure=pbar, hardness=H, layer=layer)
    warm = bem.solve_periodic(h, step=CELL.step, E_star=1.0, mean_pressure=pbar, hardness=H, layer=layer,
                              x0=low.p.reshape(h.shape))
    assert cold.status == warm.status == "converged", warm.message
    assert warm.method == "newton" and "approach-controlled" not in warm.message
    assert warm.iterations <= 2 * cold.iterations + 2  # measured 9 and 7 (cold 8 and 7)
    assert warm.mean_pressure == pytest.approx(pbar, rel=1e-12)
    assert np.abs(warm.p - cold.p).max() <= 1e-6 * H


def test_the_rigid_plastic_start_fills_the_nodes_of_smallest_gap_at_the_hardness():
    from bem.plastic import plastic_start

    h = np.array([[0.3, 0.1, 0.2], [0.0, 0.5, 0.4]])
    mask = np.ones(h.shape, dtype=bool)
    p = plastic_start(np, h, 2.5, 1.0, mask)
    np.testing.assert_array_equal(p, [[0.0, 1.0, 0.5], [1.0, 0.0, 0.0]])
    assert plastic_start(np, h, 6.5, 1.0, mask) is None  # six nodes carry at most 6 H
