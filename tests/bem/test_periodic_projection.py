"""The direction of the oblique projection of the cell's QP with a compliance per node
(:class:`bem.periodic.qp_parts.Projection`): made by a QP that is given an empty one, used as it is by a QP given a
held one (the answer the same as with its own), and shared by the model QPs of one Newton solve on a cell."""

import numpy as np

import bem.newton as newton
import bem.periodic.qp as periodic_qp
from bem.backend import get_backend
from bem.kkt import kkt_residual
from bem.periodic import PeriodicCell, PeriodicOperator
from bem.periodic.qp import solve_periodic_qp
from bem.periodic.qp_parts import Projection

from .newton_cases import CELL, FORCE, root_law, waves
from .test_periodic_edge import _self_affine

SMALL = PeriodicCell(1.0 / 64, 64, 64)


def _compliance(seed):
    """A compliance per node of the cell ``SMALL``, a fifth of the nodes soft (``D > 4 C_nn``: Jacobi there)."""
    c_nn = PeriodicOperator(SMALL, 1.0).diagonal
    return c_nn * (0.1 + 8.0 * np.random.default_rng(seed).random(SMALL.shape) ** 3)


def _kkt(op, h, D, res, force):
    """The KKT residual of a QP's answer on a product made here, with the layer's ``D p``."""
    u = op.matvec(res.p)
    gap = u + D * res.p + h - res.approach
    return kkt_residual(res.p, gap, displacement_scale=float(np.abs(u + D * res.p).max()), force=force,
                        node_area=SMALL.node_area)


def test_a_qp_given_an_empty_projection_makes_it_and_one_given_a_held_projection_uses_it():
    op, h = PeriodicOperator(SMALL, 1.0), _self_affine(SMALL)
    force = 0.01 * SMALL.area
    made = Projection()
    first = solve_periodic_qp(op, h, force=force, lam=_compliance(1), rtol=1e-10, projection=made)
    assert first.converged and made.values is not None and made.scale > 0
    values, kept = made.values, made.values.copy()
    # another model (another compliance, three times the load: a contact far from the one M 1 was made on)
    D = _compliance(2)
    given = solve_periodic_qp(op, h, force=3 * force, lam=D, rtol=1e-10, projection=made)
    own = solve_periodic_qp(op, h, force=3 * force, lam=D, rtol=1e-10)
    assert made.values is values  # used as it is, not made again
    np.testing.assert_array_equal(made.values, kept)
    assert given.converged and own.converged
    assert np.abs(given.p - own.p).max() <= 1e-8 * own.p.max()
    assert _kkt(op, h, D, given, 3 * force) <= 1e-10


def test_the_projection_holds_its_direction_over_its_largest_magnitude():
    bk = get_backend("cpu")
    m = np.random.default_rng(3).uniform(-2.0, 5.0, (6, 8)).astype(np.float32)
    made = Projection().make(bk, m)
    assert made.values.dtype == np.float16 and made.scale == float(np.abs(m).max())
    nodes = bk.select(m > 0)
    np.testing.assert_allclose(made.at(bk, nodes), m[m > 0], rtol=1e-3, atol=0)  # half precision


def test_the_model_qps_of_a_newton_solve_on_a_cell_share_one_projection_made_once(monkeypatch):
    layer, h, op = root_law(3.0), waves(CELL), PeriodicOperator(CELL, 1.0)
    given, makes = [], []
    solve = periodic_qp.solve_periodic_qp
    make = Projection.make

    def recorded(*a, projection=None, **k):
        given.append(projection)
        return solve(*a, projection=projection, **k)

    monkeypatch.setattr(periodic_qp, "solve_periodic_qp", recorded)
    monkeypatch.setattr(Projection, "make", lambda self, bk, m: makes.append(self) or make(self, bk, m))
    shared = newton.solve_newton(op, h, layer=layer, force=FORCE, x0=np.ones(CELL.shape))
    assert shared.converged and len(given) >= 3
    assert all(p is given[0] for p in given) and isinstance(given[0], Projection)
    assert makes == [given[0]]  # made by the first QP that projects obliquely, used by the rest
    # each model QP with a projection of its own: the same answer
    monkeypatch.delattr(PeriodicOperator, "shared_model_state")
    given.clear()
    own = newton.solve_newton(op, h, layer=layer, force=FORCE, x0=np.ones(CELL.shape))
    assert own.converged and all(p is None for p in given)
    assert np.abs(shared.p - own.p).max() <= 1e-8 * own.p.max()
