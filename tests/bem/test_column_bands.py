"""The block convolution by bands of spectrum columns against the whole-array path and the dense matrix."""

import numpy as np
import pytest

import bem.column_bands as column_bands
from bem import pruned_fft
from bem.block_symbol import block_product
from bem.lattice import Lattice
from bem.operator import InfluenceOperator


def _whole(op, spectra, shape, v, in_box, out_box, dtype):
    """The whole-array path written out: every row of the padded pair transformed, multiplied, inverted."""
    out = np.zeros(op.lattice.shape)
    V = block_product(spectra, pruned_fft.forward_parts(op._parts(v, in_box), shape, dtype))
    o_rows, (oq, nq) = out_box
    for a, s in enumerate(op._start):
        k0, na = o_rows[a]
        pruned_fft.inverse_into(V[a], shape, out[s + 2 * k0 : s + 2 * (k0 + na) : 2, oq : oq + nq])
    return out


def _by_bands(op, spectra, shape, v, in_box, out_box, dtype):
    out = np.zeros(op.lattice.shape)
    o_rows, (oq, nq) = out_box
    dests = [out[s + 2 * k0 : s + 2 * (k0 + na) : 2, oq : oq + nq] for s, (k0, na) in zip(op._start, o_rows)]
    column_bands.convolve_by_bands(spectra, shape, op._parts(v, in_box), dests, dtype)
    return out


def _support(lat, seed, rows, cols):
    rng = np.random.default_rng(seed)
    v = np.zeros(lat.shape)
    v[rows, cols] = rng.standard_normal(v[rows, cols].shape)
    return v * lat.mask


