"""Rough surfaces (bem.rough): synthesis, files, the periodic cell, statistics, the lattice, and the core
install without the [rough] extra."""

import importlib.util
import logging
import math
import re
import sys
from pathlib import Path

import numpy as np
import pytest

import bem
from bem import rough
from bem.gaps.measured import read_heights

SQRT3 = math.sqrt(3.0)
#: the tests of the parts that need the [rough] extra
needs_extra = pytest.mark.skipif(importlib.util.find_spec("SurfaceTopography") is None,
                                 reason="needs contactlab[rough] (SurfaceTopography)")


def _sinusoid(shape, size, a, b, phase=0.3):
    """``cos(2 pi (a x/Lx + b y/Ly) + phase)`` on the periodic grid ``z[i, j]`` at ``(i Lx/nx, j Ly/ny)``."""
    x = np.arange(shape[0])[:, None] / shape[0]
    y = np.arange(shape[1])[None, :] / shape[1]
    return np.cos(2 * np.pi * (a * x + b * y) + phase)


def _band_limited(shape, kmax, seed):
    """A random periodic grid with wave numbers ``|kx|, |ky| <= kmax`` only."""
    rng = np.random.default_rng(seed)
    spectrum = np.zeros(shape, dtype=complex)
    k0 = np.fft.fftfreq(shape[0], 1 / shape[0])[:, None]
    k1 = np.fft.fftfreq(shape[1], 1 / shape[1])[None, :]
    inside = (np.abs(k0) <= kmax) & (np.abs(k1) <= kmax)
    spectrum[inside] = rng.normal(size=inside.sum()) + 1j * rng.normal(size=inside.sum())
    return np.fft.ifft2(spectrum).real


def _spectral_slopes(rows, period):
    """rms of the derivative along axis 1 of periodic ``rows`` of the given period (spectral)."""
    k = 2j * np.pi * np.fft.fftfreq(rows.shape[1], period / rows.shape[1])
    return np.sqrt(np.mean(np.fft.ifft(k * np.fft.fft(rows, axis=1), axis=1).real ** 2))


# --- the lattice (core, numpy only) -----------------------------------------------------------

@pytest.mark.parametrize("shape, size, n_cols, a, b", [
    ((16, 12), (2.0, 1.5), 20, 3, -2),   # finer lattice
    ((32, 40), (1.0, 1.3), 12, -5, 4),   # coarser lattice, wave within its band
    ((15, 9), (1.0, 1.0), 30, 7, 4),     # odd data lengths
    ((64, 64), (1.0, 1.0), 16, 8, 3),    # kx at the lattice's Nyquist wave number
])
def test_sinusoid_is_resampled_exactly_onto_the_lattice(shape, size, n_cols, a, b, caplog):
    z = _sinusoid(shape, size, a, b)
    before = z.copy()
    with caplog.at_level(logging.WARNING):
        lat = rough.to_lattice(z, size, n_cols)
    assert np.array_equal(z, before)  # the input is not modified
    c = size[0] / n_cols
    assert lat.step == pytest.approx(c, rel=1e-15)
    assert lat.n_rows % 2 == 0 and abs(lat.n_rows - size[1] / (c * SQRT3 / 2)) <= 1
    assert lat.heights.shape == (lat.n_rows, lat.n_cols)
    assert lat.size == pytest.approx((n_cols * c, lat.n_rows * c * SQRT3 / 2), rel=1e-15)
    assert lat.stretch_y == pytest.approx(lat.size[1] / size[1], rel=1e-15)
    r, q = np.mgrid[0:lat.n_rows, 0:n_cols]
    x, y = (q + 0.5 * (r % 2)) * c, r * c * SQRT3 / 2
    expected = np.cos(2 * np.pi * (a * x / lat.size[0] + b * y / lat.size[1]) + 0.3)
    assert np.abs(lat.heights - expected).max() < 1e-12
    assert lat.stretch_large == (abs(lat.stretch_y - 1) > rough.MAX_STRETCH)
    assert lat.stretch_large == any("stretches the data along y" in m for m in caplog.messages)
    gap = lat.gap()  # against a flat: the highest node touches first
    assert gap.min() == 0 and np.array_equal(gap, lat.heights.max() - lat.heights)


