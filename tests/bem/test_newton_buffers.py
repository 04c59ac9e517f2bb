"""Newton's arrays (:mod:`bem.newton`): the step consumes the model's solution in place and the iterate may live
in the caller's start, with the numbers of the plain formulas and the caller's arrays as documented."""

import numpy as np
import pytest

import bem
from bem import layers
from bem.backend import get_backend
from bem.cg_rules import QPSolution
from bem import newton
from bem.periodic import PeriodicOperator
from bem.plastic import clip

from .newton_cases import CELL, waves

LAYER = layers.Root(0.3 * bem.diagonal_coefficient(CELL.step, 1.0))


def _plain(p, u, q, uq, t, force, area, hardness):
    """The step's formulas on new arrays."""
    new = clip(np, p + t * (q - p), hardness)
    if force is not None and hardness is None:
        new = new * (force / area / float(np.sum(new)))
    return new, u + t * (uq - u)


@pytest.mark.parametrize("force, hardness", [(None, None), (0.5, None), (None, 0.8)])
@pytest.mark.parametrize("writeable", [True, False])
def test_the_step_is_the_plain_formula_bit_for_bit_in_the_models_buffers(force, hardness, writeable):
    rng = np.random.default_rng(1)
    p, u, q, uq = (rng.standard_normal((9, 11)) for _ in range(4))
    p, q = np.abs(p), np.maximum(q, 0.0)
    keep = [x.copy() for x in (p, u, q, uq)]
    want = _plain(p, u, q, uq, 0.37, force, 0.01, hardness)
    if not writeable:
        q.flags.writeable = uq.flags.writeable = False
    sub = QPSolution(p=q, approach=0.0, iterations=1, converged=True, message="", status="converged",
                     kkt_residual=0.0, displacement=uq, history={})
    new_p, new_u = newton._advance(get_backend("cpu"), p, u, sub, 0.37, force, 0.01, hardness)
    assert np.array_equal(new_p, want[0]) and np.array_equal(new_u, want[1])
    np.testing.assert_array_equal(p, keep[0])  # the iterate and its product are not written
    np.testing.assert_array_equal(u, keep[1])
    if writeable:  # the model's solution and its product became the step's
        assert new_p is q and new_u is uq
    else:
        np.testing.assert_array_equal(q, keep[2])
        np.testing.assert_array_equal(uq, keep[3])


def _newton(x0, **kw):
    op = PeriodicOperator(CELL, 1.0)
    return newton.solve_newton(op, waves(CELL), layer=LAYER, force=0.02, x0=x0, **kw)


def test_newton_holds_its_iterate_in_a_start_it_may_overwrite():
    x0 = np.full(CELL.shape, 0.02 / CELL.area)
    plain = _newton(x0.copy())
    steps = []
    held = _newton(x0, overwrite_x0=True, callback=lambda k, p: steps.append(p))
    assert plain.converged and held.converged and held.iterations == plain.iterations >= 2
    assert held.p is x0 and np.array_equal(held.p, plain.p)
    # the callback gets each step's pressure as it was, not the array that goes on changing
    assert len(steps) == held.iterations and not any(np.shares_memory(s, x0) for s in steps)
    assert not np.array_equal(steps[0], steps[-1]) and np.array_equal(steps[-1], held.p)


@pytest.mark.parametrize("start", ["float32", "read-only", "no overwrite"])
def test_newton_leaves_a_start_it_may_not_hold_its_iterate_in(start):
    x0 = np.full(CELL.shape, 0.02 / CELL.area, dtype=np.float32 if start == "float32" else np.float64)
    x0.flags.writeable = start != "read-only"
    keep = x0.copy()
    res = _newton(x0, overwrite_x0=start != "no overwrite")
    assert res.converged and res.p is not x0
    np.testing.assert_array_equal(x0, keep)


def _half_space_case():
    """A sphere on a half-space region with a root layer: ``(op, h, force)``."""
    region = bem.HalfSpaceRegion(step=0.02, extent=0.3)
    lat = region.lattice()
    return bem.InfluenceOperator(lat, 1.0), region.nodal_gap(bem.gaps.Paraboloid(1.0), lat), 0.01


