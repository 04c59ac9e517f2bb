"""``contactlab layer-law``: a surface file becomes a layer-law folder (the law file a scene loads and
three figures showing the ladder's data with units); bad input stops with exit code 2."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
import tomli_w

from validation.io import MARKER
from validation.layer_law import ladder, make_layer_law, synthetic_surface
from validation.run import execute_scene
from validation.scene import load_scene

from .conftest import cli

from ..instrument_data import unpacked

pytest.importorskip("SurfaceTopography")
pytest.importorskip("matplotlib")

E_STAR = 115e9  # Pa
SIZE_UM = 100.0  # the file's cell size [um]
SYNTHETIC = "hurst=0.8,rms_height=0.5e-6,size=1e-4,grid=64,long_cutoff=25e-6,short_cutoff=12.5e-6,seed=3"


@pytest.fixture(scope="module")
def surface_file(tmp_path_factory):
    """A periodic self-affine cell saved as heights in um (a .npy states no unit)."""
    surface = synthetic_surface(hurst=0.8, size=1e-4, grid=64, rms_height=0.5e-6, long_cutoff=25e-6,
                                short_cutoff=12.5e-6, seed=3).surface
    path = tmp_path_factory.mktemp("surface") / "heights.npy"
    np.save(path, np.asarray(surface.heights) * 1e6)
    return path


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """The library call behind the command, on a small synthetic cell."""
    surface = synthetic_surface(**{k: (int(v) if k in ("grid", "seed") else float(v))
                                   for k, v in (item.split("=") for item in SYNTHETIC.split(","))})
    pressures = ladder(surface, E_STAR, n=8)
    calls = []
    out = make_layer_law(surface, tmp_path_factory.mktemp("law") / "law", E_star=E_STAR, pressures=pressures,
                         progress=lambda *a: calls.append(a))
    return out, calls


def _run(tmp_path, *extra, out="law"):
    return cli("layer-law", *extra, "--E-star", E_STAR, "--n-pressures", 8, "--out", tmp_path / out)


def test_a_surface_file_becomes_a_law_folder_a_scene_loads(surface_file, tmp_path):
    code, out, err = _run(tmp_path, surface_file, "--size", f"{SIZE_UM},{SIZE_UM}", "--scale", 1e-6)
    assert code == 0, err
    folder = tmp_path / "law"
    assert json.loads((folder / MARKER).read_text())["kind"] == "layer-law"
    assert sorted(p.name for p in folder.iterdir()) == sorted([MARKER, "layer_law.toml", "closure.png",
                                                               "contact_fraction.png", "stiffness.png", "persson.png"])
    import tomllib

    start = tomllib.loads((folder / "layer_law.toml").read_text())["topography"]["ladder_start"]
    assert f"{8 + start['added']} mean pressures" in out and "layer_law.toml" in out
    assert start["interpolated_share"] <= start["max_interpolated"] == 0.01  # the default rule
    scene = {"scene": {"name": "rough"}, "bodies": {"E_star": E_STAR}, "gap": {"type": "paraboloid", "R": 0.01},
             "layer": {"law": "tabulated", "file": "layer_law.toml"}, "load": {"force": 50.0},
             "bem": {"nodes_across": 16}}
    (folder.parent / "law" / "scene.toml").write_text(tomli_w.dumps(scene))  # a scene beside the law file
    run = execute_scene(load_scene(folder / "scene.toml"))
    assert run.bem.converged and run.bem.closure.max() > 0
    code, _, err = _run(tmp_path, surface_file, "--size", f"{SIZE_UM},{SIZE_UM}", "--scale", 1e-6)
    assert code == 2 and "scene.toml" in err  # the folder holds a file contactlab did not write: refused


def test_the_heights_in_um_are_converted_to_metres(surface_file, tmp_path, folder):
    code, _, err = _run(tmp_path, surface_file, "--size", f"{SIZE_UM},{SIZE_UM}", "--scale", 1e-6, "--no-figures")
    assert code == 0, err
    import tomllib

    data = tomllib.loads((tmp_path / "law" / "layer_law.toml").read_text())
    assert data["topography"]["surface"]["rms_height"] == pytest.approx(0.5e-6, rel=0.05)
    assert data["topography"]["step"] == pytest.approx(1e-4 / 64, rel=1e-12)
    assert not (tmp_path / "law" / "closure.png").exists()


def test_a_layer_law_folder_is_replaced_by_a_new_run(tmp_path):
    for _ in range(2):
        code, _, err = _run(tmp_path, "--synthetic", SYNTHETIC, "--no-figures")
        assert code == 0, err


@pytest.mark.parametrize("args, match", [
    ((), "SURFACE is missing"),
    (("x.npy", "--synthetic", SYNTHETIC), "not allowed together with --synthetic"),
    (("--synthetic", "hurst=0.8,size=1e-4"), "--synthetic grid is missing"),
    (("--synthetic", "hurst=0.8,size=1e-4,grid=64,colour=3"), "--synthetic 'colour=3' is not allowed"),
    (("--synthetic", "hurst=0.8,size=1e-4,grid=6.5"), "--synthetic grid = '6.5' is not allowed"),
    (("--synthetic", SYNTHETIC, "--p-range", "1e9:1e8"), "--p-range = (1000000000.0, 100000000.0) is not allowed"),
    (("--synthetic", SYNTHETIC, "--p-range", "0:1e8"), "--p-range LOW = 0.0 is not allowed: it must be > 0"),
    (("--synthetic", SYNTHETIC, "--p-range-rel", "0.1:-1"), "--p-range-rel HIGH = -1.0 is not allowed"),
    (("--synthetic", SYNTHETIC.replace("seed=3", "seed=-1")), "--synthetic seed = -1 is not allowed"),
    (("--synthetic", SYNTHETIC.replace("hurst=0.8", "hurst=2")), "--synthetic hurst = 2.0 is not allowed"),
    (("--synthetic", SYNTHETIC.replace("size=1e-4", "size=-1")), "--synthetic size = -1.0 is not allowed"),
    (("--synthetic", SYNTHETIC, "--rtol", "10"), "--rtol = 10.0 is not allowed: it must be in (0, 0.01]"),
    (("--synthetic", SYNTHETIC, "--rtol", "1"), "--rtol = 1.0 is not allowed: it must be in (0, 0.01]"),
    (("--synthetic", SYNTHETIC, "--p-range", "1e9"), "--p-range = '1e9' is not allowed"),
    (("--synthetic", SYNTHETIC, "--scale", "1e-6"), "--scale = 1e-06 is not allowed with --synthetic"),
    (("--synthetic", SYNTHETIC, "--n-cols", "0"), "--n-cols = 0 is not allowed"),
    (("--synthetic", SYNTHETIC, "--rtol", "-1"), "--rtol = -1.0 is not allowed"),
    (("no_such_file.x3p",), "no_such_file.x3p"),
])
def test_bad_input_exits_2_with_one_line(tmp_path, args, match):
    code, _, err = _run(tmp_path, *args)
    assert code == 2, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert match in err
    assert not (tmp_path / "law").exists()


def test_a_file_without_a_length_unit_needs_scale(surface_file, tmp_path):
    code, _, err = _run(tmp_path, surface_file, "--size", f"{SIZE_UM},{SIZE_UM}")
    assert code == 2 and err.startswith(f"contactlab: error: --scale is missing: SURFACE = '{surface_file}' states "
                                        "no length unit; give --scale M, metres per length unit of the file")
    code, _, err = _run(tmp_path, surface_file, "--scale", "1e-6")
    assert code == 2 and err.startswith(f"contactlab: error: --size is missing: SURFACE = '{surface_file}' does not "
                                        "state its size; give --size LX,LY in the file's length unit"), err
    assert "file =" not in err and "physical_sizes" not in err


def test_the_readme_line_runs_as_written(surface_file, tmp_path, monkeypatch):
    readme = (Path(__file__).resolve().parents[2] / "README.md").read_text()
    line = next(x for x in readme.splitlines() if x.startswith("contactlab layer-law surface.npy"))
    argv = line.split("#")[0].split()[1:]
    monkeypatch.chdir(tmp_path)
    np.save(tmp_path / "surface.npy", np.load(surface_file)[:16, :16])  # a small surface.npy, heights in um
    code, out, err = cli(*argv)
    assert code == 0, err
    law = (tmp_path / argv[argv.index("--out") + 1] / "layer_law.toml")
    assert law.is_file() and "lattice nodes" in out


@pytest.mark.parametrize("args, match", [
    ((), "--size is missing: "),
    (("--size", "100,-1", "--scale", "1e-6"), "--size LY = -1.0 is not allowed: it must be > 0"),
    (("--size", "100,100", "--scale", "-1"), "--scale = -1.0 is not allowed: it must be > 0"),
])
def test_the_options_of_a_surface_file_are_named_as_written(surface_file, tmp_path, args, match):
    code, _, err = _run(tmp_path, surface_file, *args)
    assert code == 2 and err.startswith("contactlab: error: " + match), err


@pytest.mark.parametrize("kwargs, match", [
    ({"n": 1}, "n = 1 is not allowed: it must be >= 2"),
    ({"pressures": (1e9, 1e8)}, "pressures = (1000000000.0, 100000000.0) is not allowed: it must be increasing"),
    ({"relative": (0.0, 0.1)}, r"relative[0] = 0.0 is not allowed: it must be > 0"),
])
def test_the_ladder_names_its_keywords(kwargs, match):
    from bem.checks import InputError

    surface = synthetic_surface(hurst=0.8, size=1e-4, grid=16, rms_height=1e-6, seed=1)
    with pytest.raises(InputError) as err:
        ladder(surface, E_STAR, **kwargs)
    assert str(err.value).startswith(match)


def test_a_relative_ladder_of_a_flat_surface_names_the_option(tmp_path):
    np.save(tmp_path / "flat.npy", np.zeros((32, 32)))
    code, _, err = _run(tmp_path, tmp_path / "flat.npy", "--size", "1,1", "--scale", "1e-6")
    assert code == 2 and err.startswith("contactlab: error: --p-range-rel = (0.003, 0.3) is not allowed: it must be "
                                        "used with a surface of rms slope > 0"), err


def test_a_surface_whose_header_states_an_impossible_size_exits_2(tmp_path):
    """An x3p file with the grid step (its ``Increment``) 1e300 m: the size is no length a solve can take."""
    import SurfaceTopography

    z = np.random.default_rng(0).random((32, 32)) * 1e-6
    SurfaceTopography.Topography(z, (32e300, 32e300), unit="m").to_x3p(str(tmp_path / "s.x3p"))
    code, _, err = _run(tmp_path, tmp_path / "s.x3p")
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert err.startswith(f"contactlab: error: SURFACE = {str(tmp_path / 's.x3p')!r} is not allowed: the size it "
                          "states times scale, (3.2e+301, 3.2e+301), must be two lengths in [1e-60, 1e+60]")
    assert not (tmp_path / "law").exists()


def test_n_pressures_and_the_output_folder_are_checked_before_solving(tmp_path):
    code, _, err = cli("layer-law", "--synthetic", SYNTHETIC, "--E-star", E_STAR, "--n-pressures", 1, "--out",
                       tmp_path / "law")
    assert code == 2 and "--n-pressures = 1 is not allowed: it must be >= 2" in err
    code, _, err = cli("layer-law", "--synthetic", SYNTHETIC, "--E-star", -1, "--out", tmp_path / "law")
    assert code == 2 and "--E-star = -1.0 is not allowed: it must be > 0" in err
    (tmp_path / "file").write_text("")
    code, _, err = _run(tmp_path, "--synthetic", SYNTHETIC, out="file")
    assert code == 2 and "--out = " in err and "it is a file" in err


def test_the_progress_hook_sees_every_step_of_the_ladder(folder):
    out, calls = folder
    """The library's one progress protocol, progress(label, done, total): one call after each step, the total
    growing by the pressures added below the ladder."""
    added = out.law.ladder_start["added"]
    assert added > 0 and out.law.mean_pressure.size == 8 + added
    assert [c[1:] for c in calls] == [(k, 8) for k in range(1, 9)] + [(k, k) for k in range(9, 9 + added)]
    assert all(label.startswith("A/A0 ") and label.endswith(" iterations") for label, _, _ in calls)


def _points(ax):
    """The line of ``ax`` drawn with markers only (the ladder's points): its x and y data."""
    (line,) = [ln for ln in ax.get_lines() if ln.get_marker() == "o" and ln.get_linestyle() == "None"]
    return np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)


