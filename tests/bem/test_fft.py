"""The FFT back end: thread count rule and the padded transform pair."""

import os

import numpy as np
import pytest

from bem import fft
from bem.checks import InputError

from .fft_cases import use_library


def test_threads_follow_affinity_then_env_then_setter(monkeypatch):
    monkeypatch.delenv("CONTACTLAB_THREADS", raising=False)
    expected = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    assert fft.threads() == expected
    monkeypatch.setenv("CONTACTLAB_THREADS", "3")
    assert fft.threads() == 3
    monkeypatch.setenv("CONTACTLAB_THREADS", "zero")  # unusable: back to the affinity rule
    assert fft.threads() == expected
    previous = fft.set_threads(1)
    try:
        assert fft.threads() == 1
    finally:
        fft.set_threads(previous)
    assert fft.threads() == expected


@pytest.mark.parametrize("bad", [0, -1, 2.0, True, "2"])
def test_set_threads_refuses_bad_values(bad):
    with pytest.raises(InputError, match="n = "):
        fft.set_threads(bad)


@pytest.mark.parametrize("n_threads, size, parts", [(2, 1 << 17, 2), (3, 1 << 20, 3), (1, 1 << 20, 1), (2, 1000, 1)])
def test_in_parts_covers_the_axis_once_in_contiguous_parts(monkeypatch, n_threads, size, parts):
    monkeypatch.setattr(fft, "_override", n_threads)
    n = 512
    seen = []
    hits = np.zeros(n, dtype=int)

    def kernel(part):
        seen.append(part)
        hits[part] += 1

    fft.in_parts(kernel, n, size)
    assert len(seen) == parts
    assert np.all(hits == 1)  # every index once: the parts are disjoint and cover the axis
    assert all(s.step is None and s.start < s.stop for s in seen)


def test_in_parts_gives_the_numbers_of_one_thread(monkeypatch):
    """The threaded 2 x 2 block product of the periodic operator is the one-thread product, bit for bit,
    and both are the direct formula ``out_a = S_aa X_a + S_a(1-a) X_(1-a)``."""
    from bem.periodic import PeriodicCell, PeriodicOperator

    cell = PeriodicCell(1.0 / 512, 512, 512)  # a spectrum of 256 x 2 x 257 > 2**17 entries
    op = PeriodicOperator(cell, 1.0)
    X = op.spectrum(np.random.default_rng(1).standard_normal(cell.shape))
    before = X.copy()
    symbol = op.symbol(0.3 * op.diagonal)
    d, b = symbol.rows()
    monkeypatch.setattr(fft, "_override", 2)
    two = op.mix(X, symbol)
    monkeypatch.setattr(fft, "_override", 1)
    one = op.mix(X, symbol)
    np.testing.assert_array_equal(X, before)  # the input is not modified
    np.testing.assert_array_equal(two, one)
    direct = d * X + b * X[:, ::-1, :]
    np.testing.assert_allclose(two, direct, rtol=1e-15, atol=1e-15 * np.abs(direct).max())
    monkeypatch.setattr(fft, "_override", 2)
    Y = X.copy()
    assert op.mix(Y, symbol, out=Y) is Y  # in place, as the solvers call it
    np.testing.assert_array_equal(Y, one)


def test_in_parts_runs_a_part_in_the_calling_thread_and_waits_for_the_others(monkeypatch):
    import threading
    import time

    monkeypatch.setattr(fft, "_override", 3)
    caller, ran = threading.get_ident(), {}

    def kernel(part):
        if part.start == 0:
            time.sleep(0.05)  # a slow part in the pool: the caller waits for it
        ran[part.start] = threading.get_ident()

    fft.in_parts(kernel, 300, 1 << 20)
    assert sorted(ran) == [0, 100, 200]
    assert ran[200] == caller and ran[0] != caller and ran[100] != caller

    def failing(part):
        if part.start == 200:
            raise RuntimeError("the caller's part failed")
        time.sleep(0.05)
        ran[part.start] = "done"

    with pytest.raises(RuntimeError, match="caller's part"):
        fft.in_parts(failing, 300, 1 << 20)
    assert ran[0] == ran[100] == "done"  # the other parts ended before the error reached the caller


