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


def _residual_by_definition(p, gap, s, force, node_area):
    """The KKT residual written out (bem.kkt's docstring), with NumPy's own passes."""
    contact = p > 0
    parts = [max(0.0, -p.min()) / p.max() if p.max() > 0 else 0.0,
             np.abs(gap[contact]).max(initial=0.0) / s, max(0.0, -gap[~contact].min(initial=0.0)) / s]
    return max(parts + ([abs(node_area * p.sum() - force) / force] if force is not None else []))


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("case", ["mixed", "all_in_contact", "none_in_contact", "negative"])
def test_the_residual_of_a_large_state_is_its_definition(case, threads):
    """On arrays of ``bem.extremes.MIN_NODES`` entries and more (the extremes in one pass, compiled where numba is
    installed, in parts on the threads) the residual is the one written out with NumPy's passes, exactly; the inputs
    untouched."""
    from bem import extremes, fft

    rng = np.random.default_rng(9)
    n = extremes.MIN_NODES + 1001
    p = {"mixed": np.maximum(rng.standard_normal(n), 0.0), "all_in_contact": rng.uniform(0.5, 1.0, n),
         "none_in_contact": np.zeros(n), "negative": rng.standard_normal(n)}[case]
    gap = rng.standard_normal(n) * 1e-3
    gap[n - 1], gap[5] = -0.7, 0.9  # extremes in the first and the last part
    p[n // 2] = max(p[n // 2], 0.0) * 3 + (1.0 if case != "none_in_contact" else 0.0)
    given = p.copy(), gap.copy()
    previous = fft.set_threads(threads)
    try:
        for force in (None, 1.3 * n):
            got = kkt_residual(p, gap, displacement_scale=0.5, force=force, node_area=1.0)
            assert got == _residual_by_definition(p, gap, 0.5, force, 1.0)
    finally:
        fft.set_threads(previous)
    assert np.array_equal(p, given[0]) and np.array_equal(gap, given[1])


def test_the_compiled_extremes_are_numpys():
    """:func:`bem.extremes.residual_extremes` on a large array (compiled, in parts) gives the extremes NumPy gives,
    where no node and where every node is in contact too."""
    from bem import extremes

    pytest.importorskip("numba", reason="the compiled pass needs numba (contactlab[fast])")
    rng = np.random.default_rng(12)
    n = extremes.MIN_NODES + 77
    gap = rng.standard_normal(n)
    for p in (np.maximum(rng.standard_normal(n), 0.0), np.zeros(n), rng.uniform(0.1, 1.0, n)):
        contact = p > 0
        expected = (p.min(), p.max(), np.abs(gap[contact]).max() if contact.any() else 0.0,
                    gap[~contact].min() if (~contact).any() else np.inf)
        assert extremes.residual_extremes(p, gap) == expected
    assert extremes._COMPILED and extremes._COMPILED[0] is not None  # the compiled kernel took them