def test_the_closure_figure_shows_the_ladder_in_labelled_units_on_linear_and_log_axes(folder):
    out, _ = folder
    law = out.law
    lin, log = out.figures["closure.png"].axes
    assert (lin.get_xscale(), log.get_xscale(), log.get_yscale()) == ("linear", "log", "log")
    for ax in (lin, log):
        assert ax.get_xlabel() == "mean pressure $p$ [GPa]" and ax.get_ylabel() == "closure $w$ [µm]"
        x, y = _points(ax)
        np.testing.assert_allclose(x * 1e9, law.mean_pressure, rtol=1e-12)
        np.testing.assert_allclose(y * 1e-6, law.closure, rtol=1e-12)
    assert lin.get_xlim()[0] == 0 and lin.get_xlim()[1] >= law.mean_pressure[-1] / 1e9
    assert lin.get_ylim()[1] > law.first_touch_gap / 1e-6  # the full closure is in view
    assert (out.path / "closure.png").stat().st_size > 10_000


def test_the_contact_fraction_figure_is_against_the_pressure_over_e_star_times_rms_slope(folder):
    out, _ = folder
    law = out.law
    (ax,) = out.figures["contact_fraction.png"].axes
    assert ax.get_xscale() == ax.get_yscale() == "log"
    assert "E^*" in ax.get_xlabel() and "h'_\\mathrm{rms}" in ax.get_xlabel() and "A/A_0" in ax.get_ylabel()
    (data,) = [ln for ln in ax.get_lines() if ln.get_marker() == "o"]
    x = np.asarray(data.get_xdata(), float)
    np.testing.assert_allclose(x * E_STAR * law.stats.rms_slope, law.mean_pressure, rtol=1e-12)
    np.testing.assert_allclose(data.get_ydata(), law.contact_fraction, rtol=1e-12)
    added = law.ladder_start["added"]  # the default ladder, and the pressures added below it, halving
    assert x[added] == pytest.approx(3e-3, rel=1e-12) and x[-1] == pytest.approx(0.3, rel=1e-12)
    np.testing.assert_allclose(x[1:added + 1] / x[:added], 2.0, rtol=1e-12)


