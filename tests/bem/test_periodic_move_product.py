"""The update of ``u = (C + lam) p`` after a step of the periodic QP that changed the contact, in double precision:
from the single-precision product of the step's own move (:meth:`bem.periodic.qp_parts.ContactBrick.write_move`)
instead of a double-precision product of ``p``. Against the QP that recomputes ``u`` at every change (the move's
brick refused), the dense matrix and the KKT conditions; the brick's edits against their definition."""

import math

import numpy as np
import pytest

import bem.periodic.qp as qp
from bem.backend import get_backend
from bem.kkt import kkt_residual
from bem.periodic import PeriodicCell, PeriodicOperator
from bem.periodic.qp import solve_periodic_qp
from bem.periodic.qp_parts import ContactBrick

from .test_periodic_qp import _self_affine

E_STAR = 1.0


def _brick():
    rng = np.random.default_rng(7)
    brick = ContactBrick(get_backend("cpu"), (6, 8))
    nodes = np.sort(rng.choice(48, 20, replace=False))
    brick.write(nodes, rng.standard_normal(20))
    return brick, nodes


def test_the_move_writes_at_the_clipped_nodes_adds_at_the_entering_ones_and_is_undone():
    brick, nodes = _brick()
    before = brick.values.copy()
    at = np.zeros(20, dtype=bool)
    at[[2, 5, 11]] = True
    off = np.setdiff1d(np.arange(48), nodes)[:4]
    entering = np.sort(np.concatenate([off, nodes[[5]]]))  # one node both clipped and entering
    values, extra = np.array([1.5, -2.0, 3.25]), np.array([0.5, -0.25, 4.0, 1.0, 2.0])
    got = brick.write_move(at, values, entering, extra)
    assert got is brick.values
    want = before.reshape(-1).copy()
    want[nodes[at]] = values
    want[entering] += extra
    np.testing.assert_array_equal(got.reshape(-1), want.astype(np.float32))
    brick.restore()
    np.testing.assert_array_equal(brick.values, before)  # bit for bit, the last write's brick


def test_a_move_beyond_single_precision_writes_nothing():
    brick, nodes = _brick()
    before = brick.values.copy()
    at = np.zeros(20, dtype=bool)
    at[3] = True
    for values, extra in ((np.array([1e39]), None), (np.array([np.nan]), None), (np.array([1.0]), np.array([2e38]))):
        entering = None if extra is None else np.setdiff1d(np.arange(48), nodes)[:1]
        assert brick.write_move(at, values, entering, extra) is None
        np.testing.assert_array_equal(brick.values, before)


def _spy(monkeypatch, op):
    seen = []
    spectrum = op.spectrum
    monkeypatch.setattr(op, "spectrum", lambda v, out=None: seen.append(v.dtype) or spectrum(v, out=out))
    return seen


def _exact_path(monkeypatch):
    monkeypatch.setattr(ContactBrick, "write_move", lambda self, *a: None)


@pytest.mark.parametrize("per_node", [False, True])
def test_changes_in_double_precision_take_the_product_of_the_move(monkeypatch, per_node):
    """Double precision from the start: every change of the contact after the first product updates ``u`` from the
    move's product. The answer is that of the QP that recomputes ``u`` at every change, in about as many
    iterations, with a fraction of its double-precision transforms; its displacement (confirmed) is exact."""
    monkeypatch.setattr(qp, "SINGLE_START", math.inf)
    cell = PeriodicCell(1.0 / 128, 128, 128)
    h = _self_affine(cell)
    force = 0.03 * cell.area
    lam = E_STAR * 0.0 if not per_node else np.random.default_rng(2).uniform(0.2, 2.0, cell.shape) / 128
    op = PeriodicOperator(cell, E_STAR)
    seen = _spy(monkeypatch, op)
    res = solve_periodic_qp(op, h, force=force, lam=lam, rtol=1e-10)
    with monkeypatch.context() as m:
        _exact_path(m)
        ref_op = PeriodicOperator(cell, E_STAR)
        ref_seen = _spy(m, ref_op)
        ref = solve_periodic_qp(ref_op, h, force=force, lam=lam, rtol=1e-10)
    assert res.converged and ref.converged
    changes = sum(c > 0 for c in ref.history["changes"])
    assert changes >= 15  # the contact moves in many iterations
    assert ref_seen.count(np.float64) >= changes and seen.count(np.float64) <= 4
    assert abs(res.iterations - ref.iterations) <= 2
    # the same iterates to the rounding of u while the contact moves (a direction left with t' in it departs at once)
    early = np.array(res.history["residual"][:15]) / np.array(ref.history["residual"][:15])
    assert np.abs(early - 1).max() <= 1e-4
    assert np.abs(res.p - ref.p).max() <= 1e-8 * ref.p.max()
    u = PeriodicOperator(cell, E_STAR).matvec(res.p)
    np.testing.assert_allclose(res.displacement, u, rtol=0, atol=1e-12 * np.abs(u).max())
    g = (u + lam * res.p + h - res.approach).ravel()
    kkt = kkt_residual(res.p.ravel(), g, displacement_scale=float(np.abs(u + lam * res.p).max()), force=force,
                       node_area=cell.node_area)
    assert kkt <= 1e-10