def test_lattice_keeps_rms_height_and_slopes_of_a_band_limited_surface():
    size = (1.0, 0.9)
    z = _band_limited((48, 40), 6, seed=4)
    lat = rough.to_lattice(z, size, 64)
    assert not lat.stretch_large
    # rms height: Parseval on the data grid and on every lattice row set (the band is inside both)
    assert np.sqrt(np.mean(lat.heights**2)) == pytest.approx(np.sqrt(np.mean(z**2)), rel=1e-12)
    # slopes along x on every row, along y on the columns of the even rows; y is stretched by stretch_y
    sx_data = _spectral_slopes(z.T, size[0])
    sy_data = _spectral_slopes(z, size[1])
    assert _spectral_slopes(lat.heights, lat.size[0]) == pytest.approx(sx_data, rel=1e-12)
    assert _spectral_slopes(lat.heights[0::2].T, lat.size[1]) == pytest.approx(sy_data / lat.stretch_y, rel=1e-12)


def test_coarser_lattice_drops_the_wavelengths_it_cannot_carry():
    z = _sinusoid((64, 64), (1.0, 1.0), 2, 1) + _sinusoid((64, 64), (1.0, 1.0), 20, 0, phase=1.0)
    lat = rough.to_lattice(z, (1.0, 1.0), 16)  # carries |kx| <= 8: the kx = 20 wave goes
    x, y = lat.positions()
    expected = np.cos(2 * np.pi * (2 * x / lat.size[0] + y / lat.size[1]) + 0.3)
    assert np.abs(lat.heights - expected).max() < 1e-12


@pytest.mark.parametrize("kwargs, blamed", [
    ({"heights": np.ones(8)}, "heights"),
    ({"heights": np.full((8, 8), np.nan)}, "heights"),
    ({"heights": np.ones((1, 8))}, "heights.shape"),
    ({"size": (1.0, -1.0)}, "size[1]"),
    ({"size": 1.0}, "size"),
    ({"n_cols": 1}, "n_cols"),
])
def test_lattice_refuses_bad_arguments(kwargs, blamed):
    args = {"heights": np.ones((8, 8)), "size": (1.0, 1.0), "n_cols": 8, **kwargs}
    with pytest.raises(bem.InputError) as err:
        rough.to_lattice(**args)
    assert str(err.value).startswith(blamed)


# --- synthetic surfaces ------------------------------------------------------------------------

def _hurst_from_psd(surface, long_cutoff, short_cutoff):
    """Hurst exponent of the PSD slope ``C ~ q^(-2-2H)`` fitted between 2 q_L and q_s/2."""
    q, c = surface.power_spectrum()
    fit = (q >= 2 * 2 * np.pi / long_cutoff) & (q <= 0.5 * 2 * np.pi / short_cutoff)
    slope = np.polyfit(np.log(q[fit]), np.log(c[fit]), 1)[0]
    return -(slope + 2) / 2


@needs_extra
def test_self_affine_surface_has_the_hurst_exponent_and_rms_height_asked_for():
    lc, sc = 0.25, 4 / 256
    estimates = []
    for seed in range(8):
        s = rough.self_affine((256, 256), (1.0, 1.0), hurst=0.7, rms_height=2e-6, long_cutoff=lc,
                              short_cutoff=sc, seed=seed)
        assert s.stats.rms_height == pytest.approx(2e-6, rel=1e-12)
        assert s.stats.periodic and not s.stats.edge_jump_large
        estimates.append(_hurst_from_psd(s, lc, sc))
    # one realisation scatters by 0.055 (sd over 12 seeds); the mean of 8 is within 3 sd/sqrt(8)
    assert np.mean(estimates) == pytest.approx(0.7, abs=0.06)


