"""The KKT residual's test of finiteness and the layered state of a cell (:mod:`bem.kkt`) against their definitions;
the inputs untouched."""

import math

import numpy as np
import pytest

from bem.kkt import kkt_residual, layered_state
from bem.periodic import PeriodicOperator

from .newton_cases import CELL, FORCE, root_law, waves


def _state():
    rng = np.random.default_rng(4)
    p = np.maximum(rng.standard_normal(CELL.shape), 0.0)
    p *= FORCE / CELL.node_area / p.sum()
    op = PeriodicOperator(CELL, 1.0)
    return op, p, op.matvec(p), waves(CELL)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("where", ["p", "gap"])
def test_a_residual_of_a_non_finite_state_is_inf(bad, where):
    p, gap = np.ones(50), np.zeros(50)
    (p if where == "p" else gap)[7] = bad
    assert kkt_residual(p, gap, displacement_scale=1.0) == math.inf


def test_a_finite_state_whose_sum_overflows_keeps_its_residual():
    p, gap = np.ones(4), np.array([1e308, 1e308, 0.0, 0.0])  # sum(gap) overflows, every entry is finite
    assert kkt_residual(p, gap, displacement_scale=1e308) == pytest.approx(1.0)


def test_the_layered_state_of_a_cell_is_its_definition_and_leaves_its_inputs():
    op, p, u, h = _state()
    layer = root_law(3.0)
    closure = layer.w(p)
    given = [a.copy() for a in (p, u, h, closure)]
    gap, delta, kkt = layered_state(op, h, layer, p, u, force=FORCE, closure=closure)
    total = u + layer.w(p)
    want_delta = float(np.mean((total + h)[p > 0]))  # the multiplier of the force: the mean over the contact
    assert delta == pytest.approx(want_delta, rel=1e-14)
    np.testing.assert_allclose(gap, total + h - want_delta, rtol=0, atol=1e-15 * np.abs(total).max())
    assert kkt == pytest.approx(kkt_residual(p, total + h - want_delta, displacement_scale=float(np.abs(total).max()),
                                             force=FORCE, node_area=CELL.node_area), rel=1e-12)
    for now, before in zip((p, u, h, closure), given):
        np.testing.assert_array_equal(now, before)
