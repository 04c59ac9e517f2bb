"""The cell of a measured surface in a scene (``[gap] detrend``, ``cell``, ``spikes``, ``spike_threshold``) on real
instrument files: what each key does to the heights, checked against numpy in the test; what result.json records;
the seam stated once; a mirrored cell refused from its size before it is made."""

import json

import numpy as np
import pytest
import tomli_w

import bem.checks
import bem.rough.patch
from validation.scene import SceneError, load_scene

from ..instrument_data import instrument_file, unpacked
from .conftest import cli

st = pytest.importorskip("SurfaceTopography")

TOP = "top-1.top"             # 256 x 256, nm, a patch (not periodic), a large seam
SPOT = "spot_1-1000nm.ibw"    # 256 x 256, m, an AFM scan with particles (spikes)
SUR = "sur-2.sur"             # 563 x 484, mm, 117 missing points


def _scene(folder, gap, units="SI (m, Pa, N)", E_star=115e9, mean_pressure=5e7, cell_nodes=32):
    (folder / "data").mkdir(exist_ok=True)
    if not (folder / "data" / gap["file"]).is_file():
        instrument_file(gap["file"], folder / "data")
    raw = {"scene": {"name": "cell", "units": units}, "bodies": {"E_star": E_star},
           "gap": {"type": "surface", **gap, "file": f"data/{gap['file']}"}, "load": {"mean_pressure": mean_pressure},
           "bem": {"periodic": True, **({} if cell_nodes is None else {"cell_nodes": cell_nodes})}}
    path = folder / "scene.toml"
    path.write_text(tomli_w.dumps(raw))
    return path


def _raw(name, factor=1.0):
    """The file's heights as measured, times ``factor`` (SurfaceTopography directly)."""
    topo = st.open_topography(str(unpacked(name))).topography()
    return np.ma.getdata(topo.heights()) * factor


def _plane_residual(z):
    """The least-squares plane a + b i + c j of z, fitted by numpy: its coefficients (b, c) and mean a."""
    i, j = np.meshgrid(np.arange(z.shape[0]), np.arange(z.shape[1]), indexing="ij")
    design = np.column_stack([np.ones(z.size), i.ravel(), j.ravel()])
    coeffs, *_ = np.linalg.lstsq(design, z.ravel(), rcond=None)
    return coeffs


def test_detrend_none_keeps_the_measured_heights_and_height_takes_off_the_plane(tmp_path):
    raw = _raw(TOP, 1e-9)  # the file states nm
    kept = load_scene(_scene(tmp_path, {"file": TOP, "detrend": "none"})).gap
    np.testing.assert_allclose(kept.surface.heights, raw, rtol=1e-12, atol=0)
    assert kept.cell.detrend == "none" and kept.surface.stats.detrend is None
    level = load_scene(_scene(tmp_path, {"file": TOP})).gap  # default "auto": height for a patch
    assert level.cell.detrend == "height"
    a, b, c = _plane_residual(level.surface.heights)
    scale = np.abs(raw).max()
    assert abs(a) < 1e-12 * scale and abs(b) < 1e-14 * scale and abs(c) < 1e-14 * scale
    a0, b0, c0 = _plane_residual(raw)
    assert max(abs(b0), abs(c0)) > 1e-6 * scale  # the file's plane is not nothing: the test would see it kept
    form = load_scene(_scene(tmp_path, {"file": TOP, "detrend": "curvature"})).gap.surface.heights
    i, j = np.meshgrid(np.arange(256.0), np.arange(256.0), indexing="ij")
    design = np.column_stack([np.ones(i.size), i.ravel(), j.ravel(), i.ravel() ** 2, i.ravel() * j.ravel(),
                              j.ravel() ** 2])
    coeffs, *_ = np.linalg.lstsq(design, form.ravel(), rcond=None)
    assert np.abs(coeffs * [1, 256, 256, 256**2, 256**2, 256**2]).max() < 1e-9 * scale