def _events(monkeypatch, op):
    """The double-precision transforms of ``op`` and the moves' products, in their order."""
    seen = []
    spectrum, write_move = op.spectrum, ContactBrick.write_move
    monkeypatch.setattr(op, "spectrum", lambda v, out=None: (v.dtype == np.float64 and seen.append("exact")) or
                        spectrum(v, out=out))
    monkeypatch.setattr(ContactBrick, "write_move", lambda self, *a: seen.append("write_move") or write_move(self, *a))
    return seen


@pytest.mark.parametrize("control", ["force", "approach"])
def test_an_unconfirmed_solve_recomputes_u_at_every_change(monkeypatch, control):
    """Newton's model QP (a compliance per node, the caller's start and product, ``confirm=False``) hands its ``u`` to
    the caller unconfirmed: it recomputes ``u`` at a change, never from a move, and its displacement is ``C p``."""
    cell = PeriodicCell(1.0 / 128, 128, 128)
    h = _self_affine(cell)
    op = PeriodicOperator(cell, E_STAR)
    D = np.random.default_rng(5).uniform(0.2, 2.0, cell.shape) * op.diagonal
    kw = dict(force=0.03 * cell.area) if control == "force" else dict(approach=float(np.quantile(h, 0.25)))
    x0 = solve_periodic_qp(op, h, lam=D, rtol=1e-3, **kw).p  # in double precision from the start
    seen = _events(monkeypatch, op)
    res = solve_periodic_qp(op, h, lam=D, x0=x0, u0=op.matvec(x0), rtol=1e-10, confirm=False, **kw)
    changes = sum(c > 0 for c in res.history["changes"])
    assert res.converged and changes >= 2 and res.history["residual"][0] < qp.SINGLE_START * qp.SINGLE_ABOVE
    assert "write_move" not in seen and seen.count("exact") >= changes
    u = PeriodicOperator(cell, E_STAR).matvec(res.p)
    assert np.abs(res.displacement - u).max() <= 1e-9 * np.abs(u).max()


@pytest.mark.parametrize("control", ["force", "approach"])
def test_a_callers_product_is_recomputed_at_the_first_change_before_moves_follow_it(monkeypatch, control):
    """Started in double precision near the answer from a product rounded to single precision, the first change
    recomputes ``u`` before any move's product is taken: the moves carry an exact product, not the caller's error."""
    cell = PeriodicCell(1.0 / 128, 128, 128)
    h = _self_affine(cell)
    op = PeriodicOperator(cell, E_STAR)
    D = np.random.default_rng(5).uniform(0.2, 2.0, cell.shape) * op.diagonal
    kw = dict(force=0.03 * cell.area) if control == "force" else dict(approach=float(np.quantile(h, 0.25)))
    x0 = solve_periodic_qp(op, h, lam=D, rtol=1e-3, **kw).p
    u0 = op.matvec(x0).astype(np.float32).astype(np.float64)  # as Newton's, after a step in single precision
    seen = _events(monkeypatch, op)
    res = solve_periodic_qp(op, h, lam=D, x0=x0, u0=u0, rtol=1e-10, **kw)
    assert res.converged and res.history["residual"][0] < qp.SINGLE_START * qp.SINGLE_ABOVE
    assert "write_move" in seen and seen.index("exact") < seen.index("write_move")
    u = PeriodicOperator(cell, E_STAR).matvec(res.p)
    np.testing.assert_allclose(res.displacement, u, rtol=0, atol=1e-12 * np.abs(u).max())
    g = (u + D * res.p + h - res.approach).ravel()
    kkt = kkt_residual(res.p.ravel(), g, displacement_scale=float(np.abs(u + D * res.p).max()),
                       force=kw.get("force"), node_area=cell.node_area)
    assert kkt <= 1e-10
