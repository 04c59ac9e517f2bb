"""``contactlab surface FILE``: what a real instrument file holds, in SI units, with its height map and PSD;
bad input stops with exit code 2 and a message naming the option; a missing file is named before
SurfaceTopography is imported."""

import json
import subprocess
import sys
from argparse import Namespace
from pathlib import Path

import numpy as np
import pytest

from bem import rough
from validation.cli.surface import CLIP, draw

from ..instrument_data import instrument_file
from .conftest import cli

st = pytest.importorskip("SurfaceTopography")
pytest.importorskip("matplotlib")

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def sur(tmp_path_factory):
    """sur-2.sur (mm, 117 missing points) run through the command: (folder, exit code, stdout, stderr, file)."""
    folder = tmp_path_factory.mktemp("surface")
    path = instrument_file("sur-2.sur", folder)
    code, out, err = cli("surface", path, "--fill", "harmonic", "--out", folder / "out")
    return folder / "out", code, out, err, path


def test_the_numbers_are_in_si_from_the_files_millimetres(sur):
    out, code, stdout, _, path = sur
    assert code == 0
    info = json.loads((out / "surface.json").read_text())
    topo = st.open_topography(str(path)).topography().interpolate_undefined_data().detrend("height")
    z = np.asarray(topo.heights()) * 1e-3  # mm -> m, independently of the command
    stats = info["stats"]
    assert stats["rms_height"] == pytest.approx(np.std(z), rel=1e-9)
    assert stats["rms_slope"] == pytest.approx(topo.rms_gradient(), rel=1e-9)  # slopes have no unit
    assert stats["rms_curvature"] == pytest.approx(topo.rms_curvature_from_area() / 1e-3, rel=1e-9)  # 1/m
    assert info["pixel"] == pytest.approx([1.9614921e-3 / 563, 1.6862561e-3 / 484], rel=1e-7)
    assert (stats["filled"], stats["unit"]) == (117, "mm")
    spikes = rough.find_spikes(z)
    assert info["spikes"]["count"] == spikes.count
    assert f"rms height     {np.std(z):.4g} m" in stdout and "117 points filled" in stdout


def test_the_figures_show_the_height_map_and_the_psd(sur, tmp_path):
    out, *_ = sur
    assert {p.name for p in out.iterdir()} >= {"surface.json", "heights.png", "psd.png"}
    surface = rough.from_heights(np.outer(np.linspace(-1, 1, 32), np.ones(24)) * 2e-8
                                 + np.random.default_rng(0).normal(size=(32, 24)) * 1e-9, (4e-5, 3e-5))
    figures = draw(surface, tmp_path)
    heights = figures["heights.png"].axes[0]
    image = heights.get_images()[0]
    assert np.allclose(image.get_array(), np.asarray(surface.heights).T / 1e-9)  # drawn in nm
    assert image.get_clim() == pytest.approx(tuple(np.percentile(surface.heights, CLIP) / 1e-9))
    assert image.get_extent() == pytest.approx([0, 40, 0, 30])  # µm
    assert heights.get_xlabel() == "x [µm]" and "height [nm]" in figures["heights.png"].axes[1].get_ylabel()
    psd = figures["psd.png"].axes[0]
    q, c = surface.power_spectrum()
    line = psd.get_lines()[0]
    assert np.array_equal(line.get_xdata(), q) and np.array_equal(line.get_ydata(), c)
    assert psd.get_xscale() == psd.get_yscale() == "log" and "[m$^4$]" in psd.get_ylabel()


def test_missing_points_without_fill_name_the_option(sur):
    *_, path = sur
    code, _, err = cli("surface", path)
    assert code == 2 and err.count("\n") == 1
    assert err.startswith(f"contactlab: error: FILE = {str(path)!r} is not allowed: it has 117 points without data")
    assert "--fill = 'harmonic'" in err


def test_a_file_without_unit_or_size_names_the_options(tmp_path):
    np.save(tmp_path / "z.npy", np.zeros((16, 16)))
    code, _, err = cli("surface", tmp_path / "z.npy", "--scale", "1e-6")
    assert code == 2 and err.startswith("contactlab: error: --size is missing: FILE = ") and "give --size LX,LY" in err
    code, _, err = cli("surface", tmp_path / "z.npy", "--size", "10,10")
    assert code == 2 and err.startswith("contactlab: error: --scale is missing: FILE = ") and "give --scale M" in err
    code, out, _ = cli("surface", tmp_path / "z.npy", "--size", "10,10", "--scale", "1e-6")
    assert code == 0 and "size 1e-05 x 1e-05 m" in out
    code, _, err = cli("layer-law", tmp_path / "z.npy", "--scale", "1e-6", "--E-star", "1e9", "--out", tmp_path / "x")
    assert code == 2 and err.startswith("contactlab: error: --size is missing")  # the README's line needs --size


def test_a_missing_file_is_named_without_importing_surfacetopography(tmp_path):
    code = ("import sys; from validation.cli import main; rc = main(['surface', 'nothere.x3p']); "
            "print(rc, 'SurfaceTopography' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env={"PYTHONPATH": str(ROOT)},
                          capture_output=True, text=True, timeout=120)
    assert done.stdout.split() == ["2", "False"], done.stderr
    assert done.stderr.strip() == "contactlab: error: FILE = 'nothere.x3p' is not allowed: there is no such file."


def test_the_default_lattice_of_long_pixels_does_not_oversample(tmp_path):
    z = np.random.default_rng(2).normal(size=(40, 40)) * 1e-7
    st.Topography(z, (1e-5, 2.5e-5)).to_x3p(str(tmp_path / "long.x3p"))  # dy = 2.5 dx
    code, out, _ = cli("surface", tmp_path / "long.x3p", "--detrend", "none", "--spike-threshold", "4")
    assert code == 0
    lattice = next(line for line in out.splitlines() if line.startswith("lattice"))
    assert lattice.startswith("lattice        16 x 46 nodes")  # not 40 x 116
    code, _, err = cli("surface", tmp_path / "long.x3p", "--spike-threshold", "0")
    assert code == 2 and err.startswith("contactlab: error: --spike-threshold = 0.0 is not allowed")


def test_the_shared_reader_of_file_options_returns_metres(tmp_path):
    """The shared reading of FILE (layer-law uses it too): a real nm file comes back in metres."""
    from validation.cli.surface import read

    path = instrument_file("top-1.top", tmp_path)
    args = Namespace(file=str(path), size=None, scale=None, fill=None, detrend="none", channel=0)
    assert read(args).size == pytest.approx((6e-7, 6e-7), rel=1e-12)


def test_layer_law_takes_a_files_nanometres_as_metres_once(tmp_path):
    """The law of a real .top file in nm records its cell in metres (a second conversion would make it 1e-18 m)."""
    import tomllib

    path = instrument_file("top-1.top", tmp_path)
    code, _, err = cli("layer-law", path, "--E-star", "1e11", "--n-cols", "16", "--n-pressures", "3", "--no-figures",
                       "--out", tmp_path / "law")
    assert code == 0, err
    law = tomllib.loads((tmp_path / "law" / "layer_law.toml").read_text())
    surface = law["topography"]["surface"]
    assert surface["unit"] == "nm" and surface["size"] == pytest.approx([6e-7, 6e-7], rel=1e-12)