def test_the_stiffness_figure_draws_the_finite_stiffness_in_pa_per_m(folder):
    out, _ = folder
    law = out.law
    (ax,) = out.figures["stiffness.png"].axes
    assert ax.get_xscale() == ax.get_yscale() == "log" and "[Pa/m]" in ax.get_ylabel()
    (data,) = [ln for ln in ax.get_lines() if ln.get_marker() == "o"]
    finite = np.isfinite(law.stiffness)
    assert finite.all() and math.isfinite(float(np.max(data.get_ydata())))
    np.testing.assert_allclose(data.get_ydata(), law.stiffness, rtol=1e-12)
    np.testing.assert_allclose(np.asarray(data.get_xdata(), float) * 1e9, law.mean_pressure, rtol=1e-12)


SPOT = unpacked("spot_1-1000nm.ibw")


@pytest.mark.parametrize("cell, seam_warnings", [("repeat", 1), ("mirror", 0)])
def test_a_measured_file_warns_once_about_spikes_and_seam_and_the_law_file_says_what_was_done(tmp_path, cell,
                                                                                            seam_warnings):
    """SurfaceTopography's AFM scan spot_1-1000nm.ibw: spikes up to 22 rms heights above the mean."""
    import tomllib

    code, out, err = cli("layer-law", SPOT, "--E-star", E_STAR, "--n-pressures", 4, "--n-cols", 32, "--spikes",
                         "remove", "--cell", cell, "--no-figures", "--out", tmp_path / "law")
    assert code == 0, err
    spikes = [line for line in err.splitlines() if "spikes beyond" in line]
    seams = [line for line in err.splitlines() if "edge jump" in line]
    assert len(spikes) == 1 and "1422 of 65536 points" in spikes[0] and " m of the median" in spikes[0]
    assert len(seams) == seam_warnings and all("e-09 against a grid step" in line for line in seams)  # in m
    topo = tomllib.loads((tmp_path / "law" / "layer_law.toml").read_text())["topography"]
    prep = topo["preparation"]
    assert (prep["detrend"], prep["cell"], prep["spikes_removed"], prep["spike_points"]) == ("height", cell, True,
                                                                                            1422)
    assert prep["spikes"]["top"] == pytest.approx(21.8, abs=0.1) and prep["edge_jump_large"] == (cell == "repeat")
    assert topo["surface"]["grid"] == ([512, 512] if cell == "mirror" else [256, 256])
    assert topo["ladder_start"]["interpolated_share"] <= 0.01
    assert "cell       detrend height, " + cell in out