@needs_extra
def test_self_affine_surface_is_reproducible_with_its_seed():
    kw = {"hurst": 0.8, "rms_slope": 0.1, "short_cutoff": 0.1, "seed": 7}
    a, b = rough.self_affine((32, 24), (2.0, 1.5), **kw), rough.self_affine((32, 24), (2.0, 1.5), **kw)
    c = rough.self_affine((32, 24), (2.0, 1.5), **{**kw, "seed": 8})
    assert np.array_equal(a.heights, b.heights) and not np.allclose(a.heights, c.heights)
    assert a.stats.rms_slope == pytest.approx(0.1, rel=1e-12)
    assert a.heights.shape == (32, 24) and a.size == (2.0, 1.5)
    with pytest.raises(ValueError):
        a.heights[0, 0] = 1.0  # read-only


@needs_extra
@pytest.mark.parametrize("kwargs, blamed", [
    ({"hurst": 0.0}, "hurst"),
    ({"hurst": 1.5}, "hurst"),
    ({"rms_slope": 0.1}, "(rms_height, rms_slope)"),
    ({"rms_height": -1.0}, "rms_height"),
    ({"grid": (4, 64)}, "grid[0]"),
    ({"seed": None}, "seed"),
    ({"long_cutoff": 0.01, "short_cutoff": 0.1}, "long_cutoff"),
])
def test_self_affine_refuses_bad_arguments(kwargs, blamed):
    args = {"grid": (16, 16), "size": (1.0, 1.0), "hurst": 0.8, "rms_height": 1.0, "seed": 1, **kwargs}
    with pytest.raises(bem.InputError) as err:
        rough.self_affine(**args)
    assert str(err.value).startswith(blamed)


# --- files ---------------------------------------------------------------------------------------

def _periodic_map(shape=(32, 24), size=(2.0, 1.5)):
    """A smooth periodic height map (two waves) and its size."""
    return 0.5 * _sinusoid(shape, size, 2, 1) + 0.2 * _sinusoid(shape, size, -1, 3, phase=1.1), size


@needs_extra
def test_npy_text_and_x3p_files_are_read_in_their_own_layouts(tmp_path):
    import SurfaceTopography

    z, size = _periodic_map()
    np.save(tmp_path / "map.npy", z)  # SurfaceTopography's npy layout: z[ix, iy]
    in_um = SurfaceTopography.Topography(z, size, unit="µm")
    in_um.to_matrix(str(tmp_path / "map.txt"))  # rows along y, size and unit in the header
    in_um.to_x3p(str(tmp_path / "map.x3p"))  # in metres, always
    scale = 1e-6  # metres per um: every file comes back in metres
    for name, kw in (("map.npy", {"physical_sizes": size, "unit": "um"}), ("map.txt", {}), ("map.x3p", {})):
        s = rough.read_surface(tmp_path / name, detrend=None, **kw)
        assert np.allclose(s.heights, z * scale, rtol=0, atol=1e-12 * scale), name
        assert s.size == pytest.approx((size[0] * scale, size[1] * scale), rel=1e-12)
        assert s.stats.grid == z.shape and s.stats.source == str(tmp_path / name)
        assert s.stats.rms_height == pytest.approx(np.std(z) * scale, rel=1e-12)
        assert not s.stats.edge_jump_large
    # the core reader takes the same text table as rows along y: the same grid
    _, _, core = read_heights(tmp_path / "map.txt", spacing=(size[0] / z.shape[0], size[1] / z.shape[1]))
    assert np.allclose(core, z, rtol=0, atol=1e-15)


