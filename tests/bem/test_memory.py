"""What a solve holds in memory: the invariants its peak per node rests on (``benchmarks/memory.py``
measures the peak itself, ``docs/performance.md`` reports it).

- nested iteration lets a coarser level's operator and solution go before the finer level is solved;
- the periodic operator keeps its packed symbol and nothing of the cell's size besides;
- the in-place products by blocks give the numbers of the whole-array formulas, bit for bit;
- the traced peak of a solve per node (NumPy's allocations, :mod:`tracemalloc`) stays below a bound
  on a 256 x 256 problem of each kind, a bound that solves without these invariants exceed (the peaks of both
  are stated at the test).
"""

import gc
import math
import tracemalloc
import weakref

import numpy as np
import pytest

import bem
from bem import fft
from bem.block_symbol import block_product
from bem.periodic import PeriodicCell, PeriodicOperator


def _rough(cell, seed=7, modes=24):
    """A seeded random-phase surface on the cell: a sum of its own Fourier modes (periodic), rms slope about 0.1."""
    rng = np.random.default_rng(seed)
    lx, ly = cell.size
    x, y = cell.x, cell.y
    h = np.zeros(cell.shape)
    for m in range(1, modes + 1):
        kx, ky = 2 * math.pi * rng.integers(-m, m + 1) / lx, 2 * math.pi * m / ly
        h += np.cos(kx * x + ky * y + rng.uniform(0, 2 * math.pi)) / (m * math.hypot(kx, ky))
    h *= 0.1 / math.sqrt(np.mean(np.gradient(h, cell.step, axis=1) ** 2))
    return h.max() - h


def test_nested_iteration_lets_each_coarser_level_go_before_the_finer_one(monkeypatch):
    cell = PeriodicCell(1.0 / 128, 128, 128)
    h = _rough(cell)
    made = []
    operator = PeriodicCell.operator

    def tracked(self, lattice, *args, **kw):
        op = operator(self, lattice, *args, **kw)
        made.append(weakref.ref(op))
        return op

    monkeypatch.setattr(PeriodicCell, "operator", tracked)
    alive = []

    def callback(k, p):  # called on the finest level only
        gc.collect()
        alive.append(sum(ref() is not None for ref in made))

    res = bem.solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=0.01, method="kalker", callback=callback)
    assert res.converged and len(made) == 2  # 128^2 and 64^2 (the coarsest has 4096 nodes or more)
    assert alive and max(alive) == 1  # the finest level's operator only


def test_the_periodic_operator_keeps_its_packed_symbol_only():
    cell = PeriodicCell(0.1, 64, 32)
    op = PeriodicOperator(cell, 2.0)
    held = sum(a.nbytes for a in vars(op).values() if isinstance(a, np.ndarray))
    assert held <= cell.n_nodes  # the candidate mask (a byte a node), no spectra, no kernel
    symbol = op.symbol()
    assert symbol.d.shape == (16, 1, 33) and symbol.b.shape == (16, 1, 33)  # S_00 = S_11 and S_01 (S_10 = conj S_01)
    assert symbol.d.dtype == np.float64 and symbol.b.dtype == np.complex128
    d, b = symbol.rows()
    assert d.shape == (16, 1, 33) and b.shape == (16, 2, 33) and np.array_equal(b[:, 1], np.conj(b[:, 0]))
    # the kernel it no longer stores is made on request, the same numbers as the template scaled
    w = bem.periodic.periodic_template(32, 64) * (0.1 / (math.pi * 2.0))
    assert np.array_equal(op.kernel, w)


