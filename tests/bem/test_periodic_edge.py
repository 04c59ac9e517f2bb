"""The cell's preconditioner corrected at the edges of the contact (bem.periodic.edge): the correction against its
definition by the dense inverse of the cell's operator, the spectrum of the corrected preconditioner on a fixed
contact against the plain one's (dense), its rules, and the QP's answer with it against the answer without (with a
uniform compliance and with a compliance per node)."""

import math

import numpy as np
import pytest

import bem.periodic.edge as edge
import bem.periodic.qp as periodic_qp
from bem.backend import operator_backend
from bem.kkt import kkt_residual
from bem.periodic import PeriodicCell, PeriodicOperator
from bem.periodic.edge import EdgeCorrection
from bem.periodic.qp import solve_periodic_qp
from bem.periodic.qp_parts import ContactNodes

from .test_periodic_qp import _rough


def _self_affine(cell, seed=3, hurst=0.8):
    """A random surface with a power spectrum ``|q|^-2(1 + H)`` over the cell's brick array [length]: many small
    contact spots at a few per cent of full contact."""
    n_rows, n_cols = cell.shape
    rng = np.random.default_rng(seed)
    q2 = np.fft.fftfreq(n_cols)[None, :] ** 2 + np.fft.fftfreq(n_rows)[:, None] ** 2
    amp = np.where(q2 > 0, (q2 + 1e-4) ** (-(1 + hurst) / 2), 0.0)
    z = np.real(np.fft.ifft2(amp * np.exp(2j * math.pi * rng.random(cell.shape))))
    return 0.02 * (z - z.min()) / np.ptp(z)


def _contact(cell, h, load):
    """The contact of the cell's QP under ``h`` at the mean pressure ``load`` (``E* = 1``)."""
    op = PeriodicOperator(cell, 1.0)
    res = solve_periodic_qp(op, h, force=load * cell.area, rtol=1e-11)
    assert res.converged
    return op, res.p > 0


def _dense_inverse(op):
    """``M = (C + C_nn 1 1' / N)^-1`` from the dense ``C`` (the cell's preconditioner, made independently)."""
    C = op.dense()
    n = C.shape[0]
    return C, np.linalg.inv(C + op.diagonal * np.ones((n, n)) / n)


def _apply_m(op):
    """The preconditioner as the QP hands it to :class:`EdgeCorrection`: float32 in, float32 into ``out``."""
    M = op.preconditioner()

    def apply_m(r32, out=None):
        values = M(np.asarray(r32, dtype=np.float64)).astype(np.float32)
        if out is None:
            return values
        out[...] = values
        return out

    return apply_m


def _correction(op, contact):
    """An :class:`EdgeCorrection` of the cell and the contact's flat node indices."""
    fix = EdgeCorrection(operator_backend(op)[0], _apply_m(op), contact.shape, op.diagonal, op.symbol(inverse=True))
    return fix, np.flatnonzero(contact)


def _counted(monkeypatch):
    """The times :class:`EdgeCorrection` is made (a list, its length), counted from here on."""
    made = []
    original = EdgeCorrection._make
    monkeypatch.setattr(EdgeCorrection, "_make",
                        lambda self, idx, soft=None: made.append(idx.size) or original(self, idx, soft))
    return made


def _preconditioned(op, contact, r):
    """``M_AA r`` (double precision) of a gap ``r`` at the contact's nodes."""
    v = np.zeros(contact.shape)
    v[contact] = r
    return op.preconditioner()(v)[contact]


