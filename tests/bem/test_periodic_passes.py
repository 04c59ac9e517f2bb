"""The compiled passes of the periodic QP (bem.periodic.passes) against their NumPy forms (bit for bit, the block
product to the last bit of its precision), and the QP with them against the QP without them."""

import sys

import numpy as np
import pytest

import bem.periodic.passes as passes
import bem.periodic.spectra as spectra
from bem.periodic import PeriodicCell, PeriodicOperator
from bem.periodic.qp import solve_periodic_qp

from .fourier_qp_cases import assert_same_bits, cell_qp

numba = pytest.importorskip("numba", reason="the compiled passes need numba (contactlab[fast])")

N = (1 << 17) + 5  # over bem.fft's threshold for parts: split over the threads, parts of unequal length


def _compiled():
    k = passes.kernels(passes.MIN_NODES)
    assert k.compiled
    return k


def _identical(a, b):
    return np.array_equal(a, b, equal_nan=True) and np.asarray(a).dtype == np.asarray(b).dtype


@pytest.mark.parametrize("single", [False, True])
def test_the_compiled_passes_give_the_numpy_forms_numbers(two_threads, single):
    """``gap``, ``subtract_scaled`` and ``gather`` give bit for bit the numbers of the NumPy forms, with the
    iterate's product in double and in single precision, and leave their inputs as they were."""
    rng = np.random.default_rng(7)
    ref, fast = passes.numpy_kernels(), _compiled()
    u = rng.standard_normal(N).astype(np.float32 if single else np.float64)
    h = rng.standard_normal(N) * 1e-3
    u[N - 1], h[3] = 10.0, -20.0  # the extremes in the last node of the last part and in the first part
    u0, h0 = u.copy(), h.copy()
    g_ref, g_fast = np.empty(N), np.full(N, np.nan)
    a, b = ref.gap(u, h, g_ref), fast.gap(u, h, g_fast)
    assert a[0] is g_ref and b[0] is g_fast and a[1:] == b[1:]
    assert _identical(g_fast, g_ref)
    assert _identical(u, u0) and _identical(h, h0)
    below = -np.abs(u0)  # u below 0 at every node: its maximum must not come out as 0
    assert fast.gap(below, -h0, np.empty(N))[1:] == ref.gap(below, -h0, np.empty(N))[1:]
    r = rng.standard_normal(N).astype(np.float32)
    tau = 0.37 + 1e-9
    expected, v = u0.copy(), u0.copy()
    ref.subtract_scaled(expected, r.copy(), tau)
    fast.subtract_scaled(v, r.copy(), tau)
    assert _identical(v, expected)
    assert not _identical(expected, u0)
    s = 1.0 + 1.1e-4  # the rescaling to the force, in u's precision (not a float32)
    expected, v = u0.copy(), u0.copy()
    ref.subtract_scaled(expected, r.copy(), tau, s)
    fast.subtract_scaled(v, r.copy(), tau, s)
    assert _identical(v, expected)
    step = u0.copy()
    step -= r * np.float32(tau)
    step *= step.dtype.type(s)
    assert _identical(expected, step)
    shape = (400, 320)  # 2-D views that are not contiguous (no flat view): written in place all the same
    v2, r2 = u0[:np.prod(shape)].reshape(shape), r[:np.prod(shape)].reshape(shape)
    whole, g_whole = np.zeros((400, 640), dtype=u0.dtype), np.zeros((400, 640))
    view, g_view = whole[:, :320], g_whole[:, 320:]
    view[...] = v2
    fast.subtract_scaled(view, r2.copy(), tau)
    expected2 = v2.copy()
    ref.subtract_scaled(expected2, r2.copy(), tau)
    assert _identical(view, expected2)
    assert fast.gap(v2, h[:np.prod(shape)].reshape(shape), g_view)[1:] == ref.gap(
        v2, h[:np.prod(shape)].reshape(shape), np.empty(shape))[1:]
    assert _identical(g_view, v2 + h[:np.prod(shape)].reshape(shape))
    idx = np.flatnonzero(rng.random(N) < 0.3)
    x = r.copy()
    got = fast.gather(x, idx)
    assert _identical(got, ref.gather(x, idx)) and got.dtype == np.float64
    assert _identical(x, r)
    assert fast.gather(x, idx[:0]).shape == (0,)


