"""Result directories: atomic writing, the ParaView file, re-runnable scene, BEM-only imports."""

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import bem

import validation.run.runner as runner
from bem.files import lattice_triangles
from validation.io import OutputError, atomic_directory, atomic_write_json
from validation.run import execute_scene, run_scene
from validation.scene import SceneError, load_scene

ROOT = Path(__file__).resolve().parents[2]
FAST = ["bem.nodes_across=16"]


def _leftovers(parent):
    return sorted(p.name for p in parent.iterdir() if p.name.startswith("."))


@pytest.mark.parametrize("exc", [RuntimeError("disk on fire"), KeyboardInterrupt()])
def test_interrupted_run_leaves_no_result_directory(tmp_path, monkeypatch, exc):
    def failing_write(path, *a, **k):
        Path(path).write_text("half a file")
        raise exc

    monkeypatch.setattr(runner, "write_result_vtu", failing_write)
    out = tmp_path / "res"
    with pytest.raises(type(exc)):
        run_scene("elliptic", out, overrides=FAST)
    assert not out.exists()
    assert _leftovers(tmp_path) == []


def test_failed_rerun_keeps_the_previous_result(tmp_path, monkeypatch):
    out = tmp_path / "res"
    first = run_scene("elliptic", out, overrides=FAST)
    before = {p.name: p.read_bytes() for p in out.iterdir()}

    def failing_write(path, *a, **k):
        raise RuntimeError("interrupted")

    monkeypatch.setattr(runner, "write_result_vtu", failing_write)
    with pytest.raises(RuntimeError):
        run_scene("elliptic", out, overrides=["bem.nodes_across=20"])
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert json.loads((out / "result.json").read_text())["p_max"] == first.p_max
    assert _leftovers(tmp_path) == []


def test_successful_rerun_replaces_the_result(tmp_path):
    out = tmp_path / "res"
    run_scene("elliptic", out, overrides=FAST)
    second = run_scene("elliptic", out, overrides=["bem.nodes_across=20"])
    assert json.loads((out / "result.json").read_text())["bem"]["step"] == second.bem.step
    assert _leftovers(tmp_path) == []