def test_cell_mirror_holds_the_patch_and_its_images_without_a_seam(tmp_path):
    repeat = load_scene(_scene(tmp_path, {"file": TOP}, cell_nodes=None)).gap
    mirror = load_scene(_scene(tmp_path, {"file": TOP, "cell": "mirror"}, cell_nodes=None)).gap
    z, m = repeat.surface.heights, mirror.surface.heights
    assert m.shape == (512, 512) and mirror.surface.size == pytest.approx(2 * np.array(repeat.surface.size))
    np.testing.assert_array_equal(m[:256, :256], z)
    np.testing.assert_array_equal(m[256:, :256], z[::-1, :])
    np.testing.assert_array_equal(m[:256, 256:], z[:, ::-1])
    np.testing.assert_array_equal(m[256:, 256:], z[::-1, ::-1])
    assert repeat.surface.stats.edge_jump_large and mirror.surface.stats.edge_jump == 0.0
    assert (repeat.lattice.n_cols, mirror.lattice.n_cols) == (256, 512)  # bem.cell_nodes' default doubles
    assert (repeat.cell.cell, mirror.cell.cell) == ("repeat", "mirror")


def test_spikes_are_found_against_a_robust_statistic_and_removed_on_request(tmp_path, caplog):
    raw = _raw(SPOT)
    with caplog.at_level("WARNING"):
        kept = load_scene(_scene(tmp_path, {"file": SPOT})).gap
    spikes = kept.cell.spikes
    z = kept.surface.heights  # detrended ("auto": height), spikes kept
    median = np.median(z)
    sigma = 1.482602218505602 * np.median(np.abs(z - median))
    assert spikes.median == pytest.approx(median, rel=1e-12) and spikes.robust_sigma == pytest.approx(sigma, rel=1e-12)
    score = (z - median) / sigma
    assert spikes.mask[score > 10].all() and spikes.mask[score < -10].all()
    assert score.max() > 50 and spikes.count > 1000 and not kept.cell.spikes_removed
    assert (z.max() - z.mean()) / z.std() == pytest.approx(spikes.top, rel=1e-9) and spikes.top > 20
    warned = [r.getMessage() for r in caplog.records if "spikes beyond" in r.getMessage()]
    assert len(warned) == 1 and f"{spikes.count} of 65536 points" in warned[0] and "data/" + SPOT in warned[0]
    assert not any("edge jump" in r.getMessage() for r in caplog.records)  # stated by the run, once

    removed = load_scene(_scene(tmp_path, {"file": SPOT, "spikes": "remove"})).gap
    y = removed.surface.heights
    assert removed.cell.spikes_removed and removed.cell.spikes.count == spikes.count
    np.testing.assert_array_equal(y[~spikes.mask], z[~spikes.mask])  # only the spikes change
    assert np.abs((y - median) / sigma).max() < 10  # nothing beyond the threshold is left
    assert removed.surface.stats.rms_height < 0.5 * kept.surface.stats.rms_height
    assert raw.shape == y.shape

    lower = load_scene(_scene(tmp_path, {"file": SPOT, "spike_threshold": 5.0})).gap.cell.spikes
    assert lower.threshold == 5.0 and lower.count > spikes.count


@pytest.mark.parametrize(("key", "value", "rule"), [
    ("detrend", "plane", "one of 'auto', 'none', 'center', 'height', 'slope', 'curvature'"),
    ("cell", "window", "one of 'repeat', 'mirror'"),
    ("spikes", "drop", "one of 'keep', 'remove'"),
    ("spike_threshold", 0.0, "> 0"),
    ("spike_threshold", "ten", "a real number"),
])
def test_bad_cell_keys_are_refused_naming_the_key_before_the_file_is_read(tmp_path, monkeypatch, key, value, rule):
    path = _scene(tmp_path, {"file": TOP, key: value})
    monkeypatch.setattr(st, "open_topography", lambda *a, **k: pytest.fail("the file was read"))
    with pytest.raises(SceneError) as err:
        load_scene(path)
    message = str(err.value)
    assert message.startswith(f"gap.{key} = {value!r} is not allowed: ") and rule in message, message


def test_a_periodic_file_is_refused_a_plane_taken_off(tmp_path):
    z = np.random.default_rng(3).normal(size=(32, 32)) * 1e-7
    (tmp_path / "data").mkdir()
    st.Topography(z, (1e-5, 1e-5), periodic=True).to_netcdf(str(tmp_path / "data" / "periodic.nc"))
    with pytest.raises(SceneError, match=r"^gap.detrend = 'height' is not allowed: it must be 'none', 'center' or "
                                         r"'auto' for a periodic surface"):
        load_scene(_scene(tmp_path, {"file": "periodic.nc", "detrend": "height"}))
    kept = load_scene(_scene(tmp_path, {"file": "periodic.nc"})).gap
    assert kept.cell.detrend == "none" and kept.cell.cell == "periodic"
    np.testing.assert_allclose(kept.surface.heights, z, rtol=1e-15, atol=0)


