"""The compiled passes of a Newton step (bem.newton_passes) against their NumPy forms, bit for bit, and Newton's
solve with them against the solve without them."""

import sys

import numpy as np
import pytest

import bem
from bem import newton_passes
from bem.extremes import MIN_NODES

numba = pytest.importorskip("numba", reason="the compiled passes need numba (contactlab[fast])")

N = MIN_NODES + 77  # parts of unequal length on the threads


def _same(a, b):
    return a.dtype == b.dtype and a.tobytes() == b.tobytes()


def _numpy_forms(monkeypatch):
    """The NumPy forms from here on (as without numba)."""
    monkeypatch.setattr(newton_passes, "_COMPILED", [None])


def _arrays(seed):
    rng = np.random.default_rng(seed)
    p, q = np.maximum(rng.standard_normal(N), 0.0), rng.standard_normal(N)
    u, uq = rng.standard_normal(N), rng.standard_normal(N)
    q[3] = np.nan  # stays NaN (NumPy's maximum)
    return p, q, u, uq


@pytest.mark.parametrize("threads", [1, 2])
def test_the_advance_is_numpys(monkeypatch, threads):
    from bem import fft

    previous = fft.set_threads(threads)
    try:
        p, q, u, uq = _arrays(1)
        given = p.copy(), u.copy()
        q1, uq1 = q.copy(), uq.copy()
        newton_passes.advance(p, q1, u, uq1, 0.37)
        assert newton_passes._COMPILED[0] is not None  # the compiled kernel took them
    finally:
        fft.set_threads(previous)
    _numpy_forms(monkeypatch)
    q2, uq2 = q.copy(), uq.copy()
    newton_passes.advance(p, q2, u, uq2, 0.37)
    assert _same(q1, q2) and _same(uq1, uq2)
    assert np.isnan(q1[3]) and (q1[~np.isnan(q1)] >= 0).all() and np.count_nonzero(q1 == 0) > N // 10
    assert _same(p, given[0]) and _same(u, given[1])


def test_the_gather_is_numpys(monkeypatch, two_threads):
    """The compiled gather (taken: ``N`` nodes of lattices of ``2N``) gives NumPy's values in each array's dtype (a
    2-D array read flat), the inputs untouched."""
    rng = np.random.default_rng(2)
    size = 7 * (2 * N // 7)
    arrays = [rng.standard_normal(size), rng.standard_normal(size).astype(np.float32)]
    arrays.append(rng.standard_normal((size // 7, 7)))
    sel = np.sort(rng.choice(size, N, replace=False))
    given = [a.copy() for a in arrays]
    calls, kernels = [], newton_passes._COMPILED[0] if newton_passes.load() else None

    class Counted:
        def __getattr__(self, name):
            calls.append(name)
            return getattr(kernels, name)

    monkeypatch.setattr(newton_passes, "_COMPILED", [Counted()])
    got = newton_passes.gather(sel, *arrays)
    assert "gather" in calls
    for a, g, kept in zip(arrays, got, given):
        assert _same(g, np.take(a.reshape(-1), sel)) and _same(a, kept)


@pytest.mark.parametrize("sign", [1, -1])
@pytest.mark.parametrize("single_d", [False, True])
@pytest.mark.parametrize("single_u", [False, True])
def test_the_compliance_terms_are_numpys(monkeypatch, two_threads, sign, single_d, single_u):
    """``u + D p`` into ``u`` (the QP's start, ``u`` in single or double precision) and ``u - D p`` into another
    array (the QP's elastic displacement), ``D`` per node in single or double precision."""
    rng = np.random.default_rng(3)
    D = rng.uniform(0.0, 2.0, N).astype(np.float32 if single_d else np.float64)
    p, u = np.maximum(rng.standard_normal(N), 0.0), rng.standard_normal(N).astype(np.float32 if single_u else float)
    results = []
    for form in ("compiled", "numpy"):
        if form == "numpy":
            _numpy_forms(monkeypatch)
        v = u.copy()
        out = v if sign > 0 else np.empty(N)
        got = newton_passes.with_compliance(v, D, p, out, sign, scratch=np.empty(N))
        assert got is out
        results.append(got)
    assert _same(*results)
    expected = (u + D.astype(float) * p) if sign > 0 else (u - D.astype(float) * p)
    assert np.array_equal(results[0], expected.astype(results[0].dtype))


def test_small_arrays_and_no_numba_take_the_numpy_forms(monkeypatch):
    assert newton_passes._kernels(MIN_NODES - 1, np.zeros(4)) is None
    assert newton_passes.load() is True
    monkeypatch.setitem(sys.modules, "numba", None)  # an import of numba fails
    assert newton_passes._compile() is None
    monkeypatch.setattr(newton_passes, "_COMPILED", [])
    assert newton_passes.load() is False
    assert newton_passes._kernels(10 * MIN_NODES, np.zeros(4)) is None


def test_newtons_solve_with_the_passes_is_the_solve_without(monkeypatch):
    """A root-layer cell, the compiled passes taken from 4096 entries: the same pressures and iterations bit for bit
    with the compiled passes (each used) and with the NumPy forms."""
    monkeypatch.setattr(newton_passes, "MIN_NODES", 1 << 12)
    n = 256
    cell = bem.periodic.PeriodicCell(1.0 / n, n, n)
    x, y, ly = cell.x, cell.y, cell.size[1]
    h = 0.02 * (np.cos(2 * np.pi * 3 * x) * np.cos(2 * np.pi * 2 * y / ly) + np.sin(2 * np.pi * 7 * x)) ** 2
    kw = dict(step=cell.step, E_star=1.0, mean_pressure=0.01, rtol=1e-9, layer=bem.layers.Root(1e-3))
    assert newton_passes.load()
    calls = []
    kernels = newton_passes._COMPILED[0]

    class Counted:
        def __getattr__(self, name):
            f = getattr(kernels, name)
            return lambda *a: (calls.append(name), f(*a))[1]

    monkeypatch.setattr(newton_passes, "_COMPILED", [Counted()])
    with_passes = bem.solve_periodic(h, **kw)
    assert {"advance", "gather", "added", "subtracted"} <= set(calls)
    _numpy_forms(monkeypatch)
    without = bem.solve_periodic(h, **kw)
    assert with_passes.converged and without.converged
    assert _same(with_passes.p, without.p) and with_passes.iterations == without.iterations
    assert with_passes.n_matvec == without.n_matvec
