"""The line search of a Newton step (:func:`bem.newton_moves.line_search`): the step ``t`` that minimises the
functional along ``d = q - p``, checked against the slope and the functional made by their definitions with whole
products."""

import numpy as np
import pytest

import bem
from bem.backend import get_backend
from bem.newton_moves import line_search, step_nodes
from bem.periodic import PeriodicOperator

from .newton_cases import CELL, FORCE, phi, root_law, waves


def _slope(op, layer, h, p, d, delta):
    """``d.grad Phi(p)`` by its definition: ``d.(C p + w(p) + h - delta)``, every node."""
    return float(np.sum(d * (op.matvec(p) + layer.w(p) + h - delta)))


def _search(bk, layer, p, q, u, uq, h, delta, mask):
    return line_search(bk, layer, step_nodes(bk, p, q, u, uq, h, mask), delta)


def _case(seed, overshoot):
    """A pressure ``p``, a model's answer ``q`` (nodes released, nodes entering) and the gap of the cell's waves,
    with ``q`` ``overshoot`` times a descent step from ``p``, so that the minimum along ``d`` lies inside (0, 1)."""
    rng = np.random.default_rng(seed)
    op, h = PeriodicOperator(CELL, 1.0), waves(CELL)
    layer = root_law(3.0)
    p = np.where(h < np.quantile(h, 0.3), rng.uniform(0.5, 1.5, CELL.shape), 0.0) * FORCE / CELL.area
    delta = float(np.mean((op.matvec(p) + layer.w(p) + h)[p > 0]))
    grad = op.matvec(p) + layer.w(p) + h - delta
    q = np.maximum(p - overshoot * grad / bem.diagonal_coefficient(CELL.step, 1.0), 0.0)
    return op, layer, h, p, q, delta


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_step_is_the_minimiser_of_the_functional_along_the_direction(seed):
    op, layer, h, p, q, delta = _case(seed, overshoot=3.0)
    before = (p.copy(), q.copy(), h.copy())
    u, uq = op.matvec(p), op.matvec(q)
    bk = get_backend("cpu")
    t = _search(bk, layer, p, q, u, uq, h, delta, None)
    d = q - p
    assert 0.0 < t < 1.0
    # the slope by its definition changes sign at t, and t is within 1e-9 of its root
    assert _slope(op, layer, h, p + (t - 1e-9) * d, d, delta) < 0 < _slope(op, layer, h, p + (t + 1e-9) * d, d, delta)
    assert abs(_slope(op, layer, h, p + t * d, d, delta)) <= 1e-7 * abs(_slope(op, layer, h, p, d, delta))
    at_t = phi(op, layer, h, p + t * d, delta)
    assert at_t <= min(phi(op, layer, h, p + (t + s) * d, delta) for s in (-1e-3, 1e-3, -t, 1 - t))
    # the inputs are not modified; a mask of every node gives the same step
    for a, b in zip((p, q, h), before):
        np.testing.assert_array_equal(a, b)
    assert _search(bk, layer, p, q, u, uq, h, delta, np.ones(CELL.shape, dtype=bool)) == t


def test_the_full_step_where_the_functional_falls_all_the_way_and_none_where_it_rises():
    op, layer, h, p, q, delta = _case(0, overshoot=0.05)
    bk = get_backend("cpu")
    d = q - p
    assert _slope(op, layer, h, q, d, delta) < 0  # still descending at the model's answer
    assert _search(bk, layer, p, q, op.matvec(p), op.matvec(q), h, delta, None) == 1.0
    # the direction reversed: no descent
    back = np.maximum(p - d, 0.0)
    assert _search(bk, layer, p, back, op.matvec(p), op.matvec(back), h, delta, None) == 0.0


def test_a_mask_leaves_the_nodes_off_it_out_of_the_slope():
    # the nodes off the mask move too here; the step is the minimiser along d restricted to the mask
    op, layer, h, p, q, delta = _case(1, overshoot=3.0)
    mask = np.ones(CELL.shape, dtype=bool)
    mask[: CELL.shape[0] // 2] = False
    bk = get_backend("cpu")
    u, uq = op.matvec(p), op.matvec(q)
    t = _search(bk, layer, p, q, u, uq, h, delta, mask)
    d = np.where(mask, q - p, 0.0)  # the slope on the mask: d.(C p + t C (q - p) + w(p + t d) + h - delta) there

    def slope(s):
        return float(np.sum(d * (u + s * (uq - u) + layer.w(p + s * d) + h - delta)))

    assert 0.0 < t < 1.0 and t != _search(bk, layer, p, q, u, uq, h, delta, None)
    assert slope(t - 1e-9) < 0 < slope(t + 1e-9)
