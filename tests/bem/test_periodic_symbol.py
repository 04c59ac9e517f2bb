"""The 2 x 2 block symbol of the periodic cell (:mod:`bem.periodic.symbol`): the packed Hermitian symbol against the
spectra of the kernel's blocks, the inverse against a 2 x 2 inversion per frequency, the single precision as a
rounding, blocks of rows as the whole, and no array of a symbol beyond the operator's packed one."""

import numpy as np
import pytest

from bem.periodic import PeriodicCell, PeriodicOperator
from bem.periodic.symbol import Symbol

CELL = PeriodicCell(0.3, 10, 12)  # an even number of columns: a Nyquist column in the half spectrum


def _matrices(d, b):
    """The 2 x 2 matrices ``[[S_00, S_01], [S_10, S_11]]`` per frequency, shape ``(rows, cols, 2, 2)``."""
    m = np.empty(d.shape[:1] + d.shape[2:] + (2, 2), dtype=complex)
    m[..., 0, 0] = m[..., 1, 1] = d[:, 0]
    m[..., 0, 1], m[..., 1, 0] = b[:, 0], b[:, 1]
    return m


@pytest.mark.parametrize("cell", [CELL, PeriodicCell(0.3, 11, 8)])
def test_the_packed_symbol_is_the_spectra_of_the_kernels_blocks(cell):
    """``S_00`` and ``S_01`` are the FFTs of the kernel between the even rows and between an odd row and its even
    neighbours (taken here from the kernel by offsets); ``S_10``, made as ``conj(S_01)``, is the FFT of the other
    off-diagonal block to the round-off of the kernel's sums."""
    op = PeriodicOperator(cell, 2.0)
    w = op.kernel
    even, odd = w[0::2], w[1::2]
    s00 = np.fft.rfft2(even)
    s01, s10 = np.fft.rfft2(np.roll(odd, (1, 1), axis=(0, 1))), np.fft.rfft2(odd)
    symbol = op.symbol()
    scale = np.abs(s00).max()
    assert np.abs(symbol.d[:, 0] - s00.real).max() <= 1e-14 * scale and np.abs(s00.imag).max() <= 1e-14 * scale
    assert np.abs(symbol.b[:, 0] - s01).max() <= 1e-14 * scale
    d, b = symbol.rows()
    assert np.array_equal(b[:, 1], np.conj(b[:, 0])) and np.abs(b[:, 1] - s10).max() <= 1e-13 * scale


@pytest.mark.parametrize("lam", [0.0, 0.4])
def test_the_inverse_symbol_inverts_each_block_and_gives_the_constant_mode_its_eigenvalue(lam):
    op = PeriodicOperator(CELL, 2.0)
    S = _matrices(*op.symbol(lam).rows())
    inv = _matrices(*op.symbol(lam, inverse=True).rows())
    eye = np.broadcast_to(np.eye(2), S.shape)
    zero = np.zeros(S.shape[:2], dtype=bool)
    zero[0, 0] = True
    shifted = S.copy()
    shifted[0, 0] += 0.5 * op.diagonal  # the constant mode (1, 1) / sqrt 2: eigenvalue C_nn + lam
    assert np.abs(S[0, 0] @ [1, 1] - lam).max() <= 1e-14 * np.abs(S).max()  # C vanishes on it
    np.testing.assert_allclose(inv @ shifted, eye, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.inv(shifted), inv, rtol=1e-12, atol=1e-12 * np.abs(inv).max())
    eigenvalues = np.linalg.eigvalsh(shifted[0, 0])
    assert min(abs(eigenvalues - (op.diagonal + lam))) <= 1e-12 * op.diagonal


@pytest.mark.parametrize("inverse", [False, True])
def test_single_precision_is_the_double_symbol_rounded_and_rows_are_the_whole(inverse):
    op = PeriodicOperator(CELL, 2.0)
    d, b = op.symbol(0.3, inverse=inverse).rows()
    d32, b32 = op.symbol(0.3, inverse=inverse, single=True).rows()
    assert d32.dtype == np.float32 and b32.dtype == np.complex64
    assert np.array_equal(d32, d.astype(np.float32)) and np.array_equal(b32, b.astype(np.complex64))
    symbol = op.symbol(0.3, inverse=inverse)
    parts = [symbol.rows(lo, lo + 2) for lo in range(0, d.shape[0], 2)]  # the first block holds frequency 0
    assert np.array_equal(np.concatenate([p[0] for p in parts]), d)
    assert np.array_equal(np.concatenate([p[1] for p in parts]), b)


def test_a_symbol_holds_no_array_of_its_own_and_leaves_the_packed_one_as_it_was():
    op = PeriodicOperator(CELL, 2.0)
    base = op.symbol()
    keep = base.d.copy(), base.b.copy()
    for kw in ({"lam": 0.3}, {"inverse": True}, {"lam": 0.3, "inverse": True, "single": True}):
        symbol = op.symbol(**kw)
        assert isinstance(symbol, Symbol) and symbol.d is base.d and symbol.b is base.b
        symbol.rows()
        x = op.spectrum(np.random.default_rng(0).standard_normal(CELL.shape))
        op.mix(x, symbol, out=x)
    assert np.array_equal(base.d, keep[0]) and np.array_equal(base.b, keep[1])
    assert not base.d.flags.writeable and not base.b.flags.writeable  # shared by the operators of a cell


@pytest.mark.parametrize("cell", [CELL, PeriodicCell(0.3, 11, 8), PeriodicCell(0.2, 7, 6)])
@pytest.mark.parametrize("lam", [0.0, 0.4])
@pytest.mark.parametrize("inverse", [False, True])
def test_the_diagonal_is_the_product_of_a_unit_pressure_at_every_node(cell, lam, inverse):
    """:meth:`Symbol.diagonal` (in blocks of 2 rows, even and odd numbers of columns) is the product of the symbol
    with a unit pressure at a node, read there, at nodes of both row parities (made by the operator's transforms);
    :func:`mirrored_sum` of the blocks of the symbol's rows, its form for a device's ``(D, B)``, the same."""
    from bem.periodic.symbol import mirrored_sum

    op = PeriodicOperator(cell, 2.0)
    symbol = op.symbol(lam, inverse=inverse)
    apply = op.preconditioner(lam) if inverse else (lambda v: op.matvec(v) + lam * v)
    got = symbol.diagonal(cell.n_cols, rows=2)
    for node in [(0, 0), (1, 3), (cell.n_rows - 1, cell.n_cols - 1)]:
        unit = np.zeros(cell.shape)
        unit[node] = 1.0
        assert got == pytest.approx(apply(unit)[node], rel=1e-13)
    d, _ = symbol.rows()
    assert mirrored_sum(np, d, cell.n_cols) / (d.shape[0] * cell.n_cols) == pytest.approx(got, rel=1e-14)
