"""bem.heap: the C library's free heap returned to the system before the largest products."""

import platform

import numpy as np
import pytest

import bem.column_bands as column_bands
from bem import diagonal_coefficient
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


@pytest.mark.parametrize("domain", ["cell", "half-space"])
def test_newton_asks_for_the_free_heap_at_each_step_and_before_its_product_after_a_cells_model_qp(monkeypatch, domain):
    """Newton asks :func:`bem.heap.release` at the start of each step with the bytes of three arrays of the lattice
    (the closure, ``C p + w`` and the gap made there) and, on a cell whose model QP held ``C p``, before it makes the
    product again (its spectrum and output); the cell's QP asks before each product of the whole cell that makes its
    ``u`` anew (with the bytes of the product's double-precision spectrum); the release changes no number."""
    from bem import layers, newton
    from bem.periodic import PeriodicCell, PeriodicOperator

    monkeypatch.setattr(heap, "RELEASE_ABOVE", 0)  # every size: the cell's model QPs hold C p, the C library asked
    if domain == "cell":
        cell = PeriodicCell(1.0 / 32, 32, 32)
        make = lambda: PeriodicOperator(cell, 1.0)  # noqa: E731
        h, force = 0.02 * (1 - np.cos(2 * np.pi * cell.x) * np.cos(2 * np.pi * cell.y)), 0.02
    else:
        lat = Lattice.from_extent(0.02, 0.3)
        make = lambda: InfluenceOperator(lat, 1.0)  # noqa: E731
        h, force = np.where(lat.mask, (lat.x**2 + lat.y**2) / 2, 0.0), 0.01
    layer = layers.Root(0.3 * diagonal_coefficient(0.02 if domain == "half-space" else 1.0 / 32, 1.0))
    asked, trims, real = [], [], heap.release
    monkeypatch.setattr(heap, "release", lambda nbytes: asked.append(nbytes))  # not trimmed
    kept = newton.solve_newton(make(), h, layer=layer, force=force)
    monkeypatch.setattr(heap, "release", lambda nbytes: asked.append(nbytes) or real(nbytes))
    monkeypatch.setattr(heap, "_malloc_trim", lambda: trims.append)
    trimmed = newton.solve_newton(make(), h, layer=layer, force=force)
    assert kept.converged and trimmed.converged and trimmed.iterations == kept.iterations >= 2
    assert np.array_equal(trimmed.p, kept.p) and np.array_equal(trimmed.displacement, kept.displacement)
    n_lattice = 8 * h.size
    steps = kept.iterations + 1  # the steps' starts, the last one's included
    expected = [3 * n_lattice] * steps + ([2 * n_lattice] * kept.iterations if domain == "cell" else [])
    by_newton = [n for n in asked if n in (2 * n_lattice, 3 * n_lattice)]
    by_qp = [n for n in asked if n not in (2 * n_lattice, 3 * n_lattice)]
    assert sorted(by_newton) == sorted(expected * 2) and len(trims) == len(asked) // 2 and set(trims) == {0}
    spectrum = 16 * (h.shape[0] // 2) * 2 * (h.shape[1] // 2 + 1)
    assert set(by_qp) == ({spectrum} if domain == "cell" else set()) and (by_qp or domain == "half-space")