@pytest.mark.parametrize("n_threads", [1, 3])
def test_the_block_products_equal_the_whole_array_formulas_bit_for_bit(monkeypatch, n_threads):
    rng = np.random.default_rng(3)
    monkeypatch.setattr(fft, "BLOCK", 96)  # several blocks, the last one short
    monkeypatch.setattr(fft, "_override", n_threads)
    monkeypatch.setattr(fft, "_PARTS_MIN", 1)  # three threads: the blocks in three parts (bem.fft.in_parts)
    cell = PeriodicCell(0.1, 22, 26)
    op = PeriodicOperator(cell, 1.0)
    x = op.spectrum(rng.standard_normal(cell.shape))
    symbol = op.symbol(0.3 * op.diagonal)
    d, b = symbol.rows()
    expected = d * x + b * x[:, ::-1, :]
    assert np.array_equal(op.mix(x, symbol), expected)
    y = x.copy()
    assert op.mix(y, symbol, out=y) is y and np.array_equal(y, expected)

    shape = (2, 37, 19)
    S = [[rng.standard_normal(shape[1:]) + 1j * rng.standard_normal(shape[1:]) for _ in range(2)] for _ in range(2)]
    V = rng.standard_normal(shape) + 1j * rng.standard_normal(shape)
    # the operands in the order of the whole-array formula: V_a *= S_aa, then += S_ab V_b
    want = np.stack([V[0] * S[0][0] + S[0][1] * V[1], V[1] * S[1][1] + S[1][0] * V[0]])
    assert np.array_equal(block_product(((S[0][0], S[0][1]), (S[1][0], S[1][1])), V.copy()), want)
    # a Hermitian symbol without its conjugate block: S_10 = conj(S_01)
    want = np.stack([V[0] * S[0][0] + S[0][1] * V[1], V[1] * S[1][1] + np.conj(S[0][1]) * V[0]])
    assert np.array_equal(block_product(((S[0][0], S[0][1]), (None, S[1][1])), V.copy()), want)


@pytest.mark.parametrize("block", [None, 64])  # None: one band here; 64: bands of a row or two
def test_the_preconditioner_symbol_in_place_is_the_closed_expression(monkeypatch, block):
    if block is not None:
        monkeypatch.setattr(fft, "BLOCK", block)
    lattice = bem.Lattice.from_extent(0.05, (1.0, 0.8))
    op = bem.InfluenceOperator(lattice, 1.0)
    box = op._full()
    lam, floor = 0.7 * op.diagonal, 0.5
    shape, ((s00, s01), (s10, s11)) = op._inverse_symbol(box, lam, floor)
    _, ((r00, r01), (_, r11)) = op._inverse_symbol(box, lam, floor, single=True)  # rounded as it is made
    assert r00.dtype == r11.dtype == np.float32 and r01.dtype == np.complex64
    assert np.array_equal(r00, s00.astype(np.float32)) and np.array_equal(r11, s11.astype(np.float32))
    assert np.array_equal(r01, s01.astype(np.complex64))
    _, K = op._kernel_spectra(box, box)
    size = shape[0] * shape[1]
    A, D, B = K[0, 0].real + lam / size, K[1, 1].real + lam / size, K[0, 1]
    m = (A + D) / 2
    d = np.sqrt(((A - D) / 2) ** 2 + np.abs(B) ** 2)
    low = (floor * op.diagonal + lam) / size
    inv_hi, inv_lo = 1.0 / np.maximum(m + d, low), 1.0 / np.maximum(m - d, low)
    with np.errstate(divide="ignore", invalid="ignore"):
        safe = d > 1e-14 * np.abs(m)
        half = np.where(safe, 0.5 / np.where(safe, d, 1.0), 0.0)
    diff = inv_hi - inv_lo
    scale = 1.0 / size**2
    assert s10 is None
    assert np.array_equal(s01, B * half * diff * scale)
    assert np.array_equal(s00, (inv_lo + np.where(safe, (A - m + d) * half, 0.5) * diff) * scale)
    assert np.array_equal(s11, (inv_lo + np.where(safe, (D - m + d) * half, 0.5) * diff) * scale)


def _traced_peak_per_node(solve):
    """The traced peak per node of ``solve()`` run a second time in the process: the kernels and symbols it caches
    per process are made by the first (whatever ran before it), so the peak is that of the solve itself."""
    solve()
    gc.collect()
    tracemalloc.start()
    try:
        base = tracemalloc.get_traced_memory()[0]
        res = solve()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert res.converged
    return (peak - base) / res.p.size


