"""A scene of a real instrument file (tests/data/instrument): the file's unit converted to the scene's, missing
points filled on request and recorded, the file named as the scene names it (never by its absolute path)."""

import json
import subprocess
import sys
from pathlib import Path

import pytest
import tomli_w

from validation.scene import SceneError, load_scene

from ..instrument_data import instrument_file, rewrite_x3p, write_x3p
from .conftest import cli

st = pytest.importorskip("SurfaceTopography")

ROOT = Path(__file__).resolve().parents[2]
SUR_SIZE_MM = (1.9614921, 1.6862561)  # sur-2.sur as SurfaceTopography reads it (tests/data/instrument/README.md)


def _scene(folder, gap, units="SI (m, Pa, N)", E_star=115.4e9, mean_pressure=2e6):
    """A periodic scene of ``gap`` written to ``folder/scene.toml``, its file under ``folder/data`` (copied from
    the instrument files unless it is there)."""
    (folder / "data").mkdir(exist_ok=True)
    if not (folder / gap["file"]).is_file():
        instrument_file(gap["file"].split("/")[-1], folder / "data")
    raw = {"scene": {"name": "measured", "units": units}, "bodies": {"E_star": E_star},
           "gap": {"type": "surface", **gap}, "load": {"mean_pressure": mean_pressure},
           "bem": {"periodic": True, "cell_nodes": 16}}
    path = folder / "scene.toml"
    path.write_text(tomli_w.dumps(raw))
    return path


def test_the_unit_a_file_states_is_converted_to_the_scenes(tmp_path):
    gap = {"file": "data/sur-2.sur", "fill": "harmonic"}  # the file states mm
    si = load_scene(_scene(tmp_path, gap)).gap.surface
    assert si.size == pytest.approx((SUR_SIZE_MM[0] * 1e-3, SUR_SIZE_MM[1] * 1e-3), rel=1e-7)
    mm = load_scene(_scene(tmp_path, gap, units="mm, MPa, N", E_star=115.4e3, mean_pressure=2.0)).gap.surface
    assert mm.size == pytest.approx(SUR_SIZE_MM, rel=1e-7)
    assert mm.stats.rms_height == pytest.approx(si.stats.rms_height * 1e3, rel=1e-9)
    assert (si.stats.length_unit, mm.stats.length_unit) == ("m", "mm")
    with pytest.raises(SceneError, match=r"gap.length_unit = 'um' is not allowed: .* states its lengths in mm"):
        load_scene(_scene(tmp_path, dict(gap, length_unit="um")))


def test_a_file_without_a_unit_takes_length_unit_or_the_scenes(tmp_path):
    reader = st.open_topography(str(instrument_file("ibw-10x10.ibw", tmp_path)))
    stated = tuple(reader.default_channel.physical_sizes)  # in no unit
    given = load_scene(_scene(tmp_path, {"file": "data/ibw-10x10.ibw", "length_unit": "um"})).gap.surface
    assert given.size == pytest.approx((stated[0] * 1e-6, stated[1] * 1e-6), rel=1e-12)
    assert given.stats.unit == "um"
    default = load_scene(_scene(tmp_path, {"file": "data/ibw-10x10.ibw"})).gap.surface
    assert default.size == pytest.approx(stated, rel=1e-12) and default.stats.unit is None


def test_missing_points_are_refused_without_fill_naming_the_file_as_the_scene_does(tmp_path):
    with pytest.raises(SceneError) as err:
        load_scene(_scene(tmp_path, {"file": "data/sur-2.sur"}))
    message = str(err.value)
    assert message.startswith("gap.file = 'data/sur-2.sur' is not allowed: it has 117 points without data")
    assert "gap.fill = 'harmonic'" in message and str(tmp_path) not in message


def test_a_run_records_the_points_filled_and_the_file_relative_to_the_scene(tmp_path, monkeypatch):
    _scene(tmp_path, {"file": "data/sur-2.sur", "fill": "harmonic"})
    monkeypatch.chdir(tmp_path.parent)  # the scene is named from elsewhere
    code, out, err = cli("run", f"{tmp_path.name}/scene.toml", "--out", f"{tmp_path.name}/result")
    assert code == 0, err
    text = (tmp_path / "result" / "result.json").read_text()
    surface = json.loads(text)["periodic"]["surface"]
    assert (surface["source"], surface["unit"], surface["filled"], surface["fill"]) == (
        "data/sur-2.sur", "mm", 117, "harmonic")
    assert surface["size"] == pytest.approx([SUR_SIZE_MM[0] * 1e-3, SUR_SIZE_MM[1] * 1e-3], rel=1e-7)
    assert str(tmp_path) not in text and str(tmp_path) not in err  # warnings name data/sur-2.sur too
    assert "data/sur-2.sur" in err  # the spike warning of this patch (the seam is a note of the run)


def test_check_refuses_an_x3p_that_would_inflate_beyond_its_header(tmp_path, monkeypatch):
    (tmp_path / "data").mkdir()
    write_x3p(tmp_path / "data" / "bomb.x3p")
    rewrite_x3p(tmp_path / "data" / "bomb.x3p", data=bytes(20 * 2**20))  # declared 16 x 12 float64 values
    monkeypatch.setattr(st, "open_topography", lambda *a, **k: pytest.fail("the file was handed to a reader"))
    code, _, err = cli("check", _scene(tmp_path, {"file": "data/bomb.x3p"}))
    assert code == 2 and err.count("\n") == 1
    assert err.startswith("contactlab: error: gap.file = 'data/bomb.x3p' is not allowed: its data does not match its "
                          "header: main.xml declares 16 x 12 values of type D (1536 bytes), the data member holds "
                          "20971520 bytes")


def test_a_missing_file_is_named_as_the_scene_does_before_surfacetopography_is_imported(tmp_path):
    path = _scene(tmp_path, {"file": "data/ibw-10x10.ibw"})
    (tmp_path / "data" / "ibw-10x10.ibw").unlink()
    code = ("import sys; from validation.cli import main; rc = main(['check', 'scene.toml']); "
            "print(rc, 'SurfaceTopography' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], cwd=path.parent, env={"PYTHONPATH": str(ROOT)},
                          capture_output=True, text=True, timeout=120)
    assert done.stdout.split() == ["2", "False"], done.stderr
    assert done.stderr.startswith("contactlab: error: gap.file = 'data/ibw-10x10.ibw' is not allowed: there is no "
                                  "such file")