def _transforms(x):
    """The six transforms of ``bem.fft`` of ``x`` (``(256, 2, 512)``: 2**18 entries, in parts on two threads) and
    scipy.fft's of the same data: the real FFT along the rows, the complex FFT along the columns in place (the
    parts along another axis), its inverse, unscaled along a short axis, and the inverse real FFT, scaled and not.
    Each leaves the arrays it does not write as they were."""
    import scipy.fft as sfft

    x0 = x.copy()
    spectrum = fft.rfft_into(x, np.empty((256, 2, 257), np.result_type(x.dtype, np.complex64)), 2)
    np.testing.assert_array_equal(x, x0)
    ours, theirs = [spectrum.copy()], [sfft.rfft(x, axis=2)]
    assert fft.cfft_in_place(spectrum, 0, 2) is spectrum  # along axis 0, the parts along axis 2
    ours.append(spectrum.copy())
    theirs.append(sfft.fft(ours[0], axis=0))
    back = fft.cfft_in_place(spectrum.copy(), 0, 2, inverse=True)
    ours.append(back.copy())
    theirs.append(sfft.ifft(spectrum, axis=0))
    ours.append(fft.cfft_in_place(spectrum.copy(), 0, 1, inverse=True, normalise=False))
    theirs.append(sfft.ifft(spectrum, axis=0, norm="forward"))
    ours.append(fft.irfft_into(back, np.empty(x.shape, x.dtype), 512, 2))
    np.testing.assert_array_equal(back, ours[2])
    theirs.append(sfft.irfft(ours[2], n=512, axis=2))
    ours.append(fft.irfft_into(back, np.empty(x.shape, x.dtype), 512, 2, normalise=False))
    theirs.append(sfft.irfft(ours[2], n=512, axis=2, norm="forward"))
    return ours, theirs


@pytest.mark.parametrize("entry_points", [True, False], ids=["pocketfft", "scipy.fft"])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_transforms_in_parts_equal_scipy_fft(monkeypatch, entry_points, dtype):
    """rfft_into, cfft_in_place and irfft_into on two threads give scipy.fft's numbers bit for bit, with
    pocketfft's own entry points and with the scipy.fft fallback, and leave the inputs they do not write as
    they were (:func:`_transforms`)."""
    use_library(monkeypatch, "pocketfft" if entry_points else "scipy.fft")
    monkeypatch.setattr(fft, "_override", 2)
    x = np.random.default_rng(3).standard_normal((256, 2, 512)).astype(dtype)
    ours, theirs = _transforms(x)
    for a, b in zip(ours, theirs):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_allclose(ours[4], x, rtol=0, atol=(1e-5 if dtype == np.float32 else 1e-13) * np.abs(x).max())


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_transforms_through_ducc0_agree_with_scipy_fft_and_split_into_parts_bit_for_bit(monkeypatch, dtype):
    """With ducc0 the transforms give scipy.fft's numbers to rounding (each of the six forms, so a wrong axis,
    direction or scale fails), the same numbers on two threads as on one, bit for bit, and the input back from the
    forward and inverse pair."""
    use_library(monkeypatch, "ducc0")
    x = np.random.default_rng(3).standard_normal((256, 2, 512)).astype(dtype)
    monkeypatch.setattr(fft, "_override", 2)
    two, theirs = _transforms(x)
    monkeypatch.setattr(fft, "_override", 1)
    one, _ = _transforms(x)
    eps = np.finfo(dtype).eps
    for a, b, c in zip(two, one, theirs):
        assert a.dtype == c.dtype
        np.testing.assert_array_equal(a, b)
        np.testing.assert_allclose(a, c, rtol=0, atol=64 * eps * np.abs(c).max())
    np.testing.assert_allclose(two[4], x, rtol=0, atol=64 * eps * np.abs(x).max())