@pytest.mark.parametrize("single", [False, True])
def test_the_compiled_passes_of_the_gap_give_the_numpy_forms_numbers(two_threads, single):
    """``scan`` and ``gap_at`` (the gap ``u + h`` read without an array of it) give bit for bit the numbers of the
    NumPy forms, in parts, on contiguous and strided arrays, and leave their inputs as they were."""
    rng = np.random.default_rng(11)
    ref, fast = passes.numpy_kernels(), _compiled()
    u = rng.standard_normal(N).astype(np.float32 if single else np.float64)
    h, p = rng.standard_normal(N) * 1e-3, np.where(rng.random(N) < 0.6, 0.0, rng.random(N))
    u[N - 1], h[3] = 10.0, -20.0
    keep = [x.copy() for x in (u, h, p)]
    mask, expected = np.ones(N, dtype=bool), np.zeros(N, dtype=bool)
    got, want = fast.scan(u, h, -0.3, p, mask), ref.scan(u, h, -0.3, p, expected)
    assert got[0] is mask and got[1:] == want[1:]
    assert _identical(mask, expected) and mask.any() and not mask.all()
    below = -np.abs(u)
    assert fast.scan(below, -h, 0.0, p, mask)[1:] == ref.scan(below, -h, 0.0, p, expected)[1:]
    idx = np.flatnonzero(rng.random(N) < 0.3)
    assert _identical(fast.gap_at(u, h, idx), ref.gap_at(u, h, idx))
    assert fast.gap_at(u, h, idx[:0]).shape == (0,)
    for x, y in zip((u, h, p), keep):
        assert _identical(x, y)
    shape = (400, 320)  # strided 2-D views (no flat view): the NumPy forms' numbers all the same
    n = 400 * 320
    wide = np.zeros((400, 640), dtype=u.dtype)
    view = wide[:, :320]
    view[...] = u[:n].reshape(shape)
    h2, p2 = h[:n].reshape(shape), p[:n].reshape(shape)
    out = np.zeros((400, 640), dtype=bool)[:, 320:]
    assert fast.scan(view, h2, -0.3, p2, out)[1:] == ref.scan(view.copy(), h2, -0.3, p2, np.empty(shape, bool))[1:]
    assert _identical(out, (view + h2 < -0.3) & (p2 == 0))
    assert _identical(fast.gap_at(view, h2, idx[idx < n]), (view + h2).reshape(-1)[idx[idx < n]])


@pytest.mark.parametrize("single", [False, True])
def test_the_compiled_scatter_add_gives_the_numpy_forms_numbers(two_threads, single):
    """``add_at`` is NumPy's gather, sum and scatter in ``x``'s precision, bit for bit, over parts of the
    indices on the threads; it leaves the indices and values as they were."""
    rng = np.random.default_rng(11)
    ref, fast = passes.numpy_kernels(), _compiled()
    dtype = np.float32 if single else np.float64
    u0 = rng.standard_normal(N).astype(dtype)
    idx = np.flatnonzero(rng.random(N) < 0.6)  # over 2**17 indices: in parts
    values = rng.standard_normal(idx.size) * 1e-3
    expected, x = u0.copy(), u0.copy()
    keep_idx, keep_values = idx.copy(), values.copy()
    assert ref.add_at(expected, idx, values) is expected and fast.add_at(x, idx, values) is x
    assert _identical(x, expected) and not _identical(x, u0)
    flat = u0.copy()
    flat[idx] = (u0[idx] + values).astype(dtype)
    assert _identical(expected, flat)
    assert _identical(idx, keep_idx) and _identical(values, keep_values)
    y = u0.copy()
    assert fast.add_at(y, idx[:0], values[:0]) is y and _identical(y, u0)
    # a multiple of the values (a gap's offset after a rescaling), made per node in the same roundings
    times = -3.7e-3
    expected, x = u0.copy(), u0.copy()
    assert ref.add_at(expected, idx, values, times) is expected and fast.add_at(x, idx, values, times) is x
    flat = u0.copy()
    flat[idx] = (u0[idx] + times * values).astype(dtype)
    assert _identical(x, expected) and _identical(expected, flat) and _identical(values, keep_values)


def test_a_nan_propagates_as_in_numpy(two_threads):
    """A NaN in ``u`` makes every extreme NaN; a NaN in ``h`` only the gap's minimum (NumPy's extremes)."""
    ref, fast = passes.numpy_kernels(), _compiled()
    for where in ("u", "h"):
        u, h = np.linspace(-1.0, 1.0, N), np.zeros(N)
        (u if where == "u" else h)[N - 10] = np.nan
        a, b = ref.gap(u, h, np.empty(N))[1:], fast.gap(u, h, np.empty(N))[1:]
        assert _identical(np.array(a), np.array(b))
        assert np.isnan(a[0]) and np.isnan(a[1]) == (where == "u")
        assert _identical(np.array(fast.scan(u, h, 0.0, u, np.empty(N, dtype=bool))[1:]), np.array(a))


