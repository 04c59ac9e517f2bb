"""The FFT influence operator against the dense matrix of eq. 6."""

import math

import numpy as np
import pytest

import bem
from bem.block_symbol import table_extent
from bem.lattice import Lattice
from bem.operator import InfluenceOperator
from bem.template import template


@pytest.mark.parametrize("extent", [1.0, (1.0, 0.45), (0.55, 1.0), (0.73, 0.81)])
def test_fft_product_equals_dense_product(extent):
    lat = Lattice.from_extent(0.1, extent)
    op = InfluenceOperator(lat, 2.5)
    dense = op.dense()
    rng = np.random.default_rng(7)
    for _ in range(3):
        p = rng.random(lat.shape) * lat.mask
        ref = dense @ p[lat.mask]
        got = op.matvec(p)[lat.mask]
        assert np.abs(got - ref).max() <= 1e-13 * np.abs(ref).max()


def test_dense_matrix_is_eq6_and_symmetric_positive_definite():
    lat = Lattice.from_extent(0.2, 1.0)
    op = InfluenceOperator(lat, 3.0)
    C = op.dense()
    x, y = lat.x[lat.mask], lat.y[lat.mask]
    n, m = 5, 17
    expected = 0.2 / (math.pi * 3.0) * template((x[n] - x[m]) / 0.2, (y[n] - y[m]) / 0.2)
    assert C[n, m] == pytest.approx(float(expected), rel=1e-14)
    expected_diagonal = 0.2 / (math.pi * 3.0) * 1.5 * math.sqrt(3) * math.log(3)
    assert op.diagonal == pytest.approx(expected_diagonal, rel=1e-14)
    assert C[0, 0] == pytest.approx(expected_diagonal, rel=1e-14)
    assert bem.diagonal_coefficient(0.2, 3.0) == pytest.approx(expected_diagonal, rel=1e-14)
    np.testing.assert_allclose(C, C.T, rtol=1e-12)  # template round-off, mirrored points
    assert np.linalg.eigvalsh(C).min() > 0


def test_linear_operator_wraps_the_same_product():
    lat = Lattice.from_extent(0.25, 1.0)
    op = InfluenceOperator(lat, 1.0)
    v = np.random.default_rng(1).random(lat.n_nodes)
    np.testing.assert_allclose(op.as_linear_operator() @ v, op.dense() @ v, rtol=1e-12)


def _columns(M, lat, vectors):
    return np.array([M(v)[lat.mask] for v in vectors]).T


def test_preconditioner_is_symmetric_positive_definite():
    lat = Lattice.from_extent(0.2, 1.0)
    op = InfluenceOperator(lat, 1.0)
    M = op.preconditioner(lam=0.1, box="full")
    units = []
    for k in range(lat.n_nodes):
        grid = np.zeros(lat.n_nodes)
        grid[k] = 1.0
        units.append(np.zeros(lat.shape))
        units[-1][lat.mask] = grid
    Mm = _columns(M, lat, units)
    np.testing.assert_allclose(Mm, Mm.T, atol=1e-12 * np.abs(Mm).max())
    assert np.linalg.eigvalsh((Mm + Mm.T) / 2).min() > 0


def test_support_preconditioner_is_one_spd_operator_per_box():
    """Vectors whose supports share a bounding box see one SPD operator."""
    lat = Lattice.from_extent(0.05, 1.0)
    op = InfluenceOperator(lat, 1.0)
    M = op.preconditioner(lam=0.1)
    inside = np.zeros(lat.shape, dtype=bool)
    inside[10:17, 12:19] = True
    inside &= lat.mask
    corners = np.zeros(lat.shape)
    corners[10, 12] = corners[16, 18] = 1.0  # pins the bounding box of every vector below
    base = M(corners)
    cols = []
    for r, q in zip(*np.nonzero(inside)):
        v = corners.copy()
        v[r, q] += 1.0
        cols.append((M(v) - base)[inside])
    Mb = np.array(cols).T
    np.testing.assert_allclose(Mb, Mb.T, atol=1e-12 * np.abs(Mb).max())
    assert np.linalg.eigvalsh((Mb + Mb.T) / 2).min() > 0
    full = op.preconditioner(lam=0.1, box="full")(corners)
    assert np.abs(base - full)[inside].max() < 0.5 * np.abs(full[inside]).max()  # same operator, smaller embedding
    assert np.all(M(np.zeros(lat.shape)) == 0)


def test_matvec_does_not_modify_input():
    lat = Lattice.from_extent(0.2, 1.0)
    op = InfluenceOperator(lat, 1.0)
    p = np.random.default_rng(2).random(lat.shape) * lat.mask
    keep = p.copy()
    op.matvec(p)
    np.testing.assert_array_equal(p, keep)


@pytest.mark.parametrize("box", ["support", "full"])
def test_single_precision_preconditioner_is_the_double_one_rounded(box):
    """``single=True``: the same operator to single precision, double-precision output, input untouched."""
    lat = Lattice.from_extent(0.05, 1.0)
    op = InfluenceOperator(lat, 1.0)
    rng = np.random.default_rng(5)
    r = np.where(rng.random(lat.shape) < 0.3, rng.standard_normal(lat.shape), 0.0) * lat.mask
    keep = r.copy()
    exact = op.preconditioner(lam=0.1, box=box)(r)
    single = op.preconditioner(lam=0.1, box=box, single=True)(r)
    np.testing.assert_array_equal(r, keep)
    assert single.dtype == np.float64 and np.all(single[~lat.mask] == 0)
    err = np.abs(single - exact).max() / np.abs(exact).max()
    assert 1e-9 < err < 1e-5  # rounded (not the double product), to single precision