def test_library_takes_ducc0_but_for_single_precision_real_transforms(monkeypatch):
    """The rule of the back end: ducc0 for every double-precision transform and the single-precision complex ones,
    pocketfft for the single-precision real ones; pocketfft for all without ducc0."""
    import types

    ducc = types.SimpleNamespace(name="ducc0")
    monkeypatch.setattr(fft, "_ducc0", ducc)
    for kind, dtype in [("r2c", np.float64), ("c2r", np.complex128), ("c2c", np.complex128), ("c2c", np.complex64)]:
        assert fft._library(kind, dtype) is ducc, (kind, dtype)
    for kind, dtype in [("r2c", np.float32), ("c2r", np.complex64)]:
        assert fft._library(kind, dtype) is fft._pocketfft, (kind, dtype)
    monkeypatch.setattr(fft, "_ducc0", None)
    assert all(fft._library(k, d) is fft._pocketfft for k in ("r2c", "c2c", "c2r") for d in (np.float64, np.float32))


def test_ducc0_is_used_only_where_it_is_installed_and_checks_out(monkeypatch):
    """Without the module, with a changed signature or with wrong numbers, ducc0 is not taken."""
    import sys

    ducc0 = pytest.importorskip("ducc0")
    assert fft._ducc_entry_points() is ducc0.fft
    monkeypatch.setitem(sys.modules, "ducc0", None)  # import ducc0 raises ImportError
    assert fft._ducc_entry_points() is None
    monkeypatch.undo()

    def changed(*args, **kwargs):
        raise TypeError("c2c() takes a new signature")

    monkeypatch.setattr(ducc0.fft, "c2c", changed)
    assert fft._ducc_entry_points() is None
    monkeypatch.undo()
    real = ducc0.fft.r2c
    monkeypatch.setattr(ducc0.fft, "r2c", lambda *a: 2 * real(*a))
    assert fft._ducc_entry_points() is None


def test_pocketfft_entry_points_are_used_only_where_they_check_out(monkeypatch):
    """The private entry points are taken only if they exist with the signatures used and give NumPy's numbers:
    a changed signature or wrong numbers fall back to scipy.fft (whose path the test above checks)."""
    from scipy.fft._pocketfft import pypocketfft

    assert fft._entry_points() is pypocketfft  # this SciPy's pass

    def changed(*args, **kwargs):
        raise TypeError("r2c() takes a new signature")

    monkeypatch.setattr(pypocketfft, "r2c", changed)
    assert fft._entry_points() is None
    monkeypatch.undo()
    real = pypocketfft.c2r
    monkeypatch.setattr(pypocketfft, "c2r", lambda *a: 2 * real(*a))
    assert fft._entry_points() is None


@pytest.mark.parametrize("library", ["pocketfft", "ducc0"])
def test_solves_give_the_same_numbers_on_one_two_and_three_threads(monkeypatch, library):
    """The transforms' parts begin at multiples of LINES lines, so that a cell and a half-space region (whose arrays
    are split into parts) give the same pressures bit for bit on 1, 2 and 3 threads through either library. With
    parts anywhere ducc0's do not (its last lines of a call are rounded otherwise): a 3-thread cell differs."""
    import math

    import bem
    from bem import pruned_fft
    from bem.periodic import PeriodicCell

    from .newton_cases import waves

    use_library(monkeypatch, library)
    cell = PeriodicCell(1.0 / 512, 512, 512)  # 262144 nodes: its transforms in parts
    h = waves(cell, seed=3, modes=40)

    def bump(x, y):  # a sphere with ripples on a region of 416,147 nodes
        return (x * x + y * y) / 2.0 - 2e-3 * np.cos(40 * x) * np.cos(37 * y)

    def solves():
        cell_p = bem.solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=0.01).p
        region = bem.solve(bump, E_star=1.0, step=2 * math.sqrt(0.3) / 600, extent=math.sqrt(0.3), force=0.02)
        return np.asarray(cell_p), np.asarray(region.p)

    results = []
    for n in (1, 2, 3):
        monkeypatch.setattr(fft, "_override", n)
        results.append(solves())
    for cell_p, region_p in results[1:]:
        np.testing.assert_array_equal(cell_p, results[0][0])
        np.testing.assert_array_equal(region_p, results[0][1])
    if library == "ducc0":  # the planted fault: parts anywhere
        monkeypatch.setattr(fft, "LINES", 1)
        monkeypatch.setattr(pruned_fft, "LINES", 1)
        monkeypatch.setattr(fft, "_override", 3)
        assert not np.array_equal(solves()[0], results[0][0])