@pytest.mark.parametrize("window", [False, True])
@pytest.mark.parametrize("single", [False, True])
def test_bands_give_the_numbers_of_the_whole_array(window, single, monkeypatch):
    """A window's four complex blocks and a box's Hermitian symbol, in double and single precision, with bands of
    4 columns (several bands, a last one narrower): the same products, to the last bits."""
    monkeypatch.setattr(column_bands, "_BAND_BYTES", 1)  # bands of the minimum width
    lat = Lattice.from_extent(0.04, (1.0, 0.8))
    op = InfluenceOperator(lat, 1.3)
    v = _support(lat, 3, slice(9, 31), slice(6, 19))
    box = op._box(v)
    if window:
        shape, spectra = op._kernel_spectra(op._full(), box)
        out_box = op._full()
        assert spectra.shape[:2] == (2, 2)
    else:
        shape, spectra = op._kernel_spectra(box, box, hermitian=True)
        out_box = box
        assert spectra[1][0] is None
    if single:
        spectra = spectra.astype(np.complex64) if window else (
            (spectra[0][0].astype(np.float32), spectra[0][1].astype(np.complex64)),
            (None, spectra[1][1].astype(np.float32)))
    dtype = np.float32 if single else np.float64
    assert (shape[1] // 2 + 1) % 4 and shape[1] // 2 + 1 > 8
    keep = v.copy()
    whole = _whole(op, spectra, shape, v, box, out_box, dtype)
    bands = _by_bands(op, spectra, shape, v, box, out_box, dtype)
    np.testing.assert_array_equal(v, keep)  # the input is not modified
    scale = np.abs(whole).max()
    assert scale > 0
    assert np.abs(bands - whole).max() <= (1e-6 if single else 1e-14) * scale


def test_the_operator_by_bands_is_the_dense_product(monkeypatch):
    """Above the size where bands are taken (lowered here to every product) ``C p`` of a window and of the whole
    region is the dense matrix's, and the preconditioner is the one of the whole-array path."""
    lat = Lattice.from_extent(0.05, (1.0, 0.7))
    p_window = _support(lat, 4, slice(5, 14), slice(3, 11))
    p_full = np.random.default_rng(5).random(lat.shape) * lat.mask
    whole_op = InfluenceOperator(lat, 2.0)
    reference = [whole_op.preconditioner(lam=0.2, single=single)(p_window) for single in (False, True)]
    calls = []
    original = column_bands.convolve_by_bands
    monkeypatch.setattr("bem.operator.BANDS_ABOVE", 0)
    monkeypatch.setattr("bem.operator.convolve_by_bands", lambda *a: calls.append(1) or original(*a))
    op = InfluenceOperator(lat, 2.0)
    dense = op.dense()
    for p in (p_window, p_full):
        ref = dense @ p[lat.mask]
        assert np.abs(op.matvec(p)[lat.mask] - ref).max() <= 1e-13 * np.abs(ref).max()
    for single, ref in zip((False, True), reference):
        got = op.preconditioner(lam=0.2, single=single)(p_window)
        assert np.abs(got - ref).max() <= (1e-6 if single else 1e-13) * np.abs(ref).max()
    assert len(calls) == 4


def test_band_width_follows_the_rows():
    assert column_bands.band_columns(1024, 16) == (1 << 20) // (2 * 1024 * 16)
    assert column_bands.band_columns(1 << 20, 16) == 4


@pytest.mark.parametrize("extent, rows, cols", [
    ((1.0, 0.7), slice(5, 14), slice(8, 16)),  # first row even (start (0, 1)), off the centre
    ((0.85, 0.9), slice(0, 6), slice(0, 5)),  # a corner
    ((0.9, 0.75), slice(9, 30), slice(12, 26)),  # first row odd (start (1, 0)), to the last rows and columns
    ((0.9, 0.75), slice(3, 8), slice(2, 9)),  # first row odd, off the centre
])
def test_the_paired_window_is_the_dense_product(extent, rows, cols, monkeypatch):
    """Input on a window whose parities hold the same rows, output everywhere, by two blocks and the phase of the
    shift between the parities (taken here for every window): the dense matrix's product, and the four blocks'."""
    monkeypatch.setattr("bem.operator.BANDS_ABOVE", 0)
    lat = Lattice.from_extent(0.05, extent)
    op = InfluenceOperator(lat, 1.7)
    dense = op.dense()
    for seed in range(3):
        p = _support(lat, seed, rows, cols)
        box = op._window(op._box(p))[0]  # widened to the same rows of both parities
        assert box != op._full() and box[0][0] == box[0][1]
        ref = dense @ p[lat.mask]
        got = op.matvec(p)
        assert np.all(got[~lat.mask] == 0)
        assert np.abs(got[lat.mask] - ref).max() <= 1e-13 * np.abs(ref).max()
        shape, spectra = op._kernel_spectra(op._full(), box)
        four = _by_bands(op, spectra, shape, p, box, op._full(), np.float64)
        assert np.abs(got - four)[lat.mask].max() <= 1e-14 * np.abs(four).max()
    assert [key[0] for key in op._spectra] == ["P"]
    assert isinstance(op._spectra[("P", box)][1], column_bands.PairedSymbol)


def test_a_window_on_the_last_row_of_one_parity_keeps_four_blocks(monkeypatch):
    """A box that reaches the last row of the parity with more rows cannot be widened to the same rows of both."""
    monkeypatch.setattr("bem.operator.BANDS_ABOVE", 0)
    lat = Lattice.from_extent(0.05, (1.0, 0.7))
    op = InfluenceOperator(lat, 1.7)
    assert op._n == (17, 16) and op._start == (0, 1)
    p = np.zeros(lat.shape)
    p[30:33, 10:14] = 1.0  # brick rows 30-32: even-parity rows 15-16, odd row 15
    p *= lat.mask
    ref = op.dense() @ p[lat.mask]
    got = op.matvec(p)
    assert np.abs(got[lat.mask] - ref).max() <= 1e-13 * np.abs(ref).max()
    assert [key[0] for key in op._spectra] == ["C"]


@pytest.mark.parametrize("extent", [(1.0, 0.7), (0.9, 0.75), (0.95, 0.9)])
@pytest.mark.parametrize("rows, cols", [((0, 5), (0, 7)), ((3, 9), (5, 11)), ((6, 10), (9, 23))])
def test_paired_spectra_reach_every_offset_of_the_four_blocks(extent, rows, cols):
    """Boxes not snapped, filled to their edges (every offset from the box to the region is met), both parity orders
    (``sigma`` = +1 and -1) and equal or unequal rows of the parities: the four blocks' products."""
    lat = Lattice.from_extent(0.05, extent)
    op = InfluenceOperator(lat, 1.1)
    box = ((rows, rows), cols)
    full = op._full()
    v = np.random.default_rng(sum(rows) + sum(cols)).standard_normal(lat.shape)
    shape, four = op._kernel_spectra(full, box)
    pair_shape, paired = column_bands.paired_spectra(op._table, op._start, op._n, lat.shape[1], box)
    ref = _by_bands(op, four, shape, v, box, full, np.float64)
    got = _by_bands(op, paired, pair_shape, v, box, full, np.float64)
    assert np.abs(got - ref).max() <= 1e-14 * np.abs(ref).max()


def test_a_coated_window_is_paired_too(monkeypatch):
    """The coated half-space's coefficient table has the same offsets: its paired window is its dense product."""
    import bem

    monkeypatch.setattr("bem.operator.BANDS_ABOVE", 0)
    bodies = bem.Bodies(210e9, 0.3, 210e9, 0.3, coating1=bem.Coating(0.05, 3.0, 0.3))
    lat = Lattice.from_extent(0.05, (0.9, 0.75))
    op = InfluenceOperator(lat, bodies.E_star, bodies=bodies)
    p = _support(lat, 9, slice(6, 20), slice(5, 19))
    ref = op.dense() @ p[lat.mask]
    got = op.matvec(p)
    assert np.abs(got[lat.mask] - ref).max() <= 1e-13 * np.abs(ref).max()
    assert [key[0] for key in op._spectra] == ["P"]


def test_windows_are_taken_up_to_their_own_bounds(monkeypatch):
    """On NumPy a window is kept up to ``_NUMPY_FULL_ABOVE`` of the whole region's padded points, four blocks below
    ``BANDS_ABOVE`` and paired above (on a device up to ``_FULL_ABOVE``), and a cached paired window is reused for a
    smaller support up to ``_PAIRED_REUSE_UP_TO`` times its points; every product is the dense matrix's."""
    import bem.operator as operator

    lat = Lattice.from_extent(0.05, (1.0, 0.8))
    op = InfluenceOperator(lat, 1.0)
    dense = op.dense()
    full = op._full()

    def size(b):
        return (max(op._n) + max(r[1] for r in b[0])) * (lat.shape[1] + b[1][1])

    wide = _support(lat, 1, slice(2, 20), slice(2, 37))  # a box of 0.7-0.85 of the whole padding
    ratio = size(op._box(wide)) / size(full)
    assert operator._FULL_ABOVE < ratio <= operator._NUMPY_FULL_ABOVE
    box = op._window(op._box(wide))[0]  # four blocks, a window
    assert box != full and [key[0] for key in op._spectra] == ["C"]
    ref = dense @ wide[lat.mask]
    assert np.abs(op.matvec(wide)[lat.mask] - ref).max() <= 1e-13 * np.abs(ref).max()
    with monkeypatch.context() as m:
        m.setattr(op.backend, "is_numpy", False)  # the rule of a device (the window's choice only)
        assert op._window(op._box(wide))[0] == full
    monkeypatch.setattr("bem.operator.BANDS_ABOVE", 0)
    op = InfluenceOperator(lat, 1.0)
    boxes = []
    for rows, cols in ((slice(2, 20), slice(2, 37)), (slice(4, 19), slice(4, 36)), (slice(8, 14), slice(10, 20))):
        p = _support(lat, 2, rows, cols)
        box = op._window(op._box(p))[0]
        boxes.append((box, size(box) / size(op._box(p))))
        ref = dense @ p[lat.mask]
        assert np.abs(op.matvec(p)[lat.mask] - ref).max() <= 1e-13 * np.abs(ref).max()
    assert boxes[0][0] != full and boxes[1][0] == boxes[0][0] and boxes[1][1] <= operator._PAIRED_REUSE_UP_TO
    assert boxes[2][0] != boxes[0][0]  # a support far smaller: its own window
    assert sorted(key[0] for key in op._spectra) == ["P", "P"]


def test_paired_spectra_need_the_same_rows_of_both_parities():
    lat = Lattice.from_extent(0.05, (1.0, 0.7))
    op = InfluenceOperator(lat, 1.0)
    with pytest.raises(ValueError, match="same rows"):
        column_bands.paired_spectra(op._table, op._start, op._n, lat.shape[1], (((2, 6), (1, 6)), (6, 12)))
