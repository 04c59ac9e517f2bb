"""The pruned padded transforms of the half-space's convolutions (bem.pruned_fft)."""

import numpy as np
import pytest

from bem import fft, pruned_fft

from .fft_cases import use_library


def test_forward_inverse_is_a_zero_padded_circular_pair():
    rng = np.random.default_rng(0)
    x = rng.random((2, 5, 7))
    shape = (fft.fast_length(11, real=False), fft.fast_length(15, real=True))
    back = pruned_fft.inverse(pruned_fft.forward(x, shape), shape, (5, 7)) / (shape[0] * shape[1])
    np.testing.assert_allclose(back, x, rtol=0, atol=1e-14)


def _gathered_forward(parts, shape, dtype):
    """The batch gathered into one zero-filled array, then the plain padded transform pair of SciPy."""
    import scipy.fft as sfft

    data = np.zeros((len(parts), max(p.shape[0] for p in parts), max(p.shape[1] for p in parts)), dtype=dtype)
    for b, p in enumerate(parts):
        data[b, : p.shape[0], : p.shape[1]] = p.astype(dtype)
    rows = sfft.rfft(data, n=shape[1], axis=-1)
    return sfft.fft(rows, n=shape[0], axis=-2)


@pytest.mark.parametrize("band", [None, 3])  # None: the default bands (one here); 3: bands of a few rows
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_forward_parts_of_strided_rows_is_the_gathered_transform_bit_for_bit(monkeypatch, band, dtype):
    use_library(monkeypatch, "pocketfft")  # the gathered transform is SciPy's
    if band is not None:
        monkeypatch.setattr(pruned_fft, "_BAND", band)
        monkeypatch.setattr(pruned_fft, "LINES", 1)  # bands of a few rows
    v = np.random.default_rng(1).standard_normal((23, 17))
    parts = [v[0::2, 2:13], v[1::2, 2:13]]  # 12 and 11 rows, views with a row stride
    keep = v.copy()
    shape = (fft.fast_length(24, real=False), fft.fast_length(21, real=True))
    got = pruned_fft.forward_parts(parts, shape, dtype)
    want = _gathered_forward(parts, shape, dtype)
    np.testing.assert_array_equal(v, keep)
    assert got.dtype == want.dtype and np.array_equal(got, want)


def test_forward_parts_into_a_given_array_writes_the_same_spectra_there():
    v = np.random.default_rng(4).standard_normal((2, 9, 7))
    shape = (fft.fast_length(17, real=False), fft.fast_length(13, real=True))
    want = pruned_fft.forward_parts(list(v), shape)
    held = np.full((3, 2) + want.shape[1:], np.nan + 0j)  # a view of it as out: the block [1] of a larger array
    got = pruned_fft.forward_parts(list(v), shape, out=held[1])
    assert np.shares_memory(got, held[1])
    assert np.array_equal(held[1], want) and np.isnan(held[0]).all() and np.isnan(held[2]).all()
    for bad in (np.empty(want.shape, dtype=np.complex64), np.empty(want.shape[::-1], dtype=complex),
                np.empty((2, want.shape[1], 2 * want.shape[2]), dtype=complex)[..., ::2]):
        with pytest.raises(ValueError, match="out = .* is not allowed"):
            pruned_fft.forward_parts(list(v), shape, out=bad)


@pytest.mark.parametrize("band", [None, 3])
def test_banded_forward_and_inverse_are_the_plain_pair_bit_for_bit(monkeypatch, band):
    import scipy.fft as sfft

    use_library(monkeypatch, "pocketfft")  # the plain pair is SciPy's
    if band is not None:
        monkeypatch.setattr(pruned_fft, "_BAND", band)
        monkeypatch.setattr(pruned_fft, "LINES", 1)  # bands of a few rows
    x = np.random.default_rng(2).random((2, 9, 7))
    shape = (fft.fast_length(17, real=False), fft.fast_length(13, real=True))
    spectrum = pruned_fft.forward(x, shape)
    assert np.array_equal(spectrum, _gathered_forward(list(x), shape, np.float64))
    plain = sfft.irfft(sfft.ifft(spectrum, axis=-2, norm="forward")[..., :9, :], n=shape[1], axis=-1,
                       norm="forward")[..., :7]
    back = pruned_fft.inverse(spectrum.copy(), shape, (9, 7))
    assert back.shape == (2, 9, 7) and np.array_equal(back, plain)
    out = np.full((18, 11), -1.0)
    pruned_fft.inverse_into(spectrum[1].copy(), shape, out[1::2, 3:10])  # a strided destination, the rest untouched
    assert np.array_equal(out[1::2, 3:10], plain[1])
    assert np.all(out[0::2] == -1.0) and np.all(out[:, :3] == -1.0) and np.all(out[:, 10:] == -1.0)


