"""The closure move of a Newton step (:func:`bem.newton_moves.closure_move`): the pressure whose closure is the
model's, kept where it lowers the functional, and Newton's method with it and without it."""

import numpy as np
import pytest

import bem
from bem import layers, newton
from bem.backend import get_backend
from bem.newton_moves import closure_move, model_closure, step_nodes
from bem.periodic import PeriodicOperator

from .newton_cases import CELL, FORCE, phi, root_law, waves


def _solve(layer, **kw):
    op = PeriodicOperator(CELL, 1.0)
    return newton.solve_newton(op, waves(CELL), layer=layer, force=FORCE, **kw)


def _without_move(monkeypatch):
    monkeypatch.setattr(newton, "closure_move", lambda op, layer, p, u, *a, **k: (p, u, False))


@pytest.mark.parametrize("scale", [0.3, 1.0, 3.0, 30.0])
def test_newton_with_the_move_takes_fewer_steps_to_the_same_answer(monkeypatch, scale):
    # from an elastic-dominated (0.3: the move gains little there) to a layer-dominated root layer
    layer = root_law(scale)
    moved = _solve(layer)
    _without_move(monkeypatch)
    plain = _solve(layer)
    assert moved.converged and plain.converged
    assert moved.kkt_residual <= 1e-10 and moved.history["closure_moves"] >= 1
    assert plain.history["closure_moves"] == 0
    assert moved.iterations < plain.iterations if scale >= 1 else moved.iterations <= plain.iterations
    np.testing.assert_allclose(moved.p, plain.p, rtol=0, atol=1e-8 * plain.p.max())


def test_with_the_layer_alone_carrying_the_load_newton_converges_in_a_few_steps(monkeypatch):
    # w' far above C_nn at every contact pressure: the closure move is Newton's method in the closure, where the
    # law is linear; the step along d alone converges linearly from a start decades below the answer
    layer = root_law(1e4)
    x0 = np.random.default_rng(1).uniform(1e-4, 1.0, CELL.shape) ** 3
    moved = _solve(layer, x0=x0.copy())
    _without_move(monkeypatch)
    plain = _solve(layer, x0=x0.copy())
    assert moved.converged and moved.iterations <= 3
    assert plain.converged and plain.iterations >= 2 * moved.iterations


def _moved(op, layer, h, p, u, closure, q, delta):
    """The closure move from ``p`` (``u = C p``) with the model's answer ``q`` and its ``closure`` (brick arrays), as a
    step that has reached ``p`` (``t = 1``, ``C q = u``)."""
    at = step_nodes(get_backend("cpu"), p, q, u, u, h)
    return closure_move(op, layer, p, u, closure.reshape(-1)[at.sel], at.end(1.0), delta, force=FORCE)


def _state(layer, x0):
    op = PeriodicOperator(CELL, 1.0)
    h = waves(CELL)
    p = x0 * (FORCE / CELL.node_area / x0.sum())
    return op, h, p, op.matvec(p)


def test_the_move_to_the_answers_closure_lands_on_the_answer_and_lowers_phi():
    layer = root_law(3.0)
    answer = _solve(layer)
    start = np.random.default_rng(2).uniform(0.5, 1.5, CELL.shape)
    op, h, p, u = _state(layer, start)
    delta = answer.approach
    before = phi(op, layer, h, p, delta)
    new_p, new_u, moved = _moved(op, layer, h, p.copy(), u.copy(), layer.w(answer.p), answer.p, delta)
    assert moved
    np.testing.assert_allclose(new_p, answer.p, rtol=0, atol=1e-12 * answer.p.max())
    np.testing.assert_allclose(new_u, op.matvec(new_p), rtol=0, atol=1e-12 * np.abs(new_u).max())
    assert phi(op, layer, h, new_p, delta) < before
    assert CELL.node_area * new_p.sum() == pytest.approx(FORCE, rel=1e-13)


def test_a_move_that_raises_phi_is_not_taken_and_leaves_the_state():
    layer = root_law(3.0)
    answer = _solve(layer)
    op, h, p, u = _state(layer, answer.p.copy())
    keep = p.copy(), u.copy()
    worse = np.random.default_rng(3).uniform(0.5, 1.5, CELL.shape)
    new_p, new_u, moved = _moved(op, layer, h, p, u, layer.w(worse), worse, answer.approach)
    assert not moved and new_p is p and new_u is u
    np.testing.assert_array_equal(p, keep[0])
    np.testing.assert_array_equal(u, keep[1])


