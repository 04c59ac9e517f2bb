"""Kalker's QP on a periodic cell in the Fourier basis (bem.periodic.qp) against the general loop
(bem.kalker.solve_qp), a dense solve and the KKT conditions; the spectral pieces of the periodic
operator against its dense matrix."""

import math

import numpy as np
import pytest

from bem.kalker import solve_qp
from bem.kkt import kkt_residual
from bem.periodic import PeriodicCell, PeriodicOperator
from bem.periodic.qp import solve_periodic_qp

from .restarted_cg import restarted_cg

E_STAR = 1.0


def _rough(cell, seed=5):
    rng = np.random.default_rng(seed)
    lx, ly = cell.size
    h = np.zeros(cell.shape)
    for m in range(1, 5):
        for n in range(-4, 5):
            amp = rng.standard_normal() / (m * m + n * n)
            h += amp * np.cos(2 * math.pi * (m * cell.x / lx + n * cell.y / ly) + rng.uniform(0, 2 * math.pi))
    return 0.02 * (h - h.min())


CELL = PeriodicCell(1.0 / 32, 32, 24)


@pytest.mark.parametrize("lam_over_cnn", [0.0, 2.0])
@pytest.mark.parametrize("control", ["force", "approach"])
def test_periodic_qp_equals_the_general_qp_and_meets_the_kkt_conditions(lam_over_cnn, control):
    cell = CELL
    h = _rough(cell)
    op = PeriodicOperator(cell, E_STAR)
    lam = lam_over_cnn * op.diagonal
    kw = dict(force=0.03 * cell.area) if control == "force" else dict(approach=float(np.quantile(h, 0.3)))
    ref = solve_qp(op, h, lam=lam, preconditioner=op.preconditioner(lam=lam), rtol=1e-10, **kw)
    fast = solve_periodic_qp(op, h, lam=lam, rtol=1e-10, **kw)
    assert ref.converged and fast.converged
    p = fast.p
    assert 0.05 < np.mean(p > 0) < 0.95
    assert np.abs(p - ref.p).max() <= 1e-8 * ref.p.max()
    assert fast.approach == pytest.approx(ref.approach, rel=1e-8, abs=1e-12 * float(np.ptp(h)))
    u = op.dense() @ p.ravel()  # the displacement, checked against the dense matrix
    np.testing.assert_allclose(fast.displacement.ravel(), u, rtol=0, atol=1e-12 * np.abs(u).max())
    g = u + lam * p.ravel() + h.ravel() - fast.approach
    force = kw.get("force")
    kkt = kkt_residual(p.ravel(), g, displacement_scale=float(np.abs(u + lam * p.ravel()).max()), force=force,
                       node_area=cell.node_area)
    assert kkt <= 1e-10


def test_periodic_qp_solves_the_dense_system_on_its_contact_set():
    """On the contact set of the answer, C_cc p_c = delta - h_c with the force as the extra equation."""
    cell = CELL
    h = _rough(cell, seed=9)
    op = PeriodicOperator(cell, E_STAR)
    force = 0.03 * cell.area
    res = solve_periodic_qp(op, h, force=force, rtol=1e-12)
    assert res.converged
    c = res.p.ravel() > 0
    C = op.dense()[np.ix_(c, c)]
    n = int(c.sum())
    kkt = np.zeros((n + 1, n + 1))
    kkt[:n, :n], kkt[:n, n], kkt[n, :n] = C, -1.0, cell.node_area
    x = np.linalg.solve(kkt, np.concatenate([-h.ravel()[c], [force]]))
    assert np.abs(res.p.ravel()[c] - x[:n]).max() <= 1e-9 * x[:n].max()
    assert res.approach == pytest.approx(x[n], rel=1e-9)