def test_small_cells_and_no_numba_take_the_numpy_forms(monkeypatch):
    assert passes.kernels(passes.MIN_NODES - 1) is passes.numpy_kernels()
    assert passes.load() is True
    monkeypatch.setitem(sys.modules, "numba", None)  # an import of numba fails
    assert passes._compile() is None
    monkeypatch.setattr(passes, "_COMPILED", [None])  # as _compile() gave it
    assert passes.kernels(10 * passes.MIN_NODES) is passes.numpy_kernels()
    assert passes.load() is False


class _Counted:
    """The compiled kernels, the names of the kernels called kept in ``calls``."""

    compiled = True

    def __init__(self, calls):
        self.calls, self.real = calls, _compiled()

    def __getattr__(self, name):
        self.calls.append(name)
        return getattr(self.real, name)


@pytest.mark.parametrize("case", ["smooth", "per_node", "hardness"])
def test_the_qp_with_the_compiled_passes_is_the_qp_without(monkeypatch, two_threads, case):
    """On a cell made to take the compiled element-wise passes (threshold lowered; the block products NumPy's) the QP
    gives bit for bit the pressures, displacement, history and products of the QP with the NumPy forms, and the
    passes were used."""
    op, h, kw = cell_qp(case)
    calls = []
    monkeypatch.setattr(passes, "MIN_NODES", 1)
    monkeypatch.setattr(passes, "_COMPILED", [_Counted(calls)])
    monkeypatch.setattr(spectra, "kernels", lambda n: passes.numpy_kernels())
    with_kernels = solve_periodic_qp(op, h, **kw)
    n_with = op.n_matvec
    gap = {"gap"} if case == "hardness" else {"scan", "gap_at"}  # an array of the gap with the bound
    assert gap | {"subtract_scaled", "gather", "merge"} | ({"add_at"} if case == "per_node" else set()) <= set(calls)
    monkeypatch.setattr(passes, "MIN_NODES", 10**12)
    op.n_matvec = 0
    without = solve_periodic_qp(op, h, **kw)
    assert_same_bits(with_kernels, without, n_with, op.n_matvec)