@needs_extra
def test_detrending_removes_the_plane_of_least_rms_height(tmp_path):
    z, size = _periodic_map()
    x = np.arange(z.shape[0])[:, None] / z.shape[0]
    y = np.arange(z.shape[1])[None, :] / z.shape[1]
    np.save(tmp_path / "tilted.npy", z + 3.0 + 0.8 * x - 0.4 * y)
    kept = rough.read_surface(tmp_path / "tilted.npy", physical_sizes=size, unit="m", detrend=None)
    flat = rough.read_surface(tmp_path / "tilted.npy", physical_sizes=size, unit="m")
    plane = kept.heights - flat.heights
    fit = np.linalg.lstsq(np.column_stack([np.ones(z.size), np.broadcast_to(x, z.shape).ravel(),
                                           np.broadcast_to(y, z.shape).ravel()]), kept.heights.ravel(), rcond=None)[0]
    assert np.allclose(plane.ravel(), fit[0] + fit[1] * np.broadcast_to(x, z.shape).ravel()
                       + fit[2] * np.broadcast_to(y, z.shape).ravel(), atol=1e-12)
    assert flat.stats.detrend == "height" and abs(flat.heights.mean()) < 1e-12


@needs_extra
def test_edge_jump_of_a_patch_is_reported_and_warned(tmp_path, caplog):
    size = (1.0, 1.0)
    x = (np.arange(32)[:, None] + 0.5) / 32
    patch = np.cos(np.pi * x) + 0.0 * np.arange(32)[None, :]  # a half wave: opposite x-edges differ by ~2
    np.save(tmp_path / "patch.npy", patch)
    with caplog.at_level(logging.WARNING):
        s = rough.read_surface(tmp_path / "patch.npy", physical_sizes=size, unit="m", detrend="center")
    jumps = np.concatenate([s.heights[0, :] - s.heights[-1, :], s.heights[:, 0] - s.heights[:, -1]])
    assert s.stats.edge_jump == pytest.approx(np.sqrt(np.mean(jumps**2)), rel=1e-12)
    # neighbours differ along x only: the mean over both directions (weights ny, nx) is half that along x
    assert s.stats.grid_step == pytest.approx(np.sqrt(np.mean(np.diff(s.heights, axis=0) ** 2) / 2), rel=1e-12)
    assert s.stats.edge_jump > 10 * s.stats.grid_step and s.stats.edge_jump_large
    assert any("edge jump" in m and "patch.npy" in m for m in caplog.messages)
    z, _ = _periodic_map((32, 32), size)  # one period of a smooth periodic map: no seam
    caplog.clear()
    with caplog.at_level(logging.WARNING):
        smooth = rough.from_heights(z, size, detrend="center")
    assert not smooth.stats.edge_jump_large and not caplog.messages
    assert smooth.stats.edge_jump == pytest.approx(smooth.stats.grid_step, rel=0.5)


@needs_extra
@pytest.mark.parametrize("hurst", [0.1, 0.3, 0.8])
def test_a_periodic_self_affine_surface_has_no_seam(hurst, caplog):
    with caplog.at_level(logging.WARNING):
        s = rough.self_affine((32, 32), (1.0, 1.0), hurst=hurst, rms_height=1.0, seed=1)
    assert not s.stats.edge_jump_large and not caplog.messages