@pytest.mark.parametrize("args, match", [
    (("--synthetic", SYNTHETIC, "--max-interpolated", "2"), "--max-interpolated = '2' is not allowed"),
    (("--synthetic", SYNTHETIC, "--cell", "mirror"), "--cell = 'mirror' is not allowed with --synthetic"),
    (("--synthetic", SYNTHETIC, "--spike-threshold", "-3"), "--spike-threshold = -3.0 is not allowed"),
])
def test_bad_cell_options_exit_2_with_one_line(tmp_path, args, match):
    code, _, err = _run(tmp_path, *args)
    assert code == 2 and len(err.strip().splitlines()) == 1 and match in err


def test_the_persson_figure_draws_the_ladder_beside_the_theory_of_its_spectrum(folder):
    out, _ = folder
    law = out.law
    area, gap = out.figures["persson.png"].axes
    assert (area.get_xscale(), area.get_yscale(), gap.get_xscale(), gap.get_yscale()) == ("log", "log", "log",
                                                                                          "linear")
    assert "A/A_0" in area.get_ylabel() and "h_\\mathrm{rms}" in gap.get_ylabel()
    for ax, ladder, theory in ((area, law.contact_fraction, law.persson["contact_fraction"]),
                               (gap, law.mean_gap / law.stats.rms_height,
                                np.asarray(law.persson["mean_gap"]) / law.stats.rms_height)):
        assert ax.get_xlabel() == "mean pressure $p$ [GPa]"
        (persson,) = [ln for ln in ax.get_lines() if ln.get_linestyle() == "--"]
        assert persson.get_label().startswith("Persson (2001, 2007)")
        np.testing.assert_allclose(np.asarray(persson.get_xdata()) * 1e9, law.persson["mean_pressure"], rtol=1e-12)
        np.testing.assert_allclose(persson.get_ydata(), theory, rtol=1e-12)
        (points,) = [ln for ln in ax.get_lines() if ln.get_marker() == "o"]
        np.testing.assert_allclose(np.asarray(points.get_xdata()) * 1e9, law.mean_pressure, rtol=1e-12)
        np.testing.assert_allclose(points.get_ydata(), ladder, rtol=1e-12)
        (added,) = [ln for ln in ax.get_lines() if ln.get_marker() == "s"]
        assert len(added.get_xdata()) == law.ladder_start["added"]