@pytest.mark.parametrize("single", [False, True])
@pytest.mark.parametrize("inverse", [False, True])
@pytest.mark.parametrize("n_cols", [64, 63])  # with and without a Nyquist column
def test_the_compiled_block_product_is_the_numpy_one(two_threads, single, inverse, n_cols):
    """The compiled 2 x 2 block product equals NumPy's to the last bits of its precision (NumPy's loops may fuse a
    multiply and an add), in place and not, and its sum equals the weighted sum of the spectrum and the product
    and the cell's ``sum v.Cv``; a sum for each block of rows."""
    cell = PeriodicCell(1.0 / n_cols, n_cols, 4200)  # 2100 x 2 x 33 entries: over the threshold for parts
    op = PeriodicOperator(cell, 1.0)
    v = np.random.default_rng(2).standard_normal(cell.shape)
    X = op.spectrum(v.astype(np.float32) if single else v)
    symbol = op.symbol(0.3 * op.diagonal, inverse=inverse, single=single)
    rows = 97  # blocks of unequal count over the parts, the last one short
    ref, ref_sums = spectra.numpy_mixed(X, symbol, np.empty_like(X), n_cols % 2 == 0, rows)
    out, sums = _compiled().mix(X, symbol, np.empty_like(X), n_cols % 2 == 0, rows)
    eps = np.finfo(np.float32 if single else np.float64).eps
    assert out.dtype == X.dtype and len(sums) == -(-X.shape[0] // rows)
    np.testing.assert_allclose(out, ref, rtol=0, atol=4 * eps * np.abs(ref).max())
    assert sum(sums) == pytest.approx(sum(ref_sums), rel=1e-5 if single else 1e-12)
    exact = spectra.weighted_dot(X.astype(np.complex128), out.astype(np.complex128), n_cols % 2 == 0)
    assert sum(sums) == pytest.approx(exact, rel=1e-13)
    if not inverse:
        u = op.brick(out.copy())
        assert sum(sums) / (cell.n_rows // 2 * n_cols) == pytest.approx(float(np.sum(v * u)), rel=1e-5 if single
                                                                          else 1e-12)
    inplace = X.copy()
    got, none = _compiled().mix(inplace, symbol, inplace, None, rows)
    assert got is inplace and len(none) == 0
    np.testing.assert_array_equal(inplace, out)


@pytest.mark.parametrize("case", ["smooth", "per_node", "hardness", "coated"])
def test_the_qp_with_every_compiled_pass_solves_the_same_problem(monkeypatch, two_threads, case):
    """With the compiled block products too the QP converges to the answer of the NumPy QP (to the tolerance's
    order), in as many iterations give or take one. The stiff coating's count moves with any rounding of the
    single-precision products (38 to 42 iterations with NumPy's symbol scaled by 1 -+ 1e-7, 33 compiled): there
    only the answer is compared."""
    op, h, kw = cell_qp(case)
    calls = []
    monkeypatch.setattr(passes, "MIN_NODES", 1)
    monkeypatch.setattr(passes, "_COMPILED", [_Counted(calls)])
    fast = solve_periodic_qp(op, h, **kw)
    assert "mix" in calls
    monkeypatch.setattr(passes, "MIN_NODES", 10**12)
    plain = solve_periodic_qp(op, h, **kw)
    assert fast.converged and plain.converged and fast.kkt_residual <= kw["rtol"]
    assert case == "coated" or abs(fast.iterations - plain.iterations) <= 1
    np.testing.assert_allclose(fast.p, plain.p, rtol=0, atol=1e-8 * plain.p.max())


@pytest.mark.parametrize("n, n_new, stay", [(40, 7, 0.8), (40, 0, 0.5), (40, 5, 0.0), (0, 4, 1.0), (25, 6, 1.0)])
def test_the_compiled_merge_is_the_numpy_insert(n, n_new, stay):
    """The next contact from the step: the nodes that stayed and the entering ones, disjoint and each sorted, merged
    in order with their values, and where the entering ones went among those that stayed (``numpy.insert``'s
    positions), including entering nodes before, between and after all others."""
    rng = np.random.default_rng(n + n_new)
    nodes = np.sort(rng.choice(200, n + n_new, replace=False))
    old = np.sort(rng.permutation(nodes)[:n])
    new = np.setdiff1d(nodes, old)
    stayed = rng.random(n) < stay
    vals, new_vals = rng.standard_normal(n), rng.standard_normal(new.size)
    kept = old[stayed]
    at_ref = np.searchsorted(kept, new)
    out_idx, out_vals = np.full(n + n_new + 3, -1), np.full(n + n_new + 3, np.nan)
    at = np.empty(new.size, dtype=np.intp)
    m = _compiled().merge(old, vals, stayed, new, new_vals, out_idx, out_vals, at)
    assert m == kept.size + new.size
    np.testing.assert_array_equal(out_idx[:m], np.insert(kept, at_ref, new))
    np.testing.assert_array_equal(out_vals[:m], np.insert(vals[stayed], at_ref, new_vals))
    np.testing.assert_array_equal(at, at_ref)
    assert np.all(out_idx[m:] == -1)  # nothing written beyond


def test_contact_nodes_with_the_merge_make_the_contacts_of_numpy_insert_in_two_held_pairs():
    """A sequence of steps that change the contact: with the compiled merge every contact read, its pressures and
    what is carried over to it equal those made by ``numpy.insert``; each is written into one of two pairs of
    arrays held from step to step, never the pair of the contact it replaces."""
    from bem.backend import get_backend
    from bem.periodic.qp_parts import ContactNodes

    bk = get_backend("cpu")
    rng = np.random.default_rng(3)
    shape = (12, 10)
    p = np.where(rng.random(shape) < 0.4, rng.random(shape), 0.0)
    merged, plain = ContactNodes(bk, p, _compiled().merge), ContactNodes(bk, p)
    buffers = set()
    for k in range(12):
        (idx_m, p_m), (idx_p, p_p) = merged.read(p), plain.read(p)
        np.testing.assert_array_equal(idx_m, idx_p)
        np.testing.assert_array_equal(p_m, p_p)
        assert idx_m.dtype == idx_p.dtype and p_m.dtype == p_p.dtype
        if k:  # made from the step: in a held pair
            values = rng.standard_normal(p.size)
            np.testing.assert_array_equal(merged.over(idx_m, values.take, values[before]),
                                          plain.over(idx_p, values.take, values[before]))
            held = [i for i, pair in enumerate(merged._pairs) if pair is not None and np.shares_memory(pair[0], idx_m)]
            assert len(held) == 1 and np.shares_memory(merged._pairs[held[0]][1], p_m)
            buffers.update(pair[0].__array_interface__["data"][0] for pair in merged._pairs if pair is not None)
        step = p_m * rng.uniform(0.5, 1.5, p_m.size)
        step[rng.random(step.size) < 0.2] = 0.0  # some leave
        off = np.flatnonzero(p.ravel() == 0)
        entering = np.sort(rng.choice(off, min(3, off.size), replace=False))
        p_o = np.where(rng.random(entering.size) < 0.7, rng.random(entering.size), 0.0)  # one may not enter
        for nodes in (merged, plain):
            nodes.stepped(step, True, entering, p_o)
        before = idx_m
        replaced = [pair for pair in merged._pairs if pair is not None and np.shares_memory(pair[0], idx_m)]
        assert not any(np.shares_memory(pair[0], merged.next[0]) for pair in replaced)
        p.reshape(-1)[idx_m] = step
        p.reshape(-1)[entering] = p_o
    assert len(buffers) <= 4  # two pairs, made anew only where a contact outgrew them