def test_the_spectral_pieces_of_the_periodic_operator_are_its_dense_matrix():
    cell = PeriodicCell(1.0 / 12, 12, 10)
    op = PeriodicOperator(cell, E_STAR)
    rng = np.random.default_rng(3)
    v, w = rng.standard_normal(cell.shape), rng.standard_normal(cell.shape)
    dense = op.dense()
    lam = 0.7 * op.diagonal
    X = op.spectrum(v)
    out = op.brick(op.mix(X, op.symbol(lam)))
    np.testing.assert_allclose(out.ravel(), dense @ v.ravel() + lam * v.ravel(), rtol=0, atol=1e-13 * np.abs(out).max())
    assert op.inner(X, op.spectrum(w)) == pytest.approx(float(np.sum(v * w)), rel=1e-13)
    odd = PeriodicCell(1.0 / 11, 11, 10)  # an odd number of columns: no Nyquist column in the spectrum
    op_odd = PeriodicOperator(odd, E_STAR)
    v_odd, w_odd = rng.standard_normal(odd.shape), rng.standard_normal(odd.shape)
    assert op_odd.inner(op_odd.spectrum(v_odd), op_odd.spectrum(w_odd)) == pytest.approx(float(np.sum(v_odd * w_odd)),
                                                                                         rel=1e-13)
    z = op.brick(op.mix(op.spectrum(v), op.symbol(lam, inverse=True)))  # (C + lam)^-1 on zero-mean vectors
    v0 = v - v.mean()
    z0 = op.brick(op.mix(op.spectrum(v0), op.symbol(lam, inverse=True)))
    np.testing.assert_allclose(dense @ z0.ravel() + lam * z0.ravel(), v0.ravel(), rtol=0, atol=1e-11 * np.abs(v0).max())
    np.testing.assert_allclose(z, op.preconditioner(lam=lam)(v), rtol=0, atol=1e-13 * np.abs(z).max())