@needs_extra
@pytest.mark.parametrize("make, kwargs, blamed, rule", [
    (lambda p: p.write_bytes(b"\x00\x01hello secret\xff" * 40), {}, "file", "not a readable .npy file"),
    (lambda p: p.with_suffix(".x3p").write_bytes(b"\x00\x01hello secret\xff" * 400), {}, "file",
     "not a readable x3p file"),
    (lambda p: p.with_suffix(".bin").write_bytes(b"\x00\x01hello secret\xff" * 40), {}, "file", "cannot read"),
    (lambda p: np.save(p, np.ones((16, 16))), {"format": "foo"}, "format", "one of"),
    (lambda p: np.save(p, np.where(np.eye(16) > 0, np.nan, 1.0)), {"physical_sizes": (1, 1), "unit": "m"}, "file",
     "16 points without data"),
    (lambda p: np.savetxt(p.with_suffix(".txt"), np.c_[np.cumsum(np.linspace(0.5, 1.5, 40)), np.zeros(40)]), {},
     "file", "not on an evenly spaced grid"),
    (lambda p: np.save(p, np.ones((6, 16))), {"physical_sizes": (1, 1), "unit": "m"}, "file", "too small"),
    (lambda p: np.save(p, np.ones((16, 16))), {"unit": "m"}, "physical_sizes is missing", "give (Lx, Ly)"),
    (lambda p: None, {}, "file", "an existing file"),
    (lambda p: np.save(p, np.ones((16, 16))), {"physical_sizes": (1, 1), "detrend": "plane"}, "detrend", "one of"),
    (lambda p: np.save(p, np.ones((16, 16))), {"physical_sizes": (1, 1), "unit": 0}, "unit", "> 0"),
    (lambda p: np.save(p, np.ones((16, 16))), {"physical_sizes": (1, 1)}, "unit is missing", "states no length unit"),
])
def test_bad_files_stop_with_a_message_naming_the_argument(tmp_path, make, kwargs, blamed, rule, caplog, capsys):
    path = tmp_path / "bad.npy"  # np.save would add .npy to another name
    make(path)
    written = [p for p in tmp_path.iterdir()]
    with caplog.at_level(logging.DEBUG), pytest.raises(bem.InputError) as err:
        rough.read_surface(written[0] if written else path, **kwargs)
    message = str(err.value)
    assert message.startswith(blamed) and rule in message, message
    for said in (message, caplog.text, *capsys.readouterr()):
        assert "secret" not in said and "hello" not in said  # nothing quoted from the file


@needs_extra
@pytest.mark.parametrize("kwargs, blamed", [
    ({"heights": np.where(np.eye(8) > 0, np.nan, 0.0)}, "heights"),
    ({"heights": np.zeros((4, 16))}, "heights.shape"),
    ({"size": (1.0, 0.0)}, "size[1]"),
    ({"periodic": True, "detrend": "height"}, "detrend"),
])
def test_from_heights_refuses_bad_arguments(kwargs, blamed):
    args = {"heights": np.zeros((8, 8)), "size": (1.0, 1.0), **kwargs}
    with pytest.raises(bem.InputError) as err:
        rough.from_heights(**args)
    assert str(err.value).startswith(blamed)


@needs_extra
def test_superfluous_physical_sizes_are_refused(tmp_path):
    import SurfaceTopography

    z, size = _periodic_map()
    SurfaceTopography.Topography(z, size).to_matrix(str(tmp_path / "map.txt"))
    with pytest.raises(bem.InputError, match=r"^physical_sizes = .* states its size"):
        rough.read_surface(tmp_path / "map.txt", physical_sizes=size)


# --- two surfaces, the lattice of a surface -----------------------------------------------------------

@needs_extra
def test_two_rough_surfaces_in_contact_are_their_sum():
    a = rough.self_affine((64, 64), (1.0, 1.0), hurst=0.8, rms_height=1.0, seed=1)
    b = rough.self_affine((64, 64), (1.0, 1.0), hurst=0.5, rms_height=0.5, seed=2)
    both = rough.combined(a, b)
    assert np.array_equal(both.heights, np.asarray(a.heights) + np.asarray(b.heights))
    assert both.stats.rms_height == pytest.approx(np.std(both.heights), rel=1e-12)
    assert both.stats.periodic and "seed = 1" in both.stats.source and "seed = 2" in both.stats.source
    other = rough.self_affine((64, 32), (1.0, 0.5), hurst=0.5, rms_height=0.5, seed=2)
    with pytest.raises(bem.InputError, match=r"^second = .* on the grid \(64, 64\)"):
        rough.combined(a, other)


