"""Products that may write their result into their input (``overwrite_p`` of :meth:`bem.InfluenceOperator.matvec`,
``overwrite_r`` of its preconditioner): the numbers of the products into a new array, bit for bit, on every path
(the whole array, bands of columns with four blocks or a paired window, the whole region), and the input kept
without the flag. The constrained CG of the half-space gives its direction's buffer to its product and the
preconditioner's input to its output (``tests/bem/test_memory.py`` bounds what that saves).
"""

import numpy as np
import pytest

from bem.lattice import Lattice
from bem.operator import InfluenceOperator
from bem.periodic import PeriodicCell, PeriodicOperator

from .test_column_bands import _support


_CASES = [  # (bands, rows, cols): a window off the centre, a corner, the whole region
    (False, slice(5, 14), slice(8, 16)),
    (True, slice(5, 14), slice(8, 16)),  # bands of columns, a paired window
    (True, slice(0, 6), slice(0, 5)),
    (False, slice(None), slice(None)),
    (True, slice(None), slice(None)),
]


@pytest.mark.parametrize("bands, rows, cols", _CASES)
def test_a_product_written_into_its_input_is_the_product_into_a_new_array(bands, rows, cols, monkeypatch):
    if bands:
        monkeypatch.setattr("bem.operator.BANDS_ABOVE", 0)
    lat = Lattice.from_extent(0.05, (1.0, 0.7))
    op = InfluenceOperator(lat, 1.7)
    dense = op.dense()
    for seed in range(2):
        p = _support(lat, seed, rows, cols)
        keep = p.copy()
        new = op.matvec(p)
        np.testing.assert_array_equal(p, keep)  # without the flag the input is kept
        ref = dense @ p[lat.mask]
        assert np.abs(new[lat.mask] - ref).max() <= 1e-13 * np.abs(ref).max()
        own = op.matvec(p, overwrite_p=True)
        assert own is p  # the result in the input's buffer
        np.testing.assert_array_equal(own, new)
    single = keep.astype(np.float32)  # not a float64 buffer: a new array, the input kept
    got = op.matvec(single, overwrite_p=True)
    assert got is not single and got.dtype == np.float64
    np.testing.assert_array_equal(single, keep.astype(np.float32))
    zero = np.zeros(lat.shape)
    assert not op.matvec(zero, overwrite_p=True).any()


@pytest.mark.parametrize("bands, rows, cols", _CASES)
@pytest.mark.parametrize("single", [False, True])
def test_a_preconditioner_written_into_its_input_is_the_one_into_a_new_array(bands, rows, cols, single, monkeypatch):
    if bands:
        monkeypatch.setattr("bem.operator.BANDS_ABOVE", 0)
    lat = Lattice.from_extent(0.05, (1.0, 0.7))
    op = InfluenceOperator(lat, 1.7)
    for box in ("support", "full"):
        r = _support(lat, 4, rows, cols)
        keep = r.copy()
        new = op.preconditioner(lam=0.3 * op.diagonal, box=box, single=single)(r)
        np.testing.assert_array_equal(r, keep)
        own = op.preconditioner(lam=0.3 * op.diagonal, box=box, single=single, overwrite_r=True)(r)
        assert own is r
        np.testing.assert_array_equal(own, new)  # the same numbers, 0 off the box
        assert np.any(new != 0)


def test_a_periodic_product_accepts_the_flag_and_keeps_its_input():
    cell = PeriodicCell(0.1, 16, 12)
    op = PeriodicOperator(cell, 2.0)
    p = np.random.default_rng(2).random(cell.shape)
    keep = p.copy()
    np.testing.assert_array_equal(op.matvec(p, overwrite_p=True), op.matvec(keep))
    np.testing.assert_array_equal(p, keep)


@pytest.mark.parametrize("lam", [0.0, 0.5, "per node"])
def test_the_half_space_qp_meets_its_kkt_conditions_with_a_compliance(lam):
    """The QP adds ``lam t`` to the product of its direction at the contact only (the direction is 0 elsewhere):
    the KKT conditions of ``min 1/2 p.(C + lam) p + p.(h - delta)`` hold at the answer, checked on a fresh product."""
    from bem.kalker import solve_qp

    lat = Lattice.from_extent(0.04, (1.0, 1.0))
    op = InfluenceOperator(lat, 1.0)
    x, y = lat.x - 0.5, lat.y - 0.5
    h = (x * x + y * y) / 2 + 2e-3 * np.cos(2 * np.pi * x / 0.13) * np.cos(2 * np.pi * y / 0.17)
    if lam == "per node":
        lam = op.diagonal * (0.5 + np.random.default_rng(1).random(lat.shape)) * lat.mask
    else:
        lam = lam * op.diagonal
    force = 2e-3
    sol = solve_qp(op, h, force=force, lam=lam, rtol=1e-10, preconditioner=op.preconditioner(overwrite_r=True))
    assert sol.converged, sol.message
    p = sol.p
    g = op.matvec(p) + lam * p + h - sol.approach
    m = lat.mask
    contact = m & (p > 0)
    scale = np.abs(op.matvec(p) + lam * p)[m].max()
    assert np.abs(g[contact]).max() <= 1e-9 * scale  # closed where it presses
    assert g[m & ~contact].min() >= -1e-9 * scale  # open elsewhere
    assert p.min() >= 0 and abs(lat.node_area * p.sum() - force) <= 1e-12 * force


def test_the_half_space_qp_from_a_product_holds_its_iterate_in_the_start_it_may_overwrite():
    """With the caller's product ``u0 = C x0`` and ``overwrite_x0`` the QP iterates in ``x0``, masked in place (0 at
    the nodes off the candidates), and gives the answer of the QP on its own copy bit for bit."""
    from bem.kalker import solve_qp

    lat = Lattice.from_extent(0.04, (1.0, 1.0))
    op = InfluenceOperator(lat, 1.0)
    x, y = lat.x - 0.5, lat.y - 0.5
    h = (x * x + y * y) / 2
    x0 = np.where(x * x + y * y < 0.01, 0.05, 0.0)
    x0[~lat.mask] = 0.05  # written off the candidates: not part of the iterate
    u0 = op.matvec(np.where(lat.mask, x0, 0.0))
    kw = dict(force=2e-3, rtol=1e-10, preconditioner=op.preconditioner(), u0=u0)
    own = solve_qp(op, h, x0=x0.copy(), **kw)
    held = solve_qp(op, h, x0=x0, overwrite_x0=True, **kw)
    assert own.converged and held.converged and held.p is x0 and own.p is not x0
    assert np.all(x0[~lat.mask] == 0)
    assert held.iterations == own.iterations and np.array_equal(held.p, own.p)
