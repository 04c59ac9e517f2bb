"""`contactlab report SWEEP_DIR`: the report of a sweep directory, as `report --help` promises; and
the stages every report build tells its progress callback."""

import numpy as np
import pytest

from validation.report.documents.results import load_results
from validation.report.documents.sections import STAGES, report_results_dir
from validation.report.documents.sweep import is_sweep_dir, load_sweep, report_sweep_dir, sweep_sections
from validation.run import run_scene
from validation.run.sweep import run_sweep

from .conftest import cli
from .test_report_build import assert_valid_offline_html, figure_sources
from .figure_spy import drawn  # noqa: F401 - a fixture
from .test_report_figures import check_png

FORCES = [50.0, 100.0, 200.0]


@pytest.fixture(scope="module")
def sweep_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep") / "elliptic-sweep"
    run_sweep("elliptic", out, parameter="load.force", values=FORCES, workers=1, overrides=["bem.nodes_across=12"])
    return out


def test_report_of_a_sweep_directory_from_the_cli(sweep_dir, tmp_path):
    assert is_sweep_dir(sweep_dir) and not is_sweep_dir(tmp_path)
    code, out, err = cli("report", sweep_dir, "--out", tmp_path / "rep")
    assert code == 0, err
    assert f"report written to {tmp_path / 'rep' / 'report.html'}" in out
    html = (tmp_path / "rep" / "report.html").read_text(encoding="utf-8")
    assert_valid_offline_html(html)
    assert len(figure_sources(html)) == 2 and all((tmp_path / "rep" / s).is_file() for s in figure_sources(html))
    md = (tmp_path / "rep" / "report.md").read_text(encoding="utf-8")
    assert md.startswith("# Elliptic Hertz contact: sweep of load.force")
    rows = [line for line in md.splitlines() if line.startswith("| 50 |") or line.startswith("| 100 |")
            or line.startswith("| 200 |")]
    assert len(rows) == 3 and all("| converged |" in r for r in rows)
    for png in sorted((tmp_path / "rep" / "figures").glob("*.png")):
        check_png(png)


def test_sweep_sections_hold_every_point_in_the_reports_units(sweep_dir, tmp_path):
    summary, points = load_sweep(sweep_dir)
    assert [row["value"] for row, _ in points] == FORCES and all(res is not None for _, res in points)
    sections = sweep_sections(summary, points, tmp_path)
    assert [s.kind for s in sections] == ["problem", "sweeps"]
    table = sections[1].items[0]
    assert table.columns[:3] == ("load.force [N]", "status", "p_max [MPa]")  # an SI scene: MPa, as its figures
    p_max = [float(r[2]) for r in table.rows]
    assert p_max[2] / p_max[0] == pytest.approx(4 ** (1 / 3), rel=0.03)  # Hertz: p_max ~ P^(1/3)
    captions = [item.caption for item in sections[1].items[1:]]
    assert len(captions) == 2 and "coloured by load.force" in captions[0]


def test_sweep_figures_show_every_point(sweep_dir, tmp_path, drawn):
    """The profiles figure has one curve per point, its colour bar the swept forces; the scalars
    figure draws each point's p_max, in MPa (the report unit of the SI scene), against the force."""
    _summary, points = load_sweep(sweep_dir)
    sweep_sections(_summary, points, tmp_path)
    profiles, scalars = drawn
    ax, bar = profiles.axes
    assert len(ax.get_lines()) == len(FORCES)
    np.testing.assert_allclose(bar.get_yticks(), FORCES)
    for ln, (_row, res) in zip(ax.get_lines(), points):
        assert ln.get_ydata().max() * 1e6 == pytest.approx(res.result.p_max, rel=0.02)  # MPa, as labelled
    assert "MPa" in ax.get_ylabel()
    p_panel = scalars.axes[0]
    (line,) = p_panel.get_lines()
    np.testing.assert_allclose(line.get_xdata(), FORCES)
    np.testing.assert_allclose(line.get_ydata() * 1e6, [res.result.p_max for _, res in points])
    assert "MPa" in p_panel.get_ylabel() and scalars.axes[-1].get_xlabel()