@pytest.mark.parametrize("domain", ["cell", "half-space"])
def test_the_model_qp_iterates_in_newtons_pressure_which_keeps_its_values(monkeypatch, domain):
    """Each model QP holds its iterate in the array of Newton's pressure (no copy of it through the QP), and Newton
    gets its pressure back with the same values: the solve is the one with the QP's own copy, bit for bit."""
    if domain == "cell":
        op, h, force = PeriodicOperator(CELL, 1.0), waves(CELL), 0.02
    else:
        op, h, force = _half_space_case()
    real, seen = op.qp, []

    def qp(h_, *, x0, **kw):
        before = x0.copy()
        sub = real(h_, x0=x0, **kw)
        seen.append((sub.p is x0, kw.get("overwrite_x0", False), before))
        return sub

    monkeypatch.setattr(op, "qp", qp)
    checks = []
    original = newton._model_qp

    def model_qp(op_, h_, layer, D, contact, on, precondition, p, u, periodic, **kw):
        sub, back, u = original(op_, h_, layer, D, contact, on, precondition, p, u, periodic, **kw)
        checks.append(np.array_equal(back, seen[-1][2]) and back is not sub.p)
        return sub, back, u

    monkeypatch.setattr(newton, "_model_qp", model_qp)
    held = newton.solve_newton(op, h, layer=LAYER, force=force)
    assert held.converged and held.iterations >= 2 and len(seen) == held.iterations
    assert all(in_buffer and overwrite for in_buffer, overwrite, _ in seen) and all(checks)
    monkeypatch.setattr(newton, "in_place", lambda bk, x: False)  # the QP's own copy of the pressure
    seen.clear()
    copied = newton.solve_newton(op, h, layer=LAYER, force=force)
    assert not any(in_buffer for in_buffer, _, _ in seen)
    assert copied.iterations == held.iterations and np.array_equal(copied.p, held.p)
    assert np.array_equal(copied.displacement, held.displacement)


@pytest.mark.parametrize("domain", ["cell", "half-space"])
def test_above_its_size_the_cells_model_qp_holds_its_product_in_newtons_and_newton_makes_it_again(monkeypatch, domain):
    """Where Newton's product ``C p`` on a periodic cell takes more than ``bem.heap.RELEASE_ABOVE`` bytes (here every
    size), each model QP gets ``u`` with ``overwrite_u0`` and iterates in it (no copy of it), and Newton makes ``C p``
    again after, exactly: one product more a step, and the answer of the solve that holds ``u`` to its tolerance (its
    path may differ: its ``u`` is exact at each step, the held one updated). A region's QP, which makes its products
    in new arrays, gets Newton's ``u`` to copy as before: the same solve bit for bit."""
    make = (lambda: (PeriodicOperator(CELL, 1.0), waves(CELL), 0.02)) if domain == "cell" else _half_space_case
    op, h, force = make()
    held = newton.solve_newton(op, h, layer=LAYER, force=force)
    n_held = op.n_matvec
    op, h, force = make()
    reference = make()[0]
    real_qp, real_matvec, given, exact = op.qp, op.matvec, [], []

    def qp(h_, *, u0, **kw):
        before = u0.copy()
        sub = real_qp(h_, u0=u0, **kw)
        given.append((kw.get("overwrite_u0", False), not np.array_equal(u0, before)))
        return sub

    def matvec(p, **kw):
        out = real_matvec(p, **kw)
        if not kw and given and len(exact) < len(given):  # Newton's product after the model's solve
            want = reference.matvec(p)
            exact.append(float(np.max(np.abs(out - want))) / float(np.max(np.abs(want))))
        return out

    monkeypatch.setattr(op, "qp", qp)
    monkeypatch.setattr(op, "matvec", matvec)
    monkeypatch.setattr(newton.heap, "RELEASE_ABOVE", 0)
    handed = newton.solve_newton(op, h, layer=LAYER, force=force)
    assert held.converged and handed.converged and min(handed.iterations, held.iterations) >= 2 and given
    if domain == "half-space":
        assert not any(overwrite or written for overwrite, written in given) and op.n_matvec == n_held
        assert handed.iterations == held.iterations and np.array_equal(handed.p, held.p)
        return
    assert all(overwrite and written for overwrite, written in given)
    assert len(exact) == len(given) and max(exact) == 0.0
    np.testing.assert_allclose(handed.p, held.p, rtol=0, atol=1e-8 * float(np.max(held.p)))
    assert handed.kkt_residual <= 1e-10
