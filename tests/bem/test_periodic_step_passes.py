"""The compiled passes of the periodic QP's step and of the prolongation (bem.periodic.step_passes) against their NumPy
forms, bit for bit; the QP with them against the QP without them; the kernel's Fourier terms made in parts."""

import sys

import numpy as np
import pytest

import bem.periodic.step_passes as step_passes
from bem import fft
from bem.periodic import PeriodicCell, kernel
from bem.periodic.qp import solve_periodic_qp

from .fourier_qp_cases import assert_same_bits, cell_qp

numba = pytest.importorskip("numba", reason="the compiled passes need numba (contactlab[fast])")

N = (1 << 17) + 5  # over bem.fft's threshold for parts: split over the threads, parts of unequal length


def _forms():
    ref, fast = step_passes.step_kernels(1), step_passes.step_kernels(step_passes.MIN_NODES)
    assert not ref.compiled and fast.compiled
    return ref, fast


def _identical(a, b):
    return np.array_equal(a, b, equal_nan=True) and np.asarray(a).dtype == np.asarray(b).dtype


@pytest.mark.parametrize("kind", ["clipped", "positive", "nan"])
def test_the_compiled_move_gives_the_numpy_forms_numbers(two_threads, kind):
    """``max(p_c0 - tau t_c, 0)``, the clipped nodes and the two flags as NumPy makes them, the inputs untouched:
    with nodes clipped in every part, with none, and with a NaN (neither clipped nor positive)."""
    rng = np.random.default_rng(3)
    p_c0 = rng.uniform(0.1, 1.0, N)
    t_c = rng.standard_normal(N) * (0.1 if kind == "positive" else 3.0)
    if kind == "nan":
        t_c[N // 3] = np.nan
    tau = 0.17 + 1e-9
    inputs = p_c0.copy(), t_c.copy()
    ref, fast = _forms()
    a, b = ref.move(p_c0, t_c, tau), fast.move(p_c0, t_c, tau)
    assert all(_identical(x, y) for x, y in zip(a[:2], b[:2])) and a[2:] == b[2:]
    assert a[2:] == {"clipped": (True, False), "positive": (False, True), "nan": (True, False)}[kind]
    assert _identical(p_c0, inputs[0]) and _identical(t_c, inputs[1])
    if kind == "clipped":  # clipped in both parts of the two threads
        assert b[1][: N // 2].any() and b[1][N // 2 :].any()


@pytest.mark.parametrize("soft_share", [0.0, 0.07, 1.0])
def test_the_compiled_soft_gather_gives_the_numpy_forms_numbers(two_threads, soft_share):
    """The preconditioned gap gathered from its float32 brick in double precision, the Jacobi estimate ``r / (C_nn +
    D)`` at the soft nodes (none, some in every part, all), as NumPy makes them; the inputs untouched."""
    rng = np.random.default_rng(8)
    idx = np.sort(rng.choice(4 * N, N, replace=False))
    x = rng.standard_normal(4 * N).astype(np.float32)
    soft = rng.uniform(size=N) < soft_share
    r, D = rng.standard_normal(N), rng.uniform(0.0, 50.0, N)
    inputs = [a.copy() for a in (x, idx, soft, r, D)]
    ref, fast = _forms()
    a, b = ref.soft_gather(x, idx, soft, r, D, 0.75), fast.soft_gather(x, idx, soft, r, D, 0.75)
    assert _identical(a, b) and a.dtype == np.float64
    assert _identical(a[~soft], x[idx[~soft]].astype(np.float64)) and _identical(a[soft], (1 / (0.75 + D) * r)[soft])
    assert all(_identical(v, w) for v, w in zip((x, idx, soft, r, D), inputs))


@pytest.mark.parametrize("s", [1.0, 1.0 + 3e-7])
def test_the_compiled_scale_and_put_give_the_numpy_forms_numbers(two_threads, s):
    rng = np.random.default_rng(5)
    idx = np.sort(rng.choice(4 * N, N, replace=False))
    p_c = rng.uniform(0.0, 2.0, N)
    p_ref, p_fast = rng.standard_normal((2, 4 * N))
    p_fast[:] = p_ref
    c_ref, c_fast, idx0 = p_c.copy(), p_c.copy(), idx.copy()
    ref, fast = _forms()
    assert ref.scale_put(p_ref, idx, c_ref, s) is p_ref and fast.scale_put(p_fast, idx, c_fast, s) is p_fast
    assert _identical(p_fast, p_ref) and _identical(c_fast, c_ref) and _identical(idx, idx0)
    assert _identical(c_ref, p_c * s if s != 1.0 else p_c) and _identical(p_ref[idx], c_ref)


@pytest.mark.parametrize("fill", [True, False])
def test_the_compiled_write_gives_the_numpy_forms_brick(two_threads, fill):
    """The float32 brick: 0 where filled (the values before it where not) and the values rounded to float32 at the
    nodes, in parts over the cell's nodes that each hold their own nodes; the rounded values returned."""
    rng = np.random.default_rng(11)
    shape = (512, 2 * N // 512 + 2)
    idx = np.sort(rng.choice(shape[0] * shape[1], N // 3, replace=False))
    values = rng.standard_normal(idx.size) * 1e3
    values[7] = np.nan
    b_ref = np.full(shape, 7.0, dtype=np.float32)
    b_fast = b_ref.copy()
    ref, fast = _forms()
    last_ref, last_fast = ref.write(b_ref, idx, values, fill), fast.write(b_fast, idx, values, fill)
    assert _identical(b_fast, b_ref) and _identical(last_fast, last_ref) and last_ref.dtype == np.float32
    off = np.ones(b_ref.size, dtype=bool)
    off[idx] = False
    assert np.all(b_ref.reshape(-1)[off] == (0.0 if fill else 7.0))


def test_the_compiled_prolongation_is_the_slices(monkeypatch):
    """:meth:`PeriodicCell.prolong` on a cell of ``MIN_NODES`` nodes (the compiled rows, on one and two threads) gives
    the numbers of its slices bit for bit."""
    fine = PeriodicCell(1.0 / 512, 512, step_passes.MIN_NODES // 512)
    values = np.random.default_rng(2).standard_normal(fine.coarsen().shape)
    outs, asked = [], []
    monkeypatch.setattr("bem.periodic.cell.prolong_kernel", lambda: asked.append(1) or step_passes.prolong_kernel())
    for threads in (1, 2):
        previous = fft.set_threads(threads)
        try:
            outs.append(fine.prolong(values))
        finally:
            fft.set_threads(previous)
    assert len(asked) == 2  # the compiled rows made both
    monkeypatch.setattr("bem.periodic.cell.MIN_NODES", 10**12)  # the slices
    slices = fine.prolong(values)
    assert len(asked) == 2
    assert all(_identical(out, slices) for out in outs)
    assert _identical(slices[0::2][0::2, 0::2], values[0::2])  # the coarse nodes themselves


def test_the_kernel_spectra_made_in_parts_are_the_serial_ones():
    """The cell's spectra with the Fourier sum's blocks of terms made on two threads (each block its own rows of
    modes) are those made on one, bit for bit."""
    spectra = []
    for threads in (1, 2):
        previous = fft.set_threads(threads)
        try:
            spectra.append(kernel.periodic_spectra(1024, 768))
        finally:
            fft.set_threads(previous)
    assert _identical(spectra[0], spectra[1])


class _Counted:
    """The compiled step kernels, the names of the kernels called kept in ``calls``."""

    compiled = True

    def __init__(self, calls):
        self.calls, self.real = calls, step_passes.step_kernels(step_passes.MIN_NODES)

    def __getattr__(self, name):
        self.calls.append(name)
        return getattr(self.real, name)


@pytest.mark.parametrize("case", ["smooth", "per_node"])
@pytest.mark.parametrize("control", ["force", "approach"])
def test_the_qp_with_the_compiled_step_passes_is_the_qp_without(monkeypatch, two_threads, case, control):
    """On a cell made to take the compiled step passes (threshold lowered) the QP gives bit for bit the pressures,
    displacement, history and products of the QP with the NumPy forms, and the passes were used."""
    op, h, kw = cell_qp(case)
    if control == "approach":
        kw.pop("force")
        kw["approach"] = 0.012
    counted = _Counted(calls := [])
    monkeypatch.setattr("bem.periodic.qp.step_kernels", lambda n, bk=None: counted)
    with_kernels = solve_periodic_qp(op, h, **kw)
    n_with = op.n_matvec
    assert {"move", "scale_put", "write"} | ({"soft_gather"} if case == "per_node" else set()) <= set(calls)
    monkeypatch.setattr("bem.periodic.qp.step_kernels", lambda n, bk=None: step_passes.step_kernels(1))
    op.n_matvec = 0
    without = solve_periodic_qp(op, h, **kw)
    assert_same_bits(with_kernels, without, n_with, op.n_matvec)


def test_small_cells_and_no_numba_take_the_numpy_forms(monkeypatch):
    assert not step_passes.step_kernels(step_passes.MIN_NODES - 1).compiled
    assert step_passes.load() is True
    monkeypatch.setitem(sys.modules, "numba", None)  # an import of numba fails
    assert step_passes._compile() is None
    monkeypatch.setattr(step_passes, "_COMPILED", [None])  # as _compile() gave it
    monkeypatch.setattr(step_passes, "_PROLONG", [])
    assert not step_passes.step_kernels(10 * step_passes.MIN_NODES).compiled
    assert step_passes.prolong_kernel() is None
    assert step_passes.load() is False