@needs_extra
def test_surface_on_the_lattice_and_its_report():
    s = rough.self_affine((64, 64), (1.0, 1.0), hurst=0.8, rms_height=1.0, short_cutoff=0.125, seed=3)
    lat = s.to_lattice(64)  # the surface holds |k| <= 8: the lattice carries it whole
    assert lat.n_rows == 74 and not lat.stretch_large
    assert np.sqrt(np.mean(lat.heights**2)) == pytest.approx(s.stats.rms_height, rel=1e-12)
    # a rough surface with power up to the grid's Nyquist wave number (measured: 2e-6 on a finer lattice)
    rough_one = rough.self_affine((128, 128), (1.0, 1.0), hurst=0.3, rms_height=1.0, seed=5)
    fine = rough_one.to_lattice(256)
    assert np.sqrt(np.mean(fine.heights**2)) == pytest.approx(1.0, rel=1e-5)
    coarse = rough_one.to_lattice(64)  # loses the power beyond its band, |kx| <= 32, |ky| <= n_rows/2
    k0 = np.fft.fftfreq(128, 1 / 128)
    band = (np.abs(k0)[:, None] <= 32) & (np.abs(k0)[None, :] <= coarse.n_rows / 2)
    kept = np.fft.ifft2(np.where(band, np.fft.fft2(rough_one.heights), 0)).real
    assert np.sqrt(np.mean(coarse.heights**2)) == pytest.approx(np.sqrt(np.mean(kept**2)), rel=1e-4)
    assert np.sqrt(np.mean(coarse.heights**2)) < 0.995
    report = s.stats.as_dict()
    assert report["grid"] == [64, 64] and report["size"] == [1.0, 1.0] and report["edge_jump_large"] is False
    assert set(report) >= {"rms_height", "rms_slope", "rms_curvature", "edge_jump", "grid_step", "source"}


@needs_extra
def test_the_example_of_docs_rough_runs(capsys):
    text = (Path(__file__).resolve().parents[2] / "docs" / "rough.md").read_text()
    code = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    exec(compile(code, "docs/rough.md", "exec"), {})
    out = capsys.readouterr().out
    assert float(re.search(r"'rms_height': (\S+),", out).group(1)) == pytest.approx(1e-6, rel=1e-12)
    assert "'source': 'self-affine H = 0.8, seed = 1'" in out
    step, n_rows, shape, stretch = re.search(r"\n(\S+) (\d+) \((\d+), 96\) (\S+)\n", out).groups()
    assert float(step) == pytest.approx(200e-6 / 96) and int(n_rows) % 2 == 0 and shape == n_rows
    assert abs(float(stretch) - 1) <= math.sqrt(3) / (2 * 96)


# --- the core without the extra ----------------------------------------------------------------

def test_core_works_without_the_extra_and_rough_surfaces_name_it(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "SurfaceTopography", None)  # import SurfaceTopography fails
    np.save(tmp_path / "map.npy", np.arange(64.0).reshape(8, 8))
    x, y, z = read_heights(tmp_path / "map.npy", spacing=1.0)
    assert z.shape == (8, 8)
    result = bem.solve(bem.gaps.Paraboloid(1.0), E_star=1.0, step=0.1, extent=1.0, force=1.0)
    assert result.converged
    lat = rough.to_lattice(_sinusoid((16, 16), (1.0, 1.0), 1, 1), (1.0, 1.0), 16)
    assert lat.heights.shape == (lat.n_rows, 16)
    calls = [lambda: rough.read_surface(tmp_path / "map.npy", physical_sizes=(1, 1)),
             lambda: rough.self_affine((16, 16), (1.0, 1.0), hurst=0.8, rms_height=1.0, seed=1),
             lambda: rough.from_heights(np.ones((8, 8)), (1.0, 1.0), detrend="height"),
             rough.formats]
    for call in calls:
        with pytest.raises(bem.InputError, match=r"install contactlab\[rough\]"):
            call()