def _self_affine(cell, seed=2026, hurst=0.8, rolloff=4, cutoff=128):
    """Gap of a seeded self-affine surface (rms slope 0.1) at the nodes: one Fourier series per row parity."""
    rng = np.random.default_rng(seed)
    lx, ly = cell.size
    m, n = np.meshgrid(np.arange(-cutoff, cutoff + 1), np.arange(-cutoff, cutoff + 1))
    gx, gy = 2 * math.pi * m / lx, 2 * math.pi * n / ly
    g = np.hypot(gx, gy)
    q_r, q_s = 2 * math.pi * rolloff / lx, 2 * math.pi * cutoff / lx
    amp = np.maximum(g, q_r) ** -(1 + hurst) * ((g > 0) & (g <= q_s))
    z = amp * (rng.standard_normal(g.shape) + 1j * rng.standard_normal(g.shape))
    z *= 0.1 / math.sqrt(0.5 * np.sum(np.abs(z) ** 2 * g * g))
    out = np.empty(cell.shape)
    half = (cell.n_rows // 2, cell.n_cols)
    for parity in (0, 1):  # odd rows are shifted by (c/2, c sqrt3/2)
        shift = np.exp(1j * parity * (gx * cell.step / 2 + gy * cell.step * math.sqrt(3) / 2))
        grid = np.zeros(half, dtype=complex)
        np.add.at(grid, (np.mod(n, half[0]), np.mod(m, half[1])), z * shift)
        out[parity::2] = np.fft.ifft2(grid).real * grid.size
    return out.max() - out


def test_periodic_qp_keeps_its_conjugate_directions_when_the_contact_changes():
    """On a rough cell whose contact set changes over most of the iterations, the QP in the Fourier basis and the
    general loop (which keeps its directions by the same rule) reach the answer of a constrained CG that restarts
    at every entering node (tests/bem/restarted_cg.py) in fewer iterations (measured: 60, and 51 with the cell's
    preconditioner corrected at the contact's edges, bem.periodic.edge, and its first steps' rule, against 82)."""
    cell = PeriodicCell(1.0 / 256, 256, 256)
    h = _self_affine(cell)
    op = PeriodicOperator(cell, E_STAR)
    force = 0.03 * cell.area
    pre = op.preconditioner()
    ref, restarted = restarted_cg(op.matvec, pre, op.diagonal, h, np.ones(cell.shape, bool), force / cell.node_area)
    general = solve_qp(op, h, force=force, preconditioner=pre, rtol=1e-10)
    fast = solve_periodic_qp(op, h, force=force, rtol=1e-10)
    assert general.converged and fast.converged
    assert sum(general.history["changes"]) > 50 * general.iterations  # the contact set moves a lot
    for sol in (general, fast):
        assert np.abs(sol.p - ref).max() <= 1e-8 * ref.max()
        assert sol.iterations <= 0.75 * restarted


@pytest.mark.parametrize("control", ["force", "approach"])
def test_periodic_qp_with_a_compliance_per_node_equals_the_general_qp(control):
    """Newton's model QP: a compliance per node, some nodes soft (Jacobi), started from the caller's
    iterate and its product."""
    from bem.kalker import compliance_preconditioner

    cell = CELL
    h = _rough(cell, seed=11)
    op = PeriodicOperator(cell, E_STAR)
    rng = np.random.default_rng(4)
    D = op.diagonal * np.where(rng.random(cell.shape) < 0.2, 30.0, 0.5) * rng.uniform(0.5, 2.0, cell.shape)
    kw = dict(force=0.03 * cell.area) if control == "force" else dict(approach=float(np.quantile(h, 0.3)))
    x0 = np.where(h < np.quantile(h, 0.3), 1.0, 0.0)
    if control == "force":
        x0 *= kw["force"] / cell.node_area / x0.sum()
    ref = solve_qp(op, h, lam=D, x0=x0, preconditioner=compliance_preconditioner(op, D, x0 > 0), rtol=1e-10, **kw)
    fast = solve_periodic_qp(op, h, lam=D, x0=x0, u0=op.matvec(x0), rtol=1e-10, **kw)
    assert ref.converged and fast.converged
    assert 0.05 < np.mean(fast.p > 0) < 0.95 and np.any((D > 4 * op.diagonal) & (fast.p > 0))
    assert np.abs(fast.p - ref.p).max() <= 1e-8 * ref.p.max()
    u = op.dense() @ fast.p.ravel()
    np.testing.assert_allclose(fast.displacement.ravel(), u, rtol=0, atol=1e-12 * np.abs(u).max())
    g = u + D.ravel() * fast.p.ravel() + h.ravel() - fast.approach
    kkt = kkt_residual(fast.p.ravel(), g, displacement_scale=float(np.abs(u + D.ravel() * fast.p.ravel()).max()),
                       force=kw.get("force"), node_area=cell.node_area)
    assert kkt <= 1e-10


@pytest.mark.parametrize("per_node", [False, True])
def test_periodic_qp_runs_its_early_products_in_single_precision_and_ends_in_double(monkeypatch, per_node):
    """A solve that starts far from the answer transforms in single precision until the KKT residual
    falls below SINGLE_ABOVE, then in double precision: the answer is the all-double one, its
    displacement is the double-precision product, and the KKT conditions hold to rtol."""
    import bem.periodic.qp as qp

    cell = PeriodicCell(1.0 / 128, 128, 128)
    h = _self_affine(cell)
    op = PeriodicOperator(cell, E_STAR)
    force = 0.03 * cell.area
    lam = op.diagonal * np.random.default_rng(2).uniform(0.2, 2.0, cell.shape) if per_node else 0.0
    seen = []
    spectrum = op.spectrum
    monkeypatch.setattr(op, "spectrum", lambda v, out=None: seen.append(v.dtype) or spectrum(v, out=out))
    res = solve_periodic_qp(op, h, force=force, lam=lam, rtol=1e-10)
    assert res.converged
    assert res.history["residual"][0] > qp.SINGLE_START * qp.SINGLE_ABOVE
    # single-precision recomputations of C p beyond the transforms that are single precision in every
    # iteration (the preconditioner's and the search direction's, and one for M 1 per node), then double ones
    assert seen.count(np.float32) > 2 * res.iterations + 1 + 3 and seen.count(np.float64) >= 3
    monkeypatch.setattr(qp, "SINGLE_START", math.inf)  # double precision throughout
    ref = solve_periodic_qp(PeriodicOperator(cell, E_STAR), h, force=force, lam=lam, rtol=1e-10)
    assert ref.converged
    assert np.abs(res.p - ref.p).max() <= 1e-8 * ref.p.max()
    u = PeriodicOperator(cell, E_STAR).matvec(res.p)
    assert res.displacement.dtype == np.float64
    np.testing.assert_allclose(res.displacement, u, rtol=0, atol=1e-12 * np.abs(u).max())
    g = (u + lam * res.p + h - res.approach).ravel()
    kkt = kkt_residual(res.p.ravel(), g, displacement_scale=float(np.abs(u + lam * res.p).max()), force=force,
                       node_area=cell.node_area)
    assert kkt <= 1e-10


def test_an_unconfirmed_loose_periodic_qp_stays_in_single_precision(monkeypatch):
    """Newton's early model QPs (``confirm=False``, ``rtol >= SINGLE_ABOVE``) transform in single
    precision after the caller's product; their displacement is ``C p`` to single precision and
    their answer meets the KKT conditions to rtol on the exact product."""
    import bem.periodic.qp as qp

    cell = PeriodicCell(1.0 / 128, 128, 128)
    h = _self_affine(cell)
    op = PeriodicOperator(cell, E_STAR)
    force = 0.03 * cell.area
    x0 = solve_periodic_qp(op, h, force=force, rtol=5e-3).p  # a start below SINGLE_START * SINGLE_ABOVE
    u0 = op.matvec(x0)
    seen = []
    spectrum = op.spectrum
    monkeypatch.setattr(op, "spectrum", lambda v, out=None: seen.append(v.dtype) or spectrum(v, out=out))
    rtol = 10 * qp.SINGLE_ABOVE
    res = solve_periodic_qp(op, h, force=force, x0=x0, u0=u0, rtol=rtol, confirm=False)
    assert res.converged and res.iterations >= 3
    assert rtol < res.history["residual"][0] < qp.SINGLE_START * qp.SINGLE_ABOVE
    assert set(seen) == {np.dtype(np.float32)}  # no double-precision transform at all
    u = PeriodicOperator(cell, E_STAR).matvec(res.p)
    error = np.abs(res.displacement - u).max() / np.abs(u).max()
    assert 1e-12 < error < 1e-5  # single precision: not exact, far below rtol
    g = (u + h - res.approach).ravel()
    kkt = kkt_residual(res.p.ravel(), g, displacement_scale=float(np.abs(u).max()), force=force,
                       node_area=cell.node_area)
    assert kkt <= rtol


@pytest.mark.parametrize("with_u0", [False, True])
def test_overwrite_x0_holds_the_iterate_in_x0_and_without_it_x0_is_untouched(with_u0):
    """``overwrite_x0``: the same answer, computed in the caller's array (returned as the solution's ``p``);
    without it the caller's ``x0`` keeps its values, negative entries included."""
    cell = CELL
    h = _rough(cell, seed=3)
    op = PeriodicOperator(cell, E_STAR)
    force = 0.03 * cell.area
    start = solve_periodic_qp(op, h, force=force, rtol=1e-2).p
    start[0, :3] = -1.0  # entries the solver clips
    kw = dict(force=force, rtol=1e-10, u0=op.matvec(np.maximum(start, 0.0)) if with_u0 else None)
    if with_u0:  # the caller's iterate as it is (the u0 path clips nothing)
        start = np.maximum(start, 0.0)
    x0 = start.copy()
    kept = solve_periodic_qp(op, h, x0=x0, **kw)
    np.testing.assert_array_equal(x0, start)  # not modified
    assert not np.shares_memory(kept.p, x0)
    own = solve_periodic_qp(op, h, x0=x0, overwrite_x0=True, **kw)
    assert own.converged and own.p is x0  # the iterate lived in x0
    np.testing.assert_array_equal(own.p, kept.p)
    assert own.iterations == kept.iterations


@pytest.mark.parametrize("with_u0", [False, True])
def test_overwrite_x0_copies_an_array_it_cannot_hold_the_iterate_in(with_u0):
    """A float32 or read-only ``x0`` is not written even with ``overwrite_x0``, started from it alone or with
    its product."""
    cell = CELL
    h = _rough(cell, seed=3)
    op = PeriodicOperator(cell, E_STAR)
    force = 0.03 * cell.area
    start = solve_periodic_qp(op, h, force=force, rtol=1e-2).p
    kw = dict(force=force, rtol=1e-10, u0=op.matvec(start) if with_u0 else None)
    ref = solve_periodic_qp(op, h, x0=start.copy(), **kw)
    for x0 in (start.astype(np.float32), start.copy()):
        x0.flags.writeable = x0.dtype == np.float32  # the float64 one read-only
        before = x0.copy()
        res = solve_periodic_qp(op, h, x0=x0, overwrite_x0=True, **kw)
        np.testing.assert_array_equal(x0, before)
        assert res.converged and res.p is not x0
        if x0.dtype == np.float64:
            np.testing.assert_array_equal(res.p, ref.p)
