"""Scenes with [study]: the built-in rough_sphere_two_scale run, checked and reported from the CLI."""

import json

import numpy as np
import pytest

from .conftest import cli

pytest.importorskip("SurfaceTopography")
pytest.importorskip("matplotlib")

HEAD = '[scene]\nname = "mine"\n'


@pytest.fixture(scope="module")
def two_scale_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("study_scene") / "result"
    code, stdout, err = cli("run", "rough_sphere_two_scale", "--out", out)
    assert code == 0, err
    return out, stdout


def test_run_writes_the_study_files_and_a_result_marker(two_scale_run):
    from validation.io import marker_kind

    out, _ = two_scale_run
    assert sorted(p.name for p in out.iterdir()) == sorted(
        [".contactlab", "scene.toml", "two_scale.json", "two_scale.md", "two_scale_map.png", "two_scale_profile.png"])
    assert marker_kind(out) == "result"
    data = json.loads((out / "two_scale.json").read_text())
    assert data["mode"] == "quick"
    assert all(r["resolved_converged"] and r["layer_converged"] and r["gt_converged"] for r in data["rows"])
    assert "windowed L2, layer" in (out / "two_scale.md").read_text()
    code, _, err = cli("run", "rough_sphere_two_scale", "--out", out)  # its own result folder is replaced
    assert code == 0, err


def test_run_prints_the_key_errors_of_every_case(two_scale_run):
    out, stdout = two_scale_run
    rows = json.loads((out / "two_scale.json").read_text())["rows"]
    errors = [line for line in stdout.splitlines() if line.startswith("error")]
    assert len(errors) == 2 * len(rows)  # the layer model and Greenwood-Tripp per case
    for r in rows:
        line = next(e for e in errors if f"a_H/lambda_L = {r['ratio']:g}, P = {r['load_factor']:g} P1, layer" in e)
        assert f"approach {100 * r['layer_approach_err']:+.2f}%" in line
        assert f"L2 {100 * r['layer_l2_err']:.2f}%" in line
    assert "two_scale.json" in stdout.splitlines()[-1]


def test_figure_data_in_the_json_matches_the_case_it_draws(two_scale_run):
    out, _ = two_scale_run
    data = json.loads((out / "two_scale.json").read_text())
    fig, row = data["figure"], data["rows"][0]
    assert fig["radius"] == pytest.approx(row["radius"], rel=1e-12)
    assert fig["layer_radius"] == pytest.approx(row["radius"] * (1 + row["layer_radius_err"]), rel=1e-9)
    assert fig["extent"] == pytest.approx(data["settings"]["extent_factor"] * row["a_hertz"], rel=1e-12)
    image = np.array([[np.nan if v is None else v for v in r] for r in fig["map"]], dtype=float)
    assert 8 <= image.shape[0] == image.shape[1] <= 96
    centres = np.linspace(-fig["extent"], fig["extent"], image.shape[0] + 1)
    centres = 0.5 * (centres[1:] + centres[:-1])
    r = np.hypot(*np.meshgrid(centres, centres))
    pixel = 2 * fig["extent"] / image.shape[0]
    assert np.nanmax(image[r > fig["radius"] + 2 * pixel], initial=0) < 0.05 * np.nanmax(image)  # inside the circle
    x, p = (np.array(a, dtype=float) for a in fig["profile"]["resolved"])
    assert 0 < p.max() <= row["p_window_max"] * (1 + 1e-3)  # a row of the windows the table measured
    assert np.allclose(np.diff(x), data["settings"]["roll_off"], rtol=1e-3)  # windows of lambda_L
    assert set(fig["profile"]) == {"resolved", "resolved_wide", "layer", "layer_windows", "gt"}


def test_report_of_the_result_folder_draws_the_two_figures(two_scale_run, tmp_path):
    from PIL import Image

    out, _ = two_scale_run
    code, _, err = cli("report", out, "--out", tmp_path / "rep")
    assert code == 0, err
    md = (tmp_path / "rep" / "report.md").read_text()
    assert "Two-scale check" in md
    assert "nominal contact circles" in md and "averaged over windows of lambda_L" in md
    for name in ("two_scale_map.png", "two_scale_profile.png"):
        assert f"figures/{name}" in md
        with Image.open(tmp_path / "rep" / "figures" / name) as img:
            arr = np.asarray(img.convert("L"), dtype=float)
        assert arr.shape[0] > 200 and arr.std() > 5  # drawn, not blank


def test_scenes_lists_and_check_validates_the_study_scene():
    code, stdout, _ = cli("scenes")
    assert code == 0 and "rough_sphere_two_scale" in stdout
    code, stdout, _ = cli("check", "rough_sphere_two_scale")
    assert code == 0
    assert stdout.strip() == "rough_sphere_two_scale: OK (study two-scale, quick = true)"


@pytest.mark.parametrize("body, key, hint", [
    ('[study]\nname = "two-scal"\n', "study.name = 'two-scal'", "Did you mean 'two-scale'?"),
    ('[study]\nname = "two-scale"\nquik = true\n', "study.quik = True", "Did you mean 'quick'?"),
    ('[study]\nname = "two-scale"\nquick = 1\n', "study.quick = 1", "true or false"),
    ('[study]\nname = "two-scale"\n[bem]\nnodes_across = 30\n', "bem.nodes_across = 30", "ignores [bem]"),
    ('[study]\nname = "two-scale"\n[fem]\nn_contact_elements = 8\n', "fem.n_contact_elements = 8", "ignores [fem]"),
    ('[study]\nquick = true\n', "study", "name"),
])
def test_bad_study_section_is_refused_naming_the_key(tmp_path, body, key, hint):
    path = tmp_path / "mine.toml"
    path.write_text(HEAD + body)
    for cmd in ("check", "run"):
        code, _, err = cli(cmd, path, *(["--out", tmp_path / "out"] if cmd == "run" else []))
        assert code == 2
        assert key in err and hint in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_study_scene_refuses_an_override_of_an_unknown_option(tmp_path):
    code, _, err = cli("check", "rough_sphere_two_scale", "--set", "study.quikc=false")
    assert code == 2 and "study.quikc" in err and "Did you mean 'quick'?" in err


@pytest.mark.parametrize("argv, what", [
    (("report", "rough_sphere_two_scale"), "a report of a scene"),
    (("sweep", "rough_sphere_two_scale", "--param", "study.quick", "--values", "false"), "a sweep"),
])
def test_commands_of_one_contact_problem_refuse_a_study_scene(tmp_path, argv, what):
    code, _, err = cli(*argv, "--out", tmp_path / "out")
    assert code == 2 and what in err and "contactlab run rough_sphere_two_scale" in err
    assert not (tmp_path / "out").exists()


def test_runner_refuses_a_study_scene():
    from validation.run import execute_scene
    from validation.scene import SceneError

    with pytest.raises(SceneError, match="runs the built-in study 'two-scale'"):
        execute_scene("rough_sphere_two_scale")
