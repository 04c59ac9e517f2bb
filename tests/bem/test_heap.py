"""bem.heap: the C library's free heap returned to the system before the largest products."""

import platform

import numpy as np
import pytest

import bem.column_bands as column_bands
import bem.heap as heap
from bem.lattice import Lattice
from bem.operator import InfluenceOperator


def _recorder(monkeypatch):
    calls = []
    monkeypatch.setattr(heap, "_malloc_trim", lambda: calls.append)
    return calls


def test_release_asks_the_c_library_only_above_its_size(monkeypatch):
    calls = _recorder(monkeypatch)
    assert heap.release(heap.RELEASE_ABOVE) is False and calls == []
    assert heap.release(heap.RELEASE_ABOVE + 1) is True and calls == [0]


def test_release_does_nothing_without_glibc(monkeypatch):
    heap._malloc_trim.cache_clear()
    monkeypatch.setattr(heap.sys, "platform", "darwin")
    try:
        assert heap._malloc_trim() is None
        assert heap.release(1 << 40) is False
    finally:
        heap._malloc_trim.cache_clear()


@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="glibc's malloc_trim")
def test_glibc_trims_and_the_products_by_bands_keep_their_numbers(monkeypatch):
    assert heap._malloc_trim() is not None and heap.release(heap.RELEASE_ABOVE + 1) is True
    monkeypatch.setattr(column_bands, "_BAND_BYTES", 1)  # the products by bands
    monkeypatch.setattr("bem.operator.BANDS_ABOVE", 0)
    lat = Lattice.from_extent(0.02, 1.0)
    p = np.where(lat.mask, np.random.default_rng(7).random(lat.shape), 0.0)
    expected = InfluenceOperator(lat, 1.0).matvec(p)
    calls = []
    real = heap._malloc_trim()
    monkeypatch.setattr(heap, "RELEASE_ABOVE", 0)  # every product's work array: the real malloc_trim asked for
    monkeypatch.setattr(heap, "_malloc_trim", lambda: lambda pad: calls.append(pad) or real(pad))
    assert np.array_equal(InfluenceOperator(lat, 1.0).matvec(p), expected)
    assert calls and set(calls) == {0}