def test_the_correction_is_its_definition_by_the_dense_inverse(monkeypatch):
    cell = PeriodicCell(1.0 / 48, 48, 48)
    op, contact = _contact(cell, _self_affine(cell), 0.01)
    fix, idx = _correction(op, contact)
    made = _counted(monkeypatch)
    _, M = _dense_inverse(op)
    off = (~contact).ravel().astype(float)
    c = np.maximum(edge.THETA * (M @ (off - off.mean()))[idx], edge.FLOOR / op.diagonal - M[0, 0])
    floored = c == edge.FLOOR / op.diagonal - M[0, 0]
    assert 0 < np.count_nonzero(floored) < idx.size  # both branches of the definition are met
    assert np.count_nonzero(c < 0) > idx.size / 2  # most contact nodes' diagonal lowered
    rng = np.random.default_rng(1)
    r = rng.standard_normal(idx.size)
    z = _preconditioned(op, contact, r)
    z_in, r_in = z.copy(), r.copy()
    got = fix.applied(z, r, idx, [idx.size, 0])
    assert np.array_equal(z, z_in) and np.array_equal(r, r_in)  # the inputs untouched
    assert len(made) == 1
    want = z + c * r
    assert np.abs(got - want).max() <= 1e-5 * np.abs(c * r).max()  # the float32 products' rounding


def test_with_soft_nodes_the_correction_is_its_definition_over_the_stiff_contact():
    """With a compliance per node the nodes the preconditioner takes by Jacobi (soft) count as off the contact ``A``
    of the definition and take no correction: ``c_a = max(theta (M (1_I - f))_a, beta / C_nn - M_nn)`` over the stiff
    contact ``A``, ``I`` the rest of the cell (the soft contact nodes with it), ``f = |I| / N``; ``c = 0`` at the soft
    nodes (the dense inverse again)."""
    cell = PeriodicCell(1.0 / 48, 48, 48)
    op, contact = _contact(cell, _self_affine(cell), 0.01)
    fix, idx = _correction(op, contact)
    _, M = _dense_inverse(op)
    soft = np.random.default_rng(6).random(idx.size) < 0.3  # at the contact's nodes
    stiff_contact = np.zeros(contact.size, dtype=bool)
    stiff_contact[idx[~soft]] = True
    off = (~stiff_contact).astype(float)
    c = np.maximum(edge.THETA * (M @ (off - off.mean()))[idx], edge.FLOOR / op.diagonal - M[0, 0])
    c[soft] = 0.0
    assert np.count_nonzero(c[~soft] < 0) > np.count_nonzero(~soft) / 2
    r = np.random.default_rng(7).standard_normal(idx.size)
    z = _preconditioned(op, contact, r)
    soft_in = soft.copy()
    got = fix.applied(z, r, idx, [idx.size, 0], None, soft)
    assert np.array_equal(soft, soft_in)
    assert np.array_equal(got[soft], z[soft])  # no correction where Jacobi preconditions
    assert np.abs(got - (z + c * r)).max() <= 1e-5 * np.abs(c * r).max()
    scratch = np.full(cell.shape, np.nan, dtype=np.float32)  # made in a scratch array of the caller's: the same
    in_scratch = EdgeCorrection(operator_backend(op)[0], _apply_m(op), cell.shape, op.diagonal,
                                op.symbol(inverse=True), lambda: scratch)
    assert np.array_equal(in_scratch.applied(z, r, idx, [idx.size, 0], None, soft), got)
    assert not np.isnan(scratch).any()
    # M_nn from a device's blocks of M's symbol (D, B): the same
    fix = EdgeCorrection(operator_backend(op)[0], _apply_m(op), cell.shape, op.diagonal, op.symbol(inverse=True).rows())
    assert np.abs(fix.applied(z, r, idx, [idx.size, 0], None, soft) - got).max() <= 1e-5 * np.abs(c * r).max()


def test_no_correction_in_a_solve_whose_settled_contact_is_mostly_soft(monkeypatch):
    """Where the soft nodes (Jacobi) are more than half of the contact when it settles, the stiff contact is islands
    among nodes that carry pressure, not the edge of the pressure: the correction is not made in that solve (nor
    after, as the contact changes); at half or less it is."""
    cell = PeriodicCell(1.0 / 48, 48, 48)
    op, contact = _contact(cell, _self_affine(cell), 0.01)
    idx = np.flatnonzero(contact)
    n = idx.size
    r = np.random.default_rng(9).standard_normal(n)
    z = _preconditioned(op, contact, r)
    made = _counted(monkeypatch)
    for share, makes in ((0.5, 1), (0.5 + 2.0 / n, 0)):
        soft = np.arange(n) < round(share * n)
        fix, _ = _correction(op, contact)
        outs = [fix.applied(z, r, idx, [n] + [0] * k, None, soft) for k in (1, 2, 3)]
        outs.append(fix.applied(z, r, idx, [n, 0, 0, 0], None, ~soft))  # fewer soft nodes later: still none
        assert len(made) == makes and (makes or all(out is z for out in outs))
        made.clear()


