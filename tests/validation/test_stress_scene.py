"""The [stress] section of a scene: validation, result.json, the volume file and the report section."""

import math

from pathlib import Path

import numpy as np
import pytest

import bem
from validation.run import execute_scene, planned_stages, run_scene, write_outputs
from validation.scene import SceneError, load_scene

from .conftest import cli

BASE = """
[scene]
name = "t"

[bodies]
E1 = 210e9
nu1 = 0.3
E2 = 70e9
nu2 = 0.2

[gap]
type = "paraboloid"
R = 0.01

[load]
force = 100.0

[bem]
nodes_across = 16
"""

CASES = {
    "unknown_key": ("[stress]\ndepth = [0.0]\n", "stress.depth"),
    "depths_text": ('[stress]\ndepths = "deep"\n', "stress.depths"),
    "depths_empty": ("[stress]\ndepths = []\n", "stress.depths"),
    "depth_negative": ("[stress]\ndepths = [0.0, -1e-5]\n", "stress.depths[1]"),
    "depth_text": ('[stress]\ndepths = [0.0, "a"]\n', "stress.depths[1]"),
    "depths_repeated": ("[stress]\ndepths = [1e-5, 1e-5]\n", "stress.depths"),
    "n_depths_with_list": ("[stress]\ndepths = [1e-5]\nn_depths = 4\n", "stress.n_depths"),
    "n_depths_one": ("[stress]\nn_depths = 1\n", "stress.n_depths"),
    "n_depths_float": ("[stress]\nn_depths = 2.5\n", "stress.n_depths"),
    "max_depth_zero": ("[stress]\nmax_depth = 0.0\n", "stress.max_depth"),
    "max_depth_huge": ("[stress]\nmax_depth = 100.0\n", "stress.max_depth"),
    "bodies_unknown": ('[stress]\nbodies = ["body3"]\n', "stress.bodies[0]"),
    "bodies_repeated": ('[stress]\nbodies = ["body1", "body1"]\n', "stress.bodies"),
    "bodies_empty": ("[stress]\nbodies = []\n", "stress.bodies"),
    "not_a_table": ("stress = 3\n", "stress"),
    "E_star_alone": ("[stress]\n", "bodies.E_star"),
}


def _scene_text(case):
    text, _ = CASES[case]
    base = BASE
    if case == "E_star_alone":
        base = BASE.replace("E1 = 210e9\nnu1 = 0.3\nE2 = 70e9\nnu2 = 0.2", "E_star = 1e11")
    if case == "not_a_table":
        return base.replace("[scene]", text + "\n[scene]")
    return base + text


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_stress_section_is_refused_naming_the_key(tmp_path, case, monkeypatch):
    path = tmp_path / "s.toml"
    path.write_text(_scene_text(case))
    monkeypatch.setattr(bem, "solve", lambda *a, **k: pytest.fail("solved before validation"))
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert CASES[case][1] in str(info.value)
    code, out, err = cli("check", path)
    assert code == 2 and CASES[case][1] in err


def test_no_section_no_stresses(tmp_path):
    import tomllib

    scene = load_scene(tomllib.loads(BASE))
    assert scene.stress is None and "stress" not in planned_stages(scene)
    result = run_scene(scene, tmp_path / "r")
    assert result.stress is None and not (tmp_path / "r" / "stress_field.vtu").exists()


@pytest.fixture(scope="module")
def stress_run(tmp_path_factory):
    import tomllib

    raw = tomllib.loads(BASE + "\n[stress]\ndepths = [0.0, 2e-5, 5e-5, 8e-5, 1.2e-4, 2e-4]\n")
    outcome = execute_scene(raw)
    out = tmp_path_factory.mktemp("stress") / "run"
    write_outputs(outcome, out)
    return outcome, out


def test_result_json_holds_the_maxima_per_body(stress_run):
    outcome, out = stress_run
    block = outcome.result.stress
    assert set(block.bodies) == {"body1", "body2"}
    assert block.depths == [0.0, 2e-5, 5e-5, 8e-5, 1.2e-4, 2e-4]
    for name, nu in (("body1", 0.3), ("body2", 0.2)):
        body = block.bodies[name]
        direct = bem.subsurface_stress(outcome.bem, block.depths, nu=nu)
        assert body.nu == nu
        assert body.max_von_mises == pytest.approx(direct.max_von_mises, rel=1e-12)
        assert body.max_tresca == pytest.approx(direct.max_tresca, rel=1e-12)
        assert body.depth_of_max == pytest.approx(direct.depth_of_max, rel=1e-12)
        assert body.location_of_max == pytest.approx(list(direct.location_of_max), rel=1e-12, abs=1e-15)
        assert len(body.axis["von_mises"]) == 6 and len(body.section["x"]) > 10
    assert outcome.result.wall_time_s_by_part["stress"] > 0
    assert (out / "result.json").is_file() and outcome.result.files["stress_field"] == "stress_field.vtu"


