"""The start of the constrained CG (bem.plastic.clipped_start): clipped in place only where allowed."""

import numpy as np
import pytest

from bem.backend import get_backend
from bem.plastic import clipped_start, in_place

BK = get_backend("cpu")


def _start():
    x0 = np.array([[-1.0, 0.5, 3.0], [2.0, -0.0, 7.0]])
    mask = np.array([[True, True, True], [False, True, True]])
    return x0, mask


@pytest.mark.parametrize("hardness", [None, 2.5])
def test_clipped_start_clips_at_zero_and_the_hardness_and_zeroes_off_the_mask(hardness):
    x0, mask = _start()
    top = np.inf if hardness is None else hardness
    expected = np.where(mask, np.clip(x0, 0.0, top), 0.0)
    copy = clipped_start(BK, x0.copy(), mask, hardness)
    own = x0.copy()
    inside = clipped_start(BK, own, mask, hardness, overwrite_x0=True)
    np.testing.assert_array_equal(copy, expected)
    np.testing.assert_array_equal(inside, expected)
    assert inside is own  # clipped where it is


def test_clipped_start_leaves_x0_alone_unless_allowed_and_able():
    x0, mask = _start()
    before = x0.copy()
    assert clipped_start(BK, x0, mask) is not x0
    np.testing.assert_array_equal(x0, before)
    read_only = x0.copy()
    read_only.flags.writeable = False
    for other in (x0.astype(np.float32), np.asfortranarray(x0), read_only):  # single precision, F order, read-only
        kept = other.copy()
        assert not in_place(BK, other)
        assert clipped_start(BK, other, mask, overwrite_x0=True) is not other
        np.testing.assert_array_equal(other, kept)
    assert not in_place(BK, [1.0, 2.0]) and in_place(BK, np.zeros(3))


def _sphere(**kw):
    import bem

    return bem.solve(bem.gaps.Paraboloid(1.0), E_star=1.0, force=4 * 0.1**3 / 3, step=0.02, extent=0.3, **kw)


def test_the_half_space_qp_holds_its_iterate_in_a_start_it_may_overwrite():
    import bem

    first = _sphere(rtol=1e-3)
    op = bem.InfluenceOperator(first.lattice, 1.0)
    h = np.where(first.lattice.mask, bem.gaps.Paraboloid(1.0)(first.lattice.x, first.lattice.y), 0.0)
    x0 = np.zeros(first.lattice.shape)
    x0[first.lattice.mask] = first.p
    x0[~first.lattice.mask] = 5.0  # off the candidate nodes: masked in place
    plain = op.qp(h, force=4 * 0.1**3 / 3, x0=x0.copy())
    held = op.qp(h, force=4 * 0.1**3 / 3, x0=x0, overwrite_x0=True)
    assert held.converged and held.p is x0 and np.array_equal(held.p, plain.p)
    assert held.iterations == plain.iterations and np.all(x0[~first.lattice.mask] == 0)


@pytest.mark.parametrize("method, layer", [("kalker", None), ("newton", "root")])
def test_a_callers_start_on_a_half_space_region_is_not_modified(method, layer):
    import bem

    law = bem.layers.Root(0.3 * bem.diagonal_coefficient(0.02, 1.0)) if layer else None
    first = _sphere(rtol=1e-3, method=method, layer=law)
    x0 = first.p.copy()
    before = x0.copy()
    res = _sphere(x0=x0, method=method, layer=law)
    assert res.converged
    np.testing.assert_array_equal(x0, before)
    assert not np.shares_memory(res.p, x0)


@pytest.mark.parametrize("per_node", [False, True])
def test_the_cells_qp_holds_its_product_in_a_u0_it_may_overwrite_with_the_numbers_of_its_copy(per_node):
    """``overwrite_u0``: the cell's QP iterates in the caller's ``C x0`` (no copy of it) and gives the solution of the
    QP that copies it, bit for bit; without it, or where ``u0`` cannot hold it (float32, F order), ``u0`` is not
    written."""
    from bem.periodic import PeriodicCell, PeriodicOperator

    cell = PeriodicCell(1.0 / 32, 32, 32)
    op = PeriodicOperator(cell, 1.0)
    h = 0.02 * (1 - np.cos(2 * np.pi * cell.x) * np.cos(2 * np.pi * cell.y))
    rng = np.random.default_rng(3)
    x0 = 1e-3 * rng.random(cell.shape)
    x0 *= 0.004 / (cell.node_area * x0.sum())
    lam = 0.02 + 0.01 * rng.random(cell.shape) if per_node else 0.0
    kw = dict(force=0.004, lam=lam, rtol=1e-9)
    u0 = op.matvec(x0)
    before = u0.copy()
    copied = op.qp(h, x0=x0.copy(), u0=u0, **kw)
    np.testing.assert_array_equal(u0, before)
    for other in (u0.astype(np.float32), np.asfortranarray(u0)):
        kept = other.copy()
        op.qp(h, x0=x0.copy(), u0=other, overwrite_u0=True, **kw)
        np.testing.assert_array_equal(other, kept)
    held = op.qp(h, x0=x0.copy(), u0=u0, overwrite_u0=True, **kw)
    assert copied.converged and held.converged and held.iterations == copied.iterations
    assert np.array_equal(held.p, copied.p) and np.array_equal(held.displacement, copied.displacement)
    assert not np.array_equal(u0, before)  # the QP's own product was held in it