def test_sweep_report_dimensionless_and_svg(sweep_dir, tmp_path):
    built = report_sweep_dir(sweep_dir, tmp_path / "rep", units="dimensionless", fmt="svg")
    assert sorted(p.suffix for p in built.figures) == [".svg", ".svg"]
    _summary, points = load_sweep(sweep_dir, units="dimensionless")
    assert all(res.dimensionless for _, res in points)


def test_sweep_dir_with_a_failed_point(sweep_dir, tmp_path):
    import json
    import shutil

    d = tmp_path / "copy"
    shutil.copytree(sweep_dir, d)
    summary = json.loads((d / "summary.json").read_text())
    summary["points"][1].update(status="error", file=None, p_max=None)
    (d / "summary.json").write_text(json.dumps(summary))
    sections = sweep_sections(*load_sweep(d), tmp_path / "w")
    assert any("failed" in t and "100" in t for t in sections[1].text)
    assert [r[1] for r in sections[1].items[0].rows] == ["converged", "error", "converged"]


def test_report_stages_reach_the_progress_callback(tmp_path):
    run_scene("elliptic", tmp_path / "run", overrides=["bem.nodes_across=12"])
    calls = []
    report_results_dir(tmp_path / "run", tmp_path / "rep", progress=lambda *a: calls.append(a))
    assert calls == [(s, k, len(STAGES)) for k, s in enumerate(STAGES)] + [("done", len(STAGES), len(STAGES))]
    res = load_results(tmp_path / "run")
    assert not res.dimensionless and np.isfinite(res.result.p_max)


@pytest.fixture(scope="module")
def layered_sweep(tmp_path_factory):
    """A sweep of the linear layer's compliance lam (two laws) of the paper's problem, without FEM."""
    from validation.scene import load_scene

    out = tmp_path_factory.mktemp("layered") / "sweep"
    scene = load_scene("paper_linear", overrides=["bem.nodes_across=12"], no_fem=True)
    run_sweep(scene, out, parameter="layer.lam", values=LAMS, workers=1)
    return out


LAMS = [4e-16, 8e-16]  # m/Pa


def _problem_text(sections):
    return " ".join(sections[0].text)


def test_a_layered_sweep_states_its_layer_and_draws_each_points_law(layered_sweep, tmp_path, drawn):
    summary, points = load_sweep(layered_sweep)
    sections = sweep_sections(summary, points, tmp_path)
    assert [s.title for s in sections] == ["Problem statement", "Interface layer law", "Sweep results"]
    assert "with an interface layer" in _problem_text(sections) and "no interface layer" not in _problem_text(sections)
    laws = drawn[0].axes[0]
    assert "[MPa]" in laws.get_xlabel() and "[mm]" in laws.get_ylabel()
    lines = [ln for ln in laws.get_lines() if not ln.get_label().startswith("_")]
    assert [ln.get_label() for ln in lines] == [f"layer.lam = {lam * 1e9:g}" for lam in LAMS]  # mm/MPa
    for ln, lam in zip(lines, LAMS):
        p, w = (np.asarray(v, float) for v in ln.get_data())
        np.testing.assert_allclose(w[1:] / p[1:], lam * 1e9, rtol=1e-12)  # w = lam p, in mm and MPa


def test_a_layer_that_cannot_be_rebuilt_is_still_a_layer_in_the_sweep_report(layered_sweep, tmp_path):
    """A custom law is never imported by a report: the problem statement names the layer and the
    method the run used, from the record, and no w(p) is drawn."""
    import json
    import shutil

    d = tmp_path / "copy"
    shutil.copytree(layered_sweep, d)
    for path in (d / "points").glob("*.json"):
        point = json.loads(path.read_text())
        custom = {"law": "custom", "w": "no_such_module_of_anyone:w", "p_scale": 1e8}
        point["scene"]["layer"] = custom
        point["result"]["layer"] = {"law": "custom", "parameters": custom}
        point["result"]["bem"]["method"] = point["result"]["method"] = "newton"
        path.write_text(json.dumps(point))
    sections = sweep_sections(*load_sweep(d), tmp_path / "w")
    assert [s.title for s in sections] == ["Problem statement", "Sweep results"]
    text = _problem_text(sections)
    assert "with an interface layer" in text and "no interface layer" not in text
    assert "Solved by the BEM: Newton" in text and "quadratic programme" not in text