@pytest.mark.parametrize("surface, load, at_most", [("smooth", 0.03, 0.75), ("smooth", 0.003, 0.85),
                                                     ("self-affine", 0.01, 0.9), ("self-affine", 0.03, 0.8)])
def test_the_corrected_preconditioner_conditions_a_fixed_contact_better(surface, load, at_most):
    """The spectrum of the preconditioned contact ``P C_AA`` on the zero-sum pressures of a fixed contact (the
    force's constraint), dense, ``P = M_AA + diag(c)`` with the ``c`` the library makes: positive definite, and its
    condition number below ``at_most`` of that of ``M_AA`` alone (measured at 48 x 48: 2.52 -> 1.76 and 2.21 -> 1.76
    on the smooth surface, 4.52 -> 3.84 and 5.22 -> 3.93 on the self-affine one)."""
    cell = PeriodicCell(1.0 / 48, 48, 48)
    op, contact = _contact(cell, _rough(cell) if surface == "smooth" else _self_affine(cell), load)
    C, M = _dense_inverse(op)
    on = contact.ravel()
    m = int(np.count_nonzero(on))
    C_AA, M_AA = C[np.ix_(on, on)], M[np.ix_(on, on)]
    fix, idx = _correction(op, contact)  # the library's correction c, read off z + c r on a positive r
    r = 1.0 + np.random.default_rng(5).random(m)
    z = M_AA @ r
    c = (fix.applied(z, r, idx, [m, 0]) - z) / r
    Q = np.linalg.qr(np.eye(m) - 1.0 / m)[0][:, : m - 1]  # an orthonormal basis of the zero-sum pressures

    def spectrum(P):
        L = np.linalg.cholesky(Q.T @ P @ Q)  # raises where P is not positive definite there
        ev = np.linalg.eigvalsh(L.T @ (Q.T @ C_AA @ Q) @ L)
        return ev[0], ev[-1] / ev[0]

    low, kappa = spectrum(M_AA + np.diag(c))
    low_plain, kappa_plain = spectrum(M_AA)
    assert low > 0 and low_plain == pytest.approx(1.0, abs=1e-6)  # M_AA - C_AA^-1 >= 0: lambda_min of M alone is 1
    assert kappa < at_most * kappa_plain


def test_the_correction_starts_when_the_contact_settles_and_is_made_again_after_enough_changes(monkeypatch):
    monkeypatch.setattr(edge, "REMAKE", 0.03)  # changes of a few nodes to count on this small contact
    cell = PeriodicCell(1.0 / 48, 48, 48)
    op, contact = _contact(cell, _self_affine(cell), 0.01)
    fix, idx = _correction(op, contact)
    made = _counted(monkeypatch)
    n = idx.size
    r = np.random.default_rng(2).standard_normal(n)
    z = _preconditioned(op, contact, r)
    many = int(edge.SETTLED * n) + 1
    assert fix.applied(z, r, idx, [n]) is z  # the first step: no earlier contact to count changes from
    assert fix.applied(z, r, idx, [n, many]) is z and not made  # the contact still moves
    few = int(edge.SETTLED * n)
    assert fix.applied(z, r, idx, [n, many, few]) is not z and len(made) == 1
    each = int(edge.REMAKE * n / 3)
    assert each > 0
    for k in range(3):  # the changes since add up to REMAKE * n at most: not made again
        fix.applied(z, r, idx, [n, many, few] + [each] * (k + 1))
    assert len(made) == 1
    fix.applied(z, r, idx, [n, many, few, each, each, each, n])
    assert len(made) == 2


