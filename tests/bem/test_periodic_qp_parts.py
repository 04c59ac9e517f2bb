"""The parts of the periodic cell's constrained CG (bem.periodic.qp_parts, bem.periodic.spectra) against plain
references; the steady contact of the QP against the QP that reads the contact at every iteration."""

import numpy as np
import pytest

import bem.periodic.qp_parts as qp_parts
from bem.backend import get_backend
from bem.periodic import PeriodicCell, PeriodicOperator
from bem.periodic.qp import solve_periodic_qp
from bem.periodic.qp_parts import ContactBrick, ContactNodes, LastPreconditionedGap, weighted_square

from .fourier_qp_cases import assert_same_bits, cell_qp


def test_last_preconditioned_gap_reads_the_kept_values_at_new_nodes():
    """``at`` gives the last kept ``z`` at nodes of the last selection (to single precision) and 0 elsewhere,
    whatever selections came before; ``keep`` copies."""
    shape = (12, 10)
    bk = get_backend("cpu")
    rng = np.random.default_rng(3)
    last = LastPreconditionedGap(bk, shape)
    assert np.array_equal(last.at(np.array([0, 5, 7])), np.zeros(3))
    for _ in range(4):
        nodes = np.flatnonzero(rng.random(shape) < 0.4)
        z = rng.standard_normal(nodes.size)
        kept = z.copy()
        last.keep(nodes, z)
        z[:] = 0.0  # the caller's array is not held
        new = np.flatnonzero(rng.random(shape) < 0.4)
        expected = np.zeros(new.size)
        where = np.isin(new, nodes)
        expected[where] = kept[np.searchsorted(nodes, new[where])]
        got = last.at(new)
        assert got.dtype == np.float64
        np.testing.assert_allclose(got, expected, rtol=1e-7, atol=0)
        assert np.all(got[~where] == 0)
        # at the kept selection itself (an unchanged contact): the kept values, as a gather would give them
        same = last.at(nodes)
        np.testing.assert_array_equal(same, kept.astype(np.float32).astype(np.float64))
        np.testing.assert_array_equal(last.at(nodes.copy()), same)  # an equal selection, another array: gathered


def test_contact_brick_holds_the_last_write_and_zero_elsewhere():
    """Whatever the selections before, the brick holds the values of the last write (rounded to float32) at its
    nodes and 0 elsewhere; a write at the same selection object skips the fill and gives the same brick."""
    shape = (10, 8)
    bk = get_backend("cpu")
    rng = np.random.default_rng(5)
    brick = ContactBrick(bk, shape)
    assert not brick.values.any()
    sel = np.flatnonzero(rng.random(shape) < 0.5)
    for nodes in (sel, sel, np.flatnonzero(rng.random(shape) < 0.3), sel, sel):
        values = rng.standard_normal(nodes.size)
        out = brick.write(nodes, values)
        expected = np.zeros(shape, dtype=np.float32)
        expected.reshape(-1)[nodes] = values.astype(np.float32)
        np.testing.assert_array_equal(out, expected)
        np.testing.assert_array_equal(brick.last, values.astype(np.float32))


def test_contact_nodes_read_the_contact_and_count_its_changes():
    """``read`` gives the nodes of ``p > 0`` and the pressures there; ``changes`` the nodes that entered or left
    since its last call; after a step that kept every node positive and let none enter, ``read`` gives the same
    selection and the step's pressures without looking at ``p``."""
    shape = (8, 6)
    bk = get_backend("cpu")
    rng = np.random.default_rng(7)
    p = np.where(rng.random(shape) < 0.4, rng.random(shape), 0.0)
    nodes = ContactNodes(bk, p)
    idx, p_c = nodes.read(p)
    np.testing.assert_array_equal(idx, np.flatnonzero(p))
    np.testing.assert_array_equal(p_c, p.ravel()[idx])
    assert nodes.changes() == (idx.size, 0)
    q = p.copy()
    q.reshape(-1)[idx[:3]] = 0.0  # three leave, two enter
    q.reshape(-1)[np.flatnonzero(p == 0)[:2]] = 1.0
    idx_q, _ = nodes.read(q)
    assert nodes.changes() == (idx_q.size, 5)
    step = q.reshape(-1)[idx_q] * 1.5  # every node positive, none entered: steady
    nodes.stepped(step, entered=False)
    q.reshape(-1)[idx_q] = step
    again, p_again = nodes.read(np.full(shape, np.nan))  # p is not read
    assert again is idx_q and p_again is step
    assert nodes.changes() == (idx_q.size, 0)
    step = step.copy()
    step[0] = 0.0  # a node left: the contact is read again
    nodes.stepped(step, entered=False)
    q.reshape(-1)[idx_q] = step
    idx_r, _ = nodes.read(q)
    np.testing.assert_array_equal(idx_r, np.flatnonzero(q))
    assert nodes.changes() == (idx_r.size, 1)
    nodes.stepped(q.reshape(-1)[idx_r], entered=True)  # a node entered elsewhere: read again
    assert not nodes.steady


def test_mix_inner_is_the_mix_and_the_inner_product():
    rng = np.random.default_rng(11)
    for cell in (PeriodicCell(1.0 / 64, 64, 48), PeriodicCell(1.0 / 63, 63, 48)):  # with and without a Nyquist column
        op = PeriodicOperator(cell, 1.0)
        v = rng.standard_normal(cell.shape)
        for single in (False, True):
            X = op.spectrum(v.astype(np.float32) if single else v)
            symbol = op.symbol(0.3 * op.diagonal, single=single)
            out, total = op.mix_inner(X, symbol)
            np.testing.assert_array_equal(out, op.mix(X, symbol))
            assert total == pytest.approx(op.inner(X, out), rel=1e-12)
            u = op.brick(out.copy())
            assert total == pytest.approx(float(np.sum(v * u)), rel=1e-5 if single else 1e-12)
            with pytest.raises(ValueError, match="out"):
                op.mix_inner(X, symbol, out=X)


@pytest.mark.parametrize("per_node", [False, True])
def test_the_steady_contact_changes_no_number_of_the_qp(monkeypatch, per_node):
    """The QP that keeps the contact, its pressures, the direction and D over steps that no node entered or left
    gives bit for bit the answer, the iterations and the products of the QP that reads them at every iteration;
    and it does keep them at some iterations."""
    op, h, kw = cell_qp("per_node" if per_node else "smooth")
    steps = []
    stepped = ContactNodes.stepped

    def counted(self, p_c, entered):
        stepped(self, p_c, entered)
        steps.append(self.steady)

    monkeypatch.setattr(qp_parts.ContactNodes, "stepped", counted)
    kept = solve_periodic_qp(op, h, **kw)
    n_kept = op.n_matvec
    assert sum(steps) >= 3

    def never(self, p_c, entered):
        self.steady = False

    monkeypatch.setattr(qp_parts.ContactNodes, "stepped", never)
    op.n_matvec = 0
    read = solve_periodic_qp(op, h, **kw)
    assert_same_bits(kept, read, n_kept, op.n_matvec)


def test_weighted_square_is_the_sum():
    d, t = np.array([1.0, 2.0, 0.5]), np.array([3.0, -1.0, 4.0])
    assert weighted_square(get_backend("cpu"), d, t) == pytest.approx(9.0 + 2.0 + 8.0, rel=1e-15)