@pytest.mark.parametrize("library", ["pocketfft", "ducc0"])
def test_padded_transforms_on_threads_equal_one_thread(monkeypatch, library):
    """forward_parts and inverse_into (the half-space's pruned pair) in parts on two threads give the numbers of
    one thread, bit for bit, banded or not, through either library, and the data back."""
    use_library(monkeypatch, library)
    x = np.random.default_rng(4).standard_normal((2, 300, 500))
    shape = (fft.fast_length(599, real=False), fft.fast_length(999, real=True))
    results = []
    for n_threads, band in ((1, 1 << 19), (2, 1 << 19), (2, 1 << 16)):
        monkeypatch.setattr(fft, "_override", n_threads)
        monkeypatch.setattr(pruned_fft, "_BAND", band)
        spectra = pruned_fft.forward_parts(list(x), shape)
        dest = np.empty((300, 500))
        pruned_fft.inverse_into(spectra[1].copy(), shape, dest)
        results.append((spectra, dest))
    for spectra, dest in results[1:]:
        np.testing.assert_array_equal(spectra, results[0][0])
        np.testing.assert_array_equal(dest, results[0][1])
    np.testing.assert_allclose(results[0][1] / (shape[0] * shape[1]), x[1], rtol=0, atol=1e-13)


@pytest.mark.parametrize("entry_points", [True, False], ids=["pocketfft", "scipy.fft"])
@pytest.mark.parametrize("band", [None, 7])
@pytest.mark.parametrize("dtype, scale", [(np.float64, None), (np.float32, 0.37)])
def test_row_transforms_are_scipy_fft_of_the_padded_rows_bit_for_bit(monkeypatch, entry_points, band, dtype, scale):
    """rfft_rows and irfft_rows (bands of rows in parts on two threads, one buffer per part) give scipy.fft's numbers
    of the zero-padded rows bit for bit, leave their inputs as they were and write only their destination."""
    import scipy.fft as sfft

    use_library(monkeypatch, "pocketfft" if entry_points else "scipy.fft")
    if band is not None:
        monkeypatch.setattr(pruned_fft, "_BAND", band)
        monkeypatch.setattr(pruned_fft, "LINES", 1)  # bands of a few rows
    monkeypatch.setattr(fft, "_override", 2)
    x = np.random.default_rng(5).standard_normal((301, 200))[:, :150]  # a strided view, 301 x 512 padded
    x0 = x.copy()
    ctype = np.result_type(dtype, np.complex64)
    dest = np.full((303, 257), np.nan, ctype)
    pruned_fft.rfft_rows(x, dest[1:-1], 512, dtype, scale)
    np.testing.assert_array_equal(x, x0)
    want = sfft.rfft((x if scale is None else x * scale).astype(dtype), n=512, axis=-1)
    assert dest.dtype == want.dtype and np.array_equal(dest[1:-1], want)
    assert np.isnan(dest[[0, -1]]).all()
    spectrum = dest[1:-1].copy()
    out = np.full((301, 180), -1.0, dtype)
    pruned_fft.irfft_rows(dest[1:-1], out[:, 5:175], 512)
    np.testing.assert_array_equal(dest[1:-1], spectrum)
    np.testing.assert_array_equal(out[:, 5:175], sfft.irfft(spectrum, n=512, axis=-1, norm="forward")[:, :170])
    assert (out[:, :5] == -1.0).all() and (out[:, 175:] == -1.0).all()
