"""The first steps of the cell's QP (bem.periodic.qp_parts.EARLY): while the contact moves, a shortened step and the
most open nodes entering first; fewer iterations to the same answer, and only where the rule applies."""

import numpy as np
import pytest

import bem.periodic.qp as qp
import bem.periodic.qp_parts as qp_parts
from bem.backend import backend_of
from bem.periodic import PeriodicCell, PeriodicOperator
from bem.periodic.qp import solve_periodic_qp

from .test_periodic_qp import _self_affine

CELL = PeriodicCell(1.0 / 256, 256, 256)


class _Record:
    def __init__(self, changes):
        self.history = {"changes": changes}


def test_the_first_steps_are_those_that_change_the_contact_early():
    assert qp_parts.early_steps(1, _Record([5]), False)
    assert qp_parts.early_steps(qp_parts.EARLY, _Record([9, 1]), False)
    assert not qp_parts.early_steps(qp_parts.EARLY + 1, _Record([9, 1]), False)  # later
    assert not qp_parts.early_steps(3, _Record([9, 0]), False)  # the last step left the contact as it was
    assert not qp_parts.early_steps(3, _Record([]), False)
    assert not qp_parts.early_steps(3, _Record([9, 4]), True)  # a compliance per node or a hardness


def test_the_most_open_nodes_enter_first():
    """Of the nodes that may enter, those whose gap is below ``ENTER_SHARE`` times the most negative one, with their
    gaps, in order; the inputs untouched."""
    nodes = np.array([3, 8, 20, 41, 77])
    gap = np.array([-1.0, -0.31, -0.29, -0.5, -0.01])
    given = nodes.copy(), gap.copy()
    kept, kept_gap = qp_parts.most_open(backend_of(gap), nodes, gap)
    assert np.array_equal(kept, [3, 8, 41]) and np.array_equal(kept_gap, [-1.0, -0.31, -0.5])
    assert np.array_equal(nodes, given[0]) and np.array_equal(gap, given[1])


def _solve(monkeypatch, early, force, **kw):
    monkeypatch.setattr(qp_parts, "EARLY", early)
    op = PeriodicOperator(CELL, 1.0)
    return solve_periodic_qp(op, _self_affine(CELL), force=force * CELL.area, rtol=1e-10, **kw)


@pytest.mark.parametrize("force", [0.01, 0.03, 0.1])
def test_the_first_steps_take_fewer_iterations_to_the_same_answer(monkeypatch, force):
    """The 256^2 self-affine cell from its uniform start, at three loads (5-60 % of the nodes in contact): the rule
    takes fewer iterations (measured: 39, 51, 32 against 40, 52, 38) to the answer of the loop without it."""
    with_rule, without = _solve(monkeypatch, qp_parts.EARLY, force), _solve(monkeypatch, 0, force)
    assert with_rule.converged and without.converged
    assert with_rule.iterations < without.iterations
    assert np.abs(with_rule.p - without.p).max() <= 1e-8 * without.p.max()


@pytest.mark.parametrize("share", ["step", "enter"])
def test_each_half_of_the_rule_acts(monkeypatch, share):
    """Neither half is idle: without the shortened step, or with every open node entering, the iterations differ."""
    default = _solve(monkeypatch, qp_parts.EARLY, 0.03).iterations
    if share == "step":
        monkeypatch.setattr(qp, "STEP_SHARE", 1.0)
    else:
        monkeypatch.setattr(qp_parts, "ENTER_SHARE", 0.0)
    assert _solve(monkeypatch, qp_parts.EARLY, 0.03).iterations != default


def test_a_compliance_per_node_takes_the_steps_as_before(monkeypatch):
    """Newton's model QPs (a compliance per node) keep the plain steps: the same iterations with and without it."""
    rng = np.random.default_rng(5)
    op = PeriodicOperator(CELL, 1.0)
    D = op.diagonal * np.where(rng.random(CELL.shape) < 0.2, 30.0, 0.5)
    counts = [_solve(monkeypatch, early, 0.03, lam=D).iterations for early in (qp_parts.EARLY, 0)]
    assert counts[0] == counts[1]