def test_the_correction_follows_the_contact_through_a_step():
    """The nodes in both contacts keep their correction, a node that left and entered again among them, and an
    entering node takes 0: the same through the step's merge and through a brick array."""
    cell = PeriodicCell(1.0 / 48, 48, 48)
    op, contact = _contact(cell, _self_affine(cell), 0.01)
    r = np.random.default_rng(4).standard_normal(idx_size := int(np.count_nonzero(contact)))
    fixes = []
    for _ in range(2):
        fix, idx = _correction(op, contact)
        fix.applied(_preconditioned(op, contact, r), r, idx, [idx_size, 0])
        fixes.append(fix)
    made = fixes[0]._at(idx, None).copy()
    assert np.count_nonzero(made) == idx.size  # c != 0 at every node of the contact it was made on
    p = np.where(contact, 1.0, 0.0)
    nodes = ContactNodes(operator_backend(op)[0], p)
    _, p_c = nodes.read(p)
    p_c = p_c.copy()
    p_c[: idx.size // 10] = 0.0  # a tenth of the contact leaves, twenty nodes off it and one of those enter
    entering = np.union1d(np.flatnonzero(~contact)[::7][:20], idx[:1])
    nodes.stepped(p_c, True, entering, np.ones(entering.size))
    after, _ = nodes.read(p)
    assert nodes.from_step is not None
    want = np.zeros(after.size)
    stayed = np.isin(after, idx)
    want[stayed] = made[np.searchsorted(idx, after[stayed])]
    k = int(np.searchsorted(after, idx[0]))  # the node that left and entered again keeps its own
    assert np.count_nonzero(~stayed) == 20 and after[k] == idx[0] and want[k] == made[0]
    for fix, contact_nodes in zip(fixes, (nodes, None)):  # the step's merge, a brick array
        assert np.array_equal(fix._at(after, contact_nodes), want)
    p_c = np.ones(after.size)
    p_c[-5:] = 0.0  # a second step from that contact: five leave, three enter
    entering = np.flatnonzero(np.isin(np.arange(p.size), after, invert=True))[1::11][:3]
    nodes.stepped(p_c, True, entering, np.ones(entering.size))
    later, _ = nodes.read(p)
    again = np.zeros(later.size)
    stayed = np.isin(later, after)
    again[stayed] = want[np.searchsorted(after, later[stayed])]
    for fix, contact_nodes in zip(fixes, (nodes, None)):
        assert np.array_equal(fix._at(later, contact_nodes), again)


def test_a_corrected_gap_that_is_no_descent_direction_is_not_taken():
    cell = PeriodicCell(1.0 / 48, 48, 48)
    op, contact = _contact(cell, _self_affine(cell), 0.01)
    fix, idx = _correction(op, contact)
    r = np.ones(idx.size)
    z = np.zeros(idx.size)  # r.(z + c r) = sum c, negative: most of the diagonal is lowered
    assert fix.applied(z, r, idx, [idx.size, 0]) is z
    z = _preconditioned(op, contact, r)  # M_AA r: r.(z + c r) = r.P r > 0
    assert fix.applied(z, r, idx, [idx.size, 0]) is not z


@pytest.mark.parametrize("surface, load", [("smooth", 0.03), ("self-affine", 0.01)])
def test_the_qp_with_the_correction_gives_the_answer_without_it_in_fewer_iterations(surface, load, monkeypatch):
    cell = PeriodicCell(1.0 / 128, 128, 128)
    h = _rough(cell) if surface == "smooth" else _self_affine(cell)
    op = PeriodicOperator(cell, 1.0)
    made = _counted(monkeypatch)
    fixed = solve_periodic_qp(op, h, force=load * cell.area, rtol=1e-10)
    monkeypatch.setattr(edge, "THETA", 0.0)
    plain = solve_periodic_qp(op, h, force=load * cell.area, rtol=1e-10)
    assert fixed.converged and plain.converged and made
    assert fixed.iterations < plain.iterations
    assert np.abs(fixed.p - plain.p).max() <= 1e-8 * plain.p.max()
    u = op.matvec(fixed.p)  # the KKT conditions on a product made here
    gap = u + h - fixed.approach
    assert kkt_residual(fixed.p, gap, displacement_scale=float(np.abs(u).max()), force=load * cell.area,
                        node_area=cell.node_area) <= 1e-10


def test_the_qp_with_a_compliance_per_node_gives_the_answer_without_the_correction_in_fewer_iterations(monkeypatch):
    """A Newton model's QP (a compliance per node, a fifth of the nodes soft: Jacobi there) on a self-affine cell:
    the same answer with the correction as without it (``THETA = 0``), in fewer iterations."""
    cell = PeriodicCell(1.0 / 128, 128, 128)
    h = _self_affine(cell)
    op = PeriodicOperator(cell, 1.0)
    D = op.diagonal * (0.1 + 8.0 * np.random.default_rng(8).random(cell.shape) ** 3)  # D > 4 C_nn: 21 % of the nodes
    made = _counted(monkeypatch)
    kw = dict(force=0.01 * cell.area, lam=D, rtol=1e-10)
    fixed = solve_periodic_qp(op, h, **kw)
    monkeypatch.setattr(edge, "THETA", 0.0)
    plain = solve_periodic_qp(op, h, **kw)
    assert fixed.converged and plain.converged and made
    assert fixed.iterations < plain.iterations
    assert np.abs(fixed.p - plain.p).max() <= 1e-8 * plain.p.max()
    u = op.matvec(fixed.p)  # the KKT conditions on a product made here, with the layer's D p
    gap = u + D * fixed.p + h - fixed.approach
    assert kkt_residual(fixed.p, gap, displacement_scale=float(np.abs(u + D * fixed.p).max()),
                        force=0.01 * cell.area, node_area=cell.node_area) <= 1e-10


@pytest.mark.parametrize("case", ["uniform compliance", "per node", "hardness"])
def test_the_correction_serves_the_qp_without_a_hardness(case, monkeypatch):
    cell = PeriodicCell(1.0 / 32, 32, 32)
    h = _rough(cell)
    op = PeriodicOperator(cell, 1.0)
    made = []

    class Spy(EdgeCorrection):
        def __init__(self, bk, apply_m, shape, diagonal, *rest):
            made.append(diagonal)
            super().__init__(bk, apply_m, shape, diagonal, *rest)

    monkeypatch.setattr(periodic_qp, "EdgeCorrection", Spy)
    kw = dict(force=0.03 * cell.area, rtol=1e-10)
    if case == "uniform compliance":
        kw["lam"] = 0.5 * op.diagonal
    elif case == "per node":
        kw["lam"] = np.full(cell.shape, 0.5 * op.diagonal)
    else:
        kw["hardness"] = 0.05
    assert solve_periodic_qp(op, h, **kw).converged
    if case == "hardness":
        assert made == []
    else:  # the diagonal of the operator it inverts: C_nn + lam (per node: lam the median of D on the stiff contact)
        assert made == [pytest.approx(1.5 * op.diagonal)]


def test_off_numpy_the_correction_is_kept_again_only_where_the_contact_changed(monkeypatch):
    """Off NumPy the kept correction is a brick array made by a spread; read at the contact it was kept on, it is
    not spread again (the nodes of a keep are recorded on every namespace)."""
    xs = pytest.importorskip("array_api_strict")
    from bem.backend import get_backend

    bk = get_backend(xs)
    shape = (8, 6)
    on = bk.select(xs.asarray(np.random.default_rng(1).random(shape) < 0.5))
    fix = EdgeCorrection(bk, None, shape, 1.0, None)
    fix.kept.keep(on, xs.full(bk.count(on), 0.25, dtype=xs.float64))
    spreads = []
    real = bk.spread
    monkeypatch.setattr(bk, "spread", lambda *a: spreads.append(a) or real(*a))
    for _ in range(2):
        c = fix._at(on, None)
        assert bool(xs.all(c == 0.25))
    assert not spreads
    other = bk.select(xs.asarray(np.random.default_rng(2).random(shape) < 0.5))
    fix._at(other, None)  # another contact: kept again there
    assert len(spreads) == 1
