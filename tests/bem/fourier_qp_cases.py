"""The periodic cell's QP in the Fourier basis (bem.periodic.qp) on NumPy and on another array namespace:
the cases and the comparison of tests/bem/test_backend_namespace.py (array_api_strict) and
tests/bem/test_gpu.py (CuPy); a small cell's QP and the check that two ways to the same iteration gave the same
solution bit for bit (tests/bem/test_periodic_qp_parts.py, tests/bem/test_periodic_passes.py)."""

import math

import numpy as np
import pytest

import bem.backend
import bem.kalker
import bem.newton
from bem import layers
from bem.periodic import PeriodicCell, PeriodicOperator, solve_periodic

CASES = ["smooth", "newton_root", "hardness", "coated"]
CELL = PeriodicCell(1.0 / 32, 32, 32)
COATING = dict(E1=1.0, nu1=0.3, E2=1.0, nu2=0.3)


def rough(cell, seed=7):
    """A smooth periodic gap of four random modes, smallest value 0 [length]."""
    rng = np.random.default_rng(seed)
    h = np.zeros(cell.shape)
    for _ in range(4):
        kx, ky = rng.integers(1, 4, size=2)
        h += rng.uniform(0.2, 1.0) * np.cos(2 * math.pi * (kx * cell.x / cell.size[0] + ky * cell.y / cell.size[1])
                                            + rng.uniform(0, 2 * math.pi))
    return h - h.min()


def _newton_model(h, step=3):
    """``(b, D, x0)`` of the model QP of Newton step ``step`` of the root layer on :data:`CELL` (NumPy): its gap
    ``b = h + w(p) - D p`` as an array, a compliance per node ``D`` (float32, as Newton makes it), stiff on the
    contact and soft (``D > 4 C_nn``) at the open nodes."""
    models = []
    model_qp = bem.newton._model_qp

    def spy(op, h, layer, D, contact, on, precondition, p, u, periodic, **kw):
        b = h + layer.w(p) - D * p
        models.append((b, D.copy(), p.copy()))
        return model_qp(op, h, layer, D, contact, on, precondition, p, u, periodic, **kw)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(bem.newton, "_model_qp", spy)
        solve_periodic(h, step=CELL.step, E_star=1.0, mean_pressure=2.0, layer=layers.Root(0.2), nested=False)
    return models[step - 1]


def compare(case, device, to_device, monkeypatch):
    """The QP of ``case`` on NumPy and on ``device`` (its arrays made by ``to_device``), checked to take the same
    iterations: the KKT residual of each iterate above ``1e-5`` to 1 %, before the rounding of other
    single-precision transforms (1e-7) has grown through the iterations, the same count to rtol = 1e-10, and
    the answer to 1e-10; never the general loop. Returns the device's solution."""
    h, kw = rough(CELL), dict(force=2.0 * CELL.size[0] * CELL.size[1], rtol=1e-10)
    bodies = bem.Bodies(**COATING, coating1=bem.Coating(0.2, 3.0, 0.3)) if case == "coated" else None
    E_star = bodies.E_star if bodies is not None else 1.0
    if case == "newton_root":
        h, D, x0 = _newton_model(h)
        kw |= dict(lam=D, x0=x0)
        assert 0 < np.count_nonzero(D > 4 * PeriodicOperator(CELL, 1.0).diagonal) < D.size  # soft and stiff nodes
    elif case == "hardness":
        kw |= dict(hardness=4.0)
    ref = PeriodicOperator(CELL, E_star, bodies=bodies).qp(h, **kw)

    def general_loop(*args, **kwargs):
        raise AssertionError("the general constrained CG ran")

    monkeypatch.setattr(bem.kalker, "constrained_cg", general_loop)
    on_device = {k: to_device(v) if isinstance(v, np.ndarray) else v for k, v in kw.items()}
    res = PeriodicOperator(CELL, E_star, device=device, bodies=bodies).qp(to_device(h), **on_device)
    assert ref.converged and res.converged and ref.iterations > 8
    assert res.iterations == ref.iterations
    residual = np.array(ref.history["residual"])
    early = residual > 1e-5
    assert np.abs(np.array(res.history["residual"])[early] / residual[early] - 1).max() < 1e-2
    p = bem.backend.to_host(res.p)
    assert np.abs(p - ref.p).max() <= 1e-10 * ref.p.max()
    assert abs(res.approach - ref.approach) <= 1e-10 * abs(ref.approach)
    if case == "hardness":
        assert 0 < np.count_nonzero(ref.p >= 4.0) < np.count_nonzero(ref.p > 0)
    return res


def assert_same_bits(a, b, products_a, products_b):
    """Two solutions of the QP (``bem.cg_rules.QPSolution``) converged with the same pressures, displacement and
    history bit for bit, after the same number of products."""
    assert a.converged and b.converged
    np.testing.assert_array_equal(a.p, b.p)
    np.testing.assert_array_equal(a.displacement, b.displacement)
    assert a.history == b.history
    assert products_a == products_b


def cell_qp(case):
    """``(op, h, kw)``: the QP of a 96 x 96 cell under a smooth two-mode gap at a fifth of full contact, ``case``
    ``"smooth"``, ``"per_node"`` (a compliance per node, soft at every seventh node), ``"hardness"`` or ``"coated"``
    (a stiff coating on the substrate), to ``rtol = 1e-11``."""
    cell = PeriodicCell(1.0 / 96, 96, 96)
    x, y = cell.x, cell.y
    lx, ly = cell.size
    h = 0.01 * (2 - np.cos(2 * np.pi * x / lx) - np.cos(2 * np.pi * (x / lx + 2 * y / ly)))
    h += 0.002 * np.sin(2 * np.pi * (3 * x / lx + 5 * y / ly))
    bodies = bem.Bodies(1.0, 0.3, math.inf, 0.0, bem.Coating(0.05, 10.0, 0.25)) if case == "coated" else None
    op = PeriodicOperator(cell, 1.0 if bodies is None else bodies.E_star, bodies=bodies)
    kw = dict(force=0.2 * cell.area * 0.01, rtol=1e-11)
    if case == "per_node":
        kw["lam"] = np.where(np.arange(h.size).reshape(h.shape) % 7 == 0, 20.0, 0.5) * op.diagonal
    elif case == "hardness":
        kw["hardness"] = 0.03
    return op, h, kw