def test_stress_field_file_is_documented(stress_run):
    """docs/results.md lists the file and describes each of its fields, and its body numbering."""
    import re

    import meshio

    _outcome, out = stress_run
    mesh = meshio.read(out / "stress_field.vtu")
    text = (Path(__file__).parents[2] / "docs" / "results.md").read_text(encoding="utf-8")
    assert re.search(r"^\| `stress_field.vtu` \|", text, re.M)
    paragraph = text[text.index("`stress_field.vtu` holds"):].split("\n\n")[0]
    for name in [*mesh.point_data, *mesh.cell_data]:
        assert f"`{name}`" in paragraph, name
    assert "`body` numbered as in `fem_field.vtu` (0 upper,\n1 lower)" in paragraph


def test_stress_field_file_reads_back_with_meshio(stress_run):
    import meshio

    from bem.files import volume_grid

    outcome, out = stress_run
    mesh = meshio.read(out / "stress_field.vtu")
    run, res = outcome.stress, outcome.bem
    rows, cols, nodes = volume_grid(res.lattice, run.depths.size, 2)
    per_body = run.depths.size * nodes.size
    assert mesh.points.shape == (2 * per_body, 3)
    hexa = mesh.cells_dict["hexahedron"]
    body = mesh.cell_data_dict["body"]["hexahedron"]
    p = mesh.points[hexa].astype(float)  # every cell has a positive volume (first face lowest)
    centre = p[..., 2].mean(axis=1)  # numbered as in fem_field.vtu: 0 upper (z > 0), 1 lower (z < 0)
    assert set(np.unique(body)) == {0, 1} and np.all(centre[body == 0] > 0) and np.all(centre[body == 1] < 0)
    volume = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 3] - p[:, 0]), p[:, 4] - p[:, 0])
    assert np.all(volume > 0)
    flat = nodes.ravel()
    st1, st2 = run.bodies["body1"], run.bodies["body2"]
    vtk = [0, 1, 2, 5, 3, 4]  # xx, yy, zz, xy, yz, xz
    upper = mesh.point_data["stress"][:per_body].reshape(run.depths.size, flat.size, 6)
    assert np.allclose(upper, st1.sigma[:, flat][..., vtk], rtol=1e-6, atol=1e-6 * st1.max_von_mises)
    assert np.allclose(mesh.points[:per_body, 2].reshape(run.depths.size, -1)[:, 0], run.depths, atol=1e-12)
    # body 2 lies below (z = -depth, deepest first), its xz and yz shears flip sign
    lower = mesh.point_data["stress"][per_body:].reshape(run.depths.size, flat.size, 6)[::-1]
    expect = st2.sigma[:, flat][..., vtk] * np.array([1, 1, 1, 1, -1, -1])
    assert np.allclose(lower, expect, rtol=1e-6, atol=1e-6 * st2.max_von_mises)
    vm = mesh.point_data["von_mises"][:per_body].reshape(run.depths.size, -1)
    assert np.allclose(vm, st1.von_mises[:, flat], rtol=1e-6)


def test_report_has_the_stress_section(stress_run, tmp_path):
    from validation.report import report_results_dir

    _, out = stress_run
    built = report_results_dir(out, tmp_path / "report")
    md = (tmp_path / "report" / "report.md").read_text()
    assert "## Subsurface stresses" in md and "stress_section.png" in md and "stress_profiles.png" in md
    assert (tmp_path / "report" / "figures" / "stress_section.png").is_file()
    assert built is not None


def test_builtin_hertz_scene_reports_the_hertz_maximum(builtin_runs):
    """The built-in hertz scene has [stress]: 0.62 p_H at 0.48 a_H (Johnson), BEM within 1 % and FEM within 2 %."""
    r = builtin_runs["hertz"]["result"]
    p0, a = r.analytic.p_max, r.analytic.contact_radius
    for body in r.stress.bodies.values():
        assert body.max_von_mises / p0 == pytest.approx(0.620, rel=0.01)
        assert body.max_tresca / p0 == pytest.approx(0.310, rel=0.01)
        assert body.depth_of_max / a == pytest.approx(0.481, abs=0.02)
        fem = body.fem
        assert abs(fem.max_von_mises_rel) <= 0.02 and abs(fem.axis_depth_of_max_rel) <= 0.02 and fem.on_axis
    assert (builtin_runs["hertz"]["dir"] / "stress_field.vtu").is_file()
    assert math.isfinite(r.wall_time_s_by_part["stress"])
