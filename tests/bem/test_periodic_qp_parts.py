"""The parts of the periodic cell's constrained CG (bem.periodic.qp_parts, bem.periodic.spectra) against plain
references; the steady contact of the QP against the QP that reads the contact at every iteration."""

import numpy as np
import pytest

import bem.periodic.qp_parts as qp_parts
from bem.backend import get_backend
from bem.periodic import PeriodicCell, PeriodicOperator
from bem.periodic.qp import solve_periodic_qp
from bem.periodic.qp_parts import ContactBrick, ContactNodes, KeptOnContact, weighted_square

from .fourier_qp_cases import assert_same_bits, cell_qp


@pytest.mark.parametrize("hold", [True, False])
def test_kept_on_contact_reads_the_kept_values_at_new_nodes(hold):
    """``at`` gives the last kept ``z`` at nodes of the last selection (to single precision) and 0 elsewhere,
    whatever selections came before; ``keep`` copies; the brick array of the reads held or not (``hold``)."""
    shape = (12, 10)
    bk = get_backend("cpu")
    rng = np.random.default_rng(3)
    last = KeptOnContact(bk, shape, hold=hold)
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
        assert (last.values is not None) == hold  # the brick array of the read
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
    # a step that sets two nodes to 0, one of which enters again, and lets two more enter: the next contact
    # is made from the step's arrays, the same as a read of the pressure
    step = q.reshape(-1)[idx_r].copy()
    step[[1, 2]] = 0.0
    off = np.flatnonzero(q == 0)[:2]
    entering = np.sort(np.concatenate([idx_r[[1]], off]))
    p_o = np.full(entering.size, 0.25)
    q.reshape(-1)[idx_r] = step
    q.reshape(-1)[entering] = p_o
    last = KeptOnContact(bk, shape)
    z = rng.standard_normal(idx_r.size)
    last.keep(idx_r, z)  # the last preconditioned gap on the contact before the step
    nodes.stepped(step, True, entering, p_o)
    assert not nodes.steady
    idx_s, p_s = nodes.read(np.full(shape, np.nan))  # p is not read
    values = rng.standard_normal(shape).ravel()  # values on the contact carried over, gathered at entering nodes
    np.testing.assert_array_equal(nodes.over(idx_s, values.take, values[idx_r]), values[idx_s])
    spread = np.zeros(np.prod(shape), dtype=np.float32)
    spread[idx_r] = z
    np.testing.assert_array_equal(last.at(idx_s, nodes), spread[idx_s].astype(np.float64))
    np.testing.assert_array_equal(idx_s, np.flatnonzero(q))
    np.testing.assert_array_equal(p_s, q.ravel()[idx_s])
    assert nodes.changes() == (idx_s.size, 3)  # one left, two entered
    full = ContactNodes(bk, q)  # the counts go on from the contact made from the step
    full.read(q)
    np.testing.assert_array_equal(nodes.was_on, full.was_on)


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


def _rough_cell_qp(per_node):
    """A 128 x 128 cell under a seeded rough gap at mean pressure 0.01 E*: nodes enter, leave and re-enter."""
    cell = PeriodicCell(1.0 / 128, 128, 128)
    rng = np.random.default_rng(17)
    spectrum = np.fft.rfft2(rng.standard_normal(cell.shape))
    q = np.hypot(*np.meshgrid(np.fft.fftfreq(128), np.fft.rfftfreq(128), indexing="ij"))
    h = np.fft.irfft2(spectrum * np.where(q > 0, np.maximum(q, 1 / 32) ** -1.8, 0.0), s=cell.shape)
    op = PeriodicOperator(cell, 1.0)
    h = 0.05 * cell.step * (h.max() - h) / h.std()
    kw = dict(force=0.01 * cell.area, rtol=1e-11)
    if per_node:
        kw["lam"] = np.where(np.arange(h.size).reshape(h.shape) % 7 == 0, 20.0, 0.5) * op.diagonal
    return op, h, kw


@pytest.mark.parametrize("case", ["smooth", "per_node", "rough", "rough_per_node"])
def test_the_kept_and_the_stepped_contact_change_no_number_of_the_qp(monkeypatch, case):
    """The QP that keeps the contact, its pressures, the direction and D over steps that no node entered or left,
    and makes the next contact from the step's arrays after the others, gives bit for bit the answer, the history
    (the contact's size and changes at every iteration), the iterations and the products of the QP that reads the
    contact from the pressure at every iteration; and it does both at some iterations."""
    op, h, kw = _rough_cell_qp(case.endswith("per_node")) if case.startswith("rough") else cell_qp(case)
    steady, made, reentered = [], [], []
    stepped = ContactNodes.stepped

    def counted(self, p_c, entered, entering=None, p_o=None):
        stepped(self, p_c, entered, entering, p_o)
        steady.append(self.steady)
        made.append(self.next is not None)
        reentered.append(np.intersect1d(*self.moved).size if self.moved else 0)  # left and entered again

    monkeypatch.setattr(qp_parts.ContactNodes, "stepped", counted)
    kept = solve_periodic_qp(op, h, **kw)
    n_kept = op.n_matvec
    assert sum(steady) >= 3 and sum(made) >= 3
    if case.startswith("rough"):
        assert sum(kept.history["changes"]) > 100 and sum(reentered) > 0  # nodes set to 0 that entered again

    def never(self, p_c, entered, entering=None, p_o=None):
        self.steady = False

    monkeypatch.setattr(qp_parts.ContactNodes, "stepped", never)
    op.n_matvec = 0
    read = solve_periodic_qp(op, h, **kw)
    assert_same_bits(kept, read, n_kept, op.n_matvec)


def test_weighted_square_is_the_sum():
    d, t = np.array([1.0, 2.0, 0.5]), np.array([3.0, -1.0, 4.0])
    assert weighted_square(get_backend("cpu"), d, t) == pytest.approx(9.0 + 2.0 + 8.0, rel=1e-15)