def test_a_run_records_the_cell_and_states_the_seam_once_in_the_scenes_unit(tmp_path):
    _scene(tmp_path, {"file": SUR, "fill": "harmonic", "spikes": "remove"}, units="mm, MPa, N", E_star=115e3,
           mean_pressure=50.0)
    code, out, err = cli("run", tmp_path / "scene.toml", "--out", tmp_path / "r")
    assert code == 0, err
    result = json.loads((tmp_path / "r" / "result.json").read_text())
    surface = result["periodic"]["surface"]
    assert (surface["cell"], surface["detrend"], surface["spikes_removed"], surface["filled"]) == (
        "repeat", "height", True, 117)
    assert surface["spike_points"] == surface["spikes"]["n_high"] + surface["spikes"]["n_low"] > 0
    seams = [m for m in result["messages"] if "edge jump" in m]
    assert len(seams) == 1 and " mm against a grid step of " in seams[0] and 'gap.cell = "mirror"' in seams[0]
    assert "edge jump" not in err and (out + err).count("edge jump of") + (out + err).count("large edge jump") == 1

    _scene(tmp_path, {"file": SUR, "fill": "harmonic", "cell": "mirror"}, units="mm, MPa, N", E_star=115e3,
           mean_pressure=50.0)
    code, out, err = cli("run", tmp_path / "scene.toml", "--out", tmp_path / "m")
    assert code == 0, err
    result = json.loads((tmp_path / "m" / "result.json").read_text())
    assert result["periodic"]["surface"]["cell"] == "mirror" and result["periodic"]["surface"]["edge_jump"] == 0
    assert not any("edge jump" in m for m in result["messages"]) and "large edge jump" not in out + err


def _no_mirror(monkeypatch):
    monkeypatch.setattr(bem.rough.patch, "_mirrored", lambda z: pytest.fail("the mirrored cell was made"))


def test_a_mirrored_cell_too_large_is_refused_from_its_size_before_it_is_made(tmp_path, monkeypatch):
    # the patch, 65536 points, fits; 2 x 2 patches do not
    monkeypatch.setattr(bem.checks, "machine_memory", lambda: 100_000 * bem.checks.bytes_per_node("surface grid"))
    _no_mirror(monkeypatch)
    assert load_scene(_scene(tmp_path, {"file": SPOT})).gap.surface.heights.size == 65536
    with pytest.raises(SceneError) as err:
        load_scene(_scene(tmp_path, {"file": SPOT, "cell": "mirror"}))
    assert str(err.value).startswith("gap.cell = 'mirror' is not allowed: the mirrored surface grid would hold "
                                     "2.62e+05 nodes (limit 1e+05")
    code, _, err = cli("layer-law", unpacked(SPOT), "--E-star", 115e9, "--cell", "mirror", "--out", tmp_path / "law")
    assert code == 2 and err.startswith("contactlab: error: --cell = 'mirror' is not allowed: the mirrored surface "
                                        "grid would hold 2.62e+05 nodes"), err
    assert not (tmp_path / "law").exists()


def test_the_lattice_of_a_mirrored_cell_is_counted_before_it_is_made(tmp_path, monkeypatch):
    # the grid, 512 x 512 = 262144 points, fits; its default lattice, 512 x 592 nodes, does not
    monkeypatch.setattr(bem.checks, "machine_memory", lambda: 300_000 * bem.checks.bytes_per_node("periodic cell"))
    _no_mirror(monkeypatch)
    code, _, err = cli("layer-law", unpacked(SPOT), "--E-star", 115e9, "--cell", "mirror", "--out", tmp_path / "law")
    assert code == 2 and err.startswith(
        "contactlab: error: --n-cols (default: Lx / max(dx, dy) of the mirrored cell) = 512 is not allowed: the "
        "mirrored periodic cell would hold 3.03e+05 nodes"), err
    with pytest.raises(SceneError, match=r"^bem.cell_nodes \(default: Lx / max\(dx, dy\) of the surface\) = 512 is "
                                         r"not allowed: the periodic cell would hold 3.03e\+05 nodes"):
        monkeypatch.undo()  # the scene's lattice is counted from the cell made (its grid fits)
        monkeypatch.setattr(bem.checks, "machine_memory", lambda: 300_000 * bem.checks.bytes_per_node("periodic cell"))
        load_scene(_scene(tmp_path, {"file": SPOT, "cell": "mirror"}, cell_nodes=None))