def test_released_nodes_go_to_zero_and_a_rigid_branch_keeps_its_pressure():
    p_cr = FORCE / CELL.area
    layer = layers.ElasticRigid(3.0 * bem.diagonal_coefficient(CELL.step, 1.0), p_cr)
    answer = _solve(layer)
    op, h, p, u = _state(layer, np.random.default_rng(4).uniform(0.5, 1.5, CELL.shape))
    rigid = np.zeros(CELL.shape, bool)
    rigid[::5] = True
    released = ~(answer.p > 0)
    released[1::5, ::2] = True
    # towards the answer's closure, beyond the rigid limit (no finite w^-1) at some nodes
    closure = np.where(rigid, 2.0 * layer.w(p_cr), layer.w(answer.p))
    # the move by its definition, and the functional's change by the definition of Phi
    want = np.where(released, 0.0, np.where(rigid, p, layer.inverse(layer.w(answer.p))))
    want *= FORCE / CELL.node_area / want.sum()
    assert phi(op, layer, h, want, 0.0) < phi(op, layer, h, p, 0.0)
    new_p, new_u, moved = _moved(op, layer, h, p.copy(), u.copy(), closure, np.where(released, 0.0, 1.0), 0.0)
    assert moved
    np.testing.assert_allclose(new_p, want, rtol=1e-13, atol=1e-15 * want.max())
    np.testing.assert_allclose(new_u, op.matvec(new_p), rtol=0, atol=1e-12 * np.abs(new_u).max())


def test_the_models_closure_is_its_formula_at_the_steps_nodes():
    layer = root_law(3.0)
    rng = np.random.default_rng(6)
    p, q, u, uq = (np.where(rng.random((9, 11)) < 0.6, rng.uniform(0.0, 2.0, (9, 11)), 0.0) for _ in range(4))
    D = rng.uniform(0.0, 2.0, (9, 11)).astype(np.float32)
    keep = p.copy(), q.copy(), D.copy()
    at = step_nodes(get_backend("cpu"), p, q, u, uq, np.zeros((9, 11)))
    on = (p > 0) | (q > 0)  # the step's nodes: pressure before or after it
    np.testing.assert_array_equal(at.sel, np.flatnonzero(on))
    want = layer.w(p[on]) + 0.7 * D[on].astype(np.float64) * (q[on] - p[on])
    out = model_closure(get_backend("cpu"), layer, at, D, 0.7)
    assert out.dtype == np.float64
    np.testing.assert_allclose(out, want, rtol=1e-15, atol=0)
    for given, kept_copy in zip((p, q, D), keep):
        np.testing.assert_array_equal(given, kept_copy)


def test_a_steep_power_law_on_a_sphere_converges_in_a_few_steps(monkeypatch):
    # w = 0.05 p^0.05: w' spans decades over the contact, the case Newton's steps along d take longest on
    def sphere():
        return bem.solve(bem.gaps.Paraboloid(1.0), E_star=1.0, force=4 * 0.1**3 / 3, step=1 / 32, extent=0.5,
                         layer=layers.Power(0.05, 0.05))

    moved = sphere()
    _without_move(monkeypatch)
    plain = sphere()
    assert moved.converged and plain.converged and moved.kkt_residual <= 1e-10
    assert moved.iterations <= 6 and plain.iterations >= 2 * moved.iterations
    np.testing.assert_allclose(moved.p, plain.p, rtol=0, atol=1e-8 * plain.p.max())


def test_after_a_partial_step_the_move_is_taken_exactly_where_it_lowers_phi():
    # the step t = 0.4 from p0 towards q; the move's candidates from the answer's closure (s = 0) to a worse one (1)
    layer = root_law(3.0)
    answer = _solve(layer)
    op, h = PeriodicOperator(CELL, 1.0), waves(CELL)
    rng = np.random.default_rng(7)
    p0 = answer.p + rng.uniform(0.5, 1.5, CELL.shape) * FORCE / CELL.area
    p0 *= FORCE / CELL.node_area / p0.sum()  # the force of q: Phi's change does not depend on delta
    q, t = answer.p, 0.4
    p = p0 + t * (q - p0)
    at = step_nodes(get_backend("cpu"), p0, q, op.matvec(p0), op.matvec(q), h)
    worse = rng.uniform(0.0, 1.0, CELL.shape) ** 4 * 10 * FORCE / CELL.area

    def candidate(s):
        closure = (1 - s) * layer.w(answer.p) + s * layer.w(worse)
        want = np.where(q > 0, layer.inverse(closure), 0.0)
        return closure, want * (FORCE / CELL.node_area / want.sum())

    def taken(s):  # the move, checked against its definition where taken
        closure, want = candidate(s)
        new_p, new_u, moved = closure_move(op, layer, p.copy(), op.matvec(p), closure.reshape(-1)[at.sel], at.end(t),
                                           answer.approach, force=FORCE)
        np.testing.assert_allclose(new_p, want if moved else p, rtol=1e-12, atol=1e-15 * p.max())
        np.testing.assert_allclose(new_u, op.matvec(new_p), rtol=0, atol=1e-12 * np.abs(new_u).max())
        return moved

    def lower(s):  # Phi by its definition
        return phi(op, layer, h, candidate(s)[1], 0.0) < phi(op, layer, h, p, 0.0)

    def edge(test):  # where test switches from True (s = 0) to False (s = 1), by bisection
        a, b = 0.0, 1.0
        assert test(a) and not test(b)
        for _ in range(30):
            a, b = ((a + b) / 2, b) if test((a + b) / 2) else (a, (a + b) / 2)
        return a

    assert abs(edge(taken) - edge(lower)) <= 1e-8