def test_periodic_single_precision_preconditioner_is_the_double_one_rounded():
    from bem.periodic import PeriodicCell, PeriodicOperator

    cell = PeriodicCell(0.1, 32, 24)
    op = PeriodicOperator(cell, 1.0)
    r = np.random.default_rng(6).standard_normal(cell.shape)
    exact, single = op.preconditioner(0.05)(r), op.preconditioner(0.05, single=True)(r)
    assert single.dtype == np.float64
    assert 1e-9 < np.abs(single - exact).max() / np.abs(exact).max() < 1e-5


def _boxes(op, rng):
    """The whole region and three random support boxes of ``op``'s lattice."""
    yield op._full()
    for _ in range(3):
        v = np.zeros(op.lattice.shape)
        r0, c0 = rng.integers(0, op.lattice.shape[0] // 2), rng.integers(0, op.lattice.shape[1] // 2)
        v[r0 : r0 + rng.integers(1, op.lattice.shape[0] // 2), c0 : c0 + rng.integers(1, op.lattice.shape[1] // 2)] = 1
        yield op._box(v)


@pytest.mark.parametrize("extent, coated", [((1.0, 0.8), False), ((0.55, 1.0), False), ((0.73, 0.81), False),
                                            ((0.6, 0.5), True)])
def test_the_symbol_of_a_box_onto_itself_is_hermitian_with_real_diagonal_blocks(extent, coated):
    """The compact spectra (``hermitian=True``) drop only round-off: the four complex blocks have diagonal blocks
    with imaginary parts, and ``S_10 - conj(S_01)``, below 1e-15 of the largest entry; the stored blocks are the
    four-block spectra's own numbers."""
    bodies = bem.Bodies(210e9, 0.3, 210e9, 0.3, coating1=bem.Coating(0.05, 3.0, 0.3)) if coated else None
    op = InfluenceOperator(Lattice.from_extent(0.05, extent), 1.0 if bodies is None else bodies.E_star, bodies=bodies)
    rng = np.random.default_rng(3)
    for box in _boxes(op, rng):
        shape, K = op._kernel_spectra(box, box)
        shape_h, ((s00, s01), (s10, s11)) = op._kernel_spectra(box, box, hermitian=True)
        scale = np.abs(K).max()
        assert shape_h == shape and s10 is None and s00.dtype == s11.dtype == np.float64
        assert np.abs(K[0, 0].imag).max() < 1e-15 * scale and np.abs(K[1, 1].imag).max() < 1e-15 * scale
        assert np.abs(K[1, 0] - K[0, 1].conj()).max() < 1e-15 * scale
        assert np.array_equal(s00, K[0, 0].real) and np.array_equal(s11, K[1, 1].real)
        assert np.array_equal(s01, K[0, 1])


def test_hermitian_spectra_need_a_box_onto_itself():
    op = InfluenceOperator(Lattice.from_extent(0.1, 1.0), 1.0)
    v = np.zeros(op.lattice.shape)
    v[2:5, 3:6] = 1.0
    with pytest.raises(ValueError, match="hermitian = True needs out_box == in_box"):
        op._kernel_spectra(op._full(), op._box(v), hermitian=True)


def test_the_product_over_the_whole_region_keeps_the_compact_spectra():
    """A product whose support spans the region uses the compact spectra of the whole box (half the memory of
    four complex blocks), and gives the product of a window's four-block spectra to round-off."""
    lat = Lattice.from_extent(0.05, (1.0, 0.8))
    op = InfluenceOperator(lat, 1.0)
    p = np.random.default_rng(4).random(lat.shape) * lat.mask
    u = op.matvec(p)
    (key, value), = op._spectra.items()
    assert key == ("C", op._full()) and value[1][1][0] is None and value[1][0][0].dtype == np.float64
    box = op._full()
    out = np.zeros(lat.shape)
    shape, K = op._kernel_spectra(box, box)  # the four blocks, through the same convolution
    op._convolve(K, shape, p, box, box, out)
    assert np.abs(u - out).max() <= 1e-15 * np.abs(u).max()


@pytest.mark.parametrize("bands", [False, True])
def test_an_operator_that_makes_its_table_anew_gives_the_products_of_one_that_holds_it(monkeypatch, bands):
    # above bem.operator.TABLE_HELD_UP_TO nodes the coefficient table is made where a symbol is built, not held:
    # the same products bit for bit (matvec windows, the preconditioner's box, the quadratic form), and no table kept
    if bands:  # the paired symbols of the larger regions
        monkeypatch.setattr("bem.operator.BANDS_ABOVE", 0)
    lat = Lattice.from_extent(0.02, 1.0)
    rng = np.random.default_rng(3)
    p = np.where(lat.mask & (rng.random(lat.shape) < 0.3), rng.random(lat.shape), 0.0)
    p[: lat.shape[0] // 3] = 0.0  # a support smaller than the region: a window of its own

    def products(op):
        return op.matvec(p), op.matvec(np.where(lat.mask, 1.0, 0.0)), op.preconditioner(single=True)(p), op.quadratic(p)

    held = InfluenceOperator(lat, 2.0)
    expected = products(held)
    monkeypatch.setattr("bem.operator.TABLE_HELD_UP_TO", 0)
    anew = InfluenceOperator(lat, 2.0)
    for a, b in zip(expected, products(anew)):
        assert np.array_equal(a, b)
    assert held._held is not None and anew._held is None
    box = anew._box(p)  # the box's symbol met the offsets of its box only: a table smaller than the lattice's
    assert all(e < n for e, n in zip(table_extent(anew._start, box, box), lat.shape))