def test_foreign_directory_is_not_replaced(tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("precious")
    with pytest.raises(OutputError, match="did not write .thesis.tex"):
        run_scene("elliptic", out, overrides=FAST)
    assert (out / "thesis.tex").read_text() == "precious"


def test_atomic_json_failure_leaves_nothing(tmp_path):
    with pytest.raises(TypeError):
        atomic_write_json(tmp_path / "x.json", {"a": object()})
    assert list(tmp_path.iterdir()) == []


def test_atomic_directory_context(tmp_path):
    with atomic_directory(tmp_path / "d") as tmp:
        (tmp / "f").write_text("x")
        assert not (tmp_path / "d").exists()
    assert (tmp_path / "d" / "f").read_text() == "x"


def test_bem_field_opens_with_meshio_and_matches_the_result(tmp_path):
    import meshio

    outcome = execute_scene("elliptic", overrides=FAST)
    runner.write_outputs(outcome, tmp_path / "res")
    mesh = meshio.read(tmp_path / "res" / "bem_field.vtu")
    res = outcome.bem
    np.testing.assert_array_equal(mesh.points[:, 0], res.x)
    np.testing.assert_array_equal(mesh.points[:, 1], res.y)
    for name, values in (("p", res.p), ("gap", res.gap), ("closure", res.closure),
                         ("displacement", res.displacement)):
        np.testing.assert_array_equal(np.ravel(mesh.point_data[name]), values)
    np.testing.assert_allclose(np.ravel(mesh.point_data["initial_gap"]),
                               res.x**2 / (2 * 0.02) + res.y**2 / (2 * 0.005), rtol=1e-12, atol=1e-18)
    assert mesh.cells[0].type == "triangle"


def test_lattice_triangles_tile_the_region():
    """Equilateral, counter-clockwise, each interior node in 6 triangles, Euler characteristic 1."""
    from bem.lattice import Lattice

    lat = Lattice.from_extent(0.1, (0.75, 0.6))
    tris = lattice_triangles(lat)
    x, y = lat.x[lat.mask], lat.y[lat.mask]
    a, b, c = (np.column_stack([x[tris[:, k]], y[tris[:, k]]]) for k in range(3))
    for u, v in ((a, b), (b, c), (c, a)):
        np.testing.assert_allclose(np.linalg.norm(u - v, axis=1), 0.1, rtol=1e-12)
    cross = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
    assert (cross > 0).all()
    count = np.bincount(tris.ravel(), minlength=x.size)
    interior = ~lat.border[lat.mask]
    assert (count[interior] == 6).all()
    edges = {tuple(sorted(e)) for t in tris for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    assert x.size - len(edges) + len(tris) == 1
    assert len({tuple(sorted(t)) for t in tris}) == len(tris)


def test_scene_file_in_the_result_reruns_identically(tmp_path):
    from bem.files import file_mode

    first = run_scene("paper_bilinear", tmp_path / "a", overrides=["bem.nodes_across=16", "fem.n_contact_elements=8"])
    files = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert files == [".contactlab", "bem_field.vtu", "fem_field.vtu", "result.json", "scene.toml"]
    for name in files:  # every file has the permissions of a new file (umask), fem_field.vtu too
        assert ((tmp_path / "a" / name).stat().st_mode & 0o777) == file_mode(), name
    second = run_scene(tmp_path / "a" / "scene.toml")
    assert second.p_max == first.p_max and second.approach == first.approach
    assert second.fem.p_max == first.fem.p_max


def test_progress_reports_every_planned_stage(tmp_path):
    """The run tells progress(label, done, total) (validation.progress): each stage at its start, the
    BEM iterations within their stage, then the end; with a result directory, its writing too."""
    events = []
    scene = load_scene("paper_elastic_rigid", overrides=["bem.nodes_across=16", "fem.n_contact_elements=8"])
    execute_scene(scene, progress=lambda *a: events.append(a))
    stages = runner.planned_stages(scene)
    assert stages == ["layer", "bem", "fem", "compare"]
    assert [e for e in events if ":" not in e[0]] == [(s, k, 4) for k, s in enumerate(stages)] + [("done", 4, 4)]
    iterations = [e for e in events if e[0].startswith("bem: iteration")]
    assert iterations and all(e[1:] == (1, 4) for e in iterations)
    events.clear()
    run_scene(scene, tmp_path / "r", progress=lambda *a: events.append(a))
    assert [e for e in events if ":" not in e[0]] == [(s, k, 5) for k, s in enumerate(stages + ["write"])] + [
        ("done", 5, 5)]


def test_not_converged_is_flagged_and_written(tmp_path):
    r = run_scene("rough_sphere", tmp_path / "r", overrides=["bem.nodes_across=16", "fem.n_contact_elements=8",
                                                             "bem.maxiter=1"])
    assert r.converged is False and r.bem.converged is False
    assert any("did not converge" in m for m in r.messages)
    assert json.loads((tmp_path / "r" / "result.json").read_text())["converged"] is False


def test_automatic_region_grows_when_the_estimate_is_short():
    """An extent_factor of 1.0 on the root law (wider than its estimate) is enlarged, not refused."""
    r = run_scene("paper_root", overrides=["bem.nodes_across=16", "bem.extent_factor=1.0"])
    assert r.converged
    assert any("enlarged" in m for m in r.messages)


@pytest.mark.parametrize("scene_name, overrides", [
    ("paper_root", ["bem.extent_factor=1.0"]),  # enlarged while calibrating the root law
    ("paper_elastic_rigid", ["bem.extent_factor=1.0", "layer.alpha_a=1.0"]),
])
def test_an_enlarged_region_is_the_estimate_times_1_5_and_solves_as_if_given(scene_name, overrides):
    """The region grows by 1.5 (up to the gap's domain) and the run is that of a scene giving the grown
    region itself: the calibration and the solve both use it."""
    from bem.region import region_limit

    scene = load_scene(scene_name, overrides=["bem.nodes_across=16", "fem.n_contact_elements=8", *overrides])
    grown = execute_scene(scene).result
    limit = region_limit(scene.gap)
    ex, ey = grown.bem.extent
    assert any("enlarged" in m for m in grown.messages)
    assert (ex, ey) == tuple(min(1.5 * e, lim) for e, lim in zip(scene.bem["extent"], limit))
    given = execute_scene(scene, overrides=[f"bem.extent=[{ex!r}, {ey!r}]"]).result
    assert not any("enlarged" in m for m in given.messages)
    for key in ("p_max", "approach", "contact_area", "iterations"):
        assert getattr(given, key) == getattr(grown, key), key
    assert given.layer["parameters"] == grown.layer["parameters"]


def test_a_given_region_the_contact_outgrows_is_refused_by_its_scene_key():
    """A region the scene gives does not grow: the error names the key as the scene writes it."""
    scene = load_scene("paper_root", overrides=["bem.nodes_across=16", "bem.extent_factor=1.0"], no_fem=True)
    ex, ey = scene.bem["extent"]  # the estimate, which the root law's contact outgrows (test above)
    with pytest.raises(bem.RegionTooSmallError, match=r"^bem\.extent = .* the contact reaches the border"):
        execute_scene(scene, overrides=[f"bem.extent=[{ex!r}, {ey!r}]"])


def test_planned_stages_hold_the_calibration_exactly_when_it_solves():
    """The "layer" stage is planned for the scenes whose layer needs calibration solves, and only those."""
    for name in ("paper_linear", "paper_root", "paper_elastic_rigid", "paper_bilinear", "hertz"):
        scene = load_scene(name, overrides=["bem.nodes_across=12"], no_fem=True)
        solves = execute_scene(scene).result.layer.get("reference_solves", 0)
        assert ("layer" in runner.planned_stages(scene)) == (solves > 0), name


def test_run_does_not_modify_the_scene():
    scene = load_scene("paper_root", overrides=["bem.nodes_across=16"])
    raw = json.dumps(scene.raw, sort_keys=True)
    run_scene(scene)
    assert json.dumps(scene.raw, sort_keys=True) == raw


HEAVY = ("gmsh", "skfem", "pyvista", "matplotlib")  # meshio is core: it writes bem_field.vtu


def test_bem_only_runs_import_no_heavy_package(tmp_path):
    scene = (ROOT / "validation" / "scenes" / "paper_root.toml").read_text()
    start = scene.index("[fem]")
    scene = scene[:start] + scene[scene.index("\n\n", start):]  # the same scene without its [fem] block
    (tmp_path / "root_bem_only.toml").write_text(scene)
    code = textwrap.dedent(f"""
        import sys
        from validation.run import run_scene
        from validation.cli import main
        run_scene("roller", {str(tmp_path / 'a')!r}, overrides=["bem.nodes_across=12"])
        run_scene({str(tmp_path / 'root_bem_only.toml')!r}, {str(tmp_path / 'b')!r},
                  overrides=["bem.nodes_across=16"])
        assert main(["--no-progress", "run", "roller", "--out", {str(tmp_path / 'c')!r},
                     "--set", "bem.nodes_across=12"]) == 0
        print(sorted(m for m in {HEAVY!r} if m in sys.modules))
    """)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=tmp_path,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == "[]"
    assert (tmp_path / "b" / "result.json").is_file() and not (tmp_path / "b" / "fem_field.vtu").exists()


def test_the_fem_edge_band_of_a_scene_is_recorded(tmp_path):
    """``[fem] refine_edge``: the FEM solves once more on a mesh refined around its contact edge, and the
    result records the band (``fem.mesh.edge = [r_e, k]``, ``r_e`` the first mesh's edge near Hertz's)."""
    r = run_scene("hertz", tmp_path / "e", overrides=["bem.nodes_across=16", "fem.n_contact_elements=8",
                                                      "fem.refine_edge=4"])
    record = json.loads((tmp_path / "e" / "result.json").read_text())
    r_e, k = record["fem"]["mesh"]["edge"]
    assert k == 4 and abs(r_e / r.fem.edge_radius - 1.0) < 0.02
    with pytest.raises(SceneError, match=r"^fem\.refine_edge = 1 is not allowed: it must be an integer >= 2"):
        load_scene("hertz", overrides=["fem.refine_edge=1"])