# traced peaks per node of these problems, each the second solve in its process (numpy 2.4): 63, 93, 86, 168, 191
# and 144 bytes, the cells with the compiled passes 54 and 78; the cell's QP holding an array of the gap u + h
# through its steps traced 70 and 110 (before the symbols below), the model QP on its own copy of Newton's pressure
# 107 (and holding its masks of the stiff and the soft nodes 105); with the compiled passes, the single-precision
# symbols of every QP kept by the operator 64 and 123, Newton's model gap as an array 84.5, its compliance D in
# double precision 80.5; the smooth cell's preconditioner corrected at the edges of the contact (bem.periodic.edge)
# 66.8 and 54.4 (63 and 54 without; its correction held as a float32 array of the cell, 69.6 and 57.7); the root
# layer's model QP holding its preconditioned gap, its direction, its gap and D p beside the product of a changed
# step, the Jacobi estimate at its contact and M 1 beside it, and M 1 of its start in single precision, 93.1 and 76.5
# (86.0 and 71.2 without; with M 1 of its start in single precision alone, 87.1 and 73.2); Newton's C p handed to
# the model QPs 78.0 and 63.2, their product in single precision in an array of its own beside it 81.2 and 65.6; the
# model QPs' preconditioner corrected at the edges (bem.periodic.edge) made in the QP's work array: the root layer
# 82.3, 66.2, 74.3 and 60.3 against 82.3, 65.3, 74.3 and 60.4 (made in new arrays 90.6, 70.6, 82.6 and 62.6). Measured
# before the warm-up solve (after the other problems in the process): a solve that holds its coarser levels, the
# spectra its symbols are made of and its copies of the iterates traced 176, 275, 180 and 343; Newton holding its
# step and the model's gap through the line search, and its iterate beside its start, 132 with the root layer; a
# product over the whole region with four complex blocks of spectra, and transforms that hold the whole unpadded
# spectrum beside the padded one, 269 on the whole-region sphere; the half-space QP holding its gap through its step
# 177, 200 and 153, its search direction beside the direction's product 151 by bands (the whole array's peak falls
# elsewhere), with the preconditioner's output beside its input as well 189 and 210; the wide sphere by bands with the
# coefficient table made anew traced 136, holding its table 144
@pytest.mark.parametrize("problem, bound", [("periodic", 70), ("periodic root layer", 89), ("sphere", 100),
                                            ("wide sphere", 175), ("whole-region sphere", 196),
                                            ("wide sphere by bands", 148),
                                            ("wide sphere, table made anew, by bands", 140),
                                            ("periodic compiled", 57), ("periodic root layer compiled", 72.5),
                                            ("periodic root layer, C p handed", 79.5),
                                            ("periodic root layer compiled, C p handed", 64.5)])
def test_the_traced_peak_of_a_solve_per_node_stays_below_its_bound(problem, bound, monkeypatch):
    if problem.endswith("by bands"):  # the products by bands of columns of the larger regions
        monkeypatch.setattr("bem.operator.BANDS_ABOVE", 0)
    if "table made anew" in problem:  # the operators of the larger regions: no coefficient table held
        monkeypatch.setattr("bem.operator.TABLE_HELD_UP_TO", 0)
    if problem.endswith("handed"):  # Newton's C p held by its model QPs, as on a cell of 16.8M nodes or more
        monkeypatch.setattr("bem.heap.RELEASE_ABOVE", 0)
    if "compiled" in problem:  # the passes of a large cell (the NumPy forms make the symbol's blocks)
        if not bem.periodic.passes.load():
            pytest.skip("numba is not installed")
        monkeypatch.setattr("bem.periodic.passes.MIN_NODES", 0)
    if problem.startswith("periodic"):
        cell = PeriodicCell(1.0 / 256, 256, 256)
        h = _rough(cell)
        layer = bem.layers.Root(bem.diagonal_coefficient(cell.step, 1.0) * math.sqrt(0.05)) if "root" in problem else None
        peak = _traced_peak_per_node(lambda: bem.solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=0.01,
                                                                layer=layer))
    else:
        shape = problem.split(" by bands")[0].split(",")[0]
        radius = {"sphere": 0.1, "wide sphere": 0.3, "whole-region sphere": 0.42}[shape]
        step = math.sqrt(2 / math.sqrt(3)) / 256
        peak = _traced_peak_per_node(lambda: bem.solve(bem.gaps.Paraboloid(1.0), E_star=1.0, force=4 * radius**3 / 3,
                                                       step=step, extent=0.5))
    assert peak < bound
