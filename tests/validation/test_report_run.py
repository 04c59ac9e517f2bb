"""Reports of REAL result directories: built-in scenes run by validation.run.run_scene at small
settings, then reported with every section of SECTIONS. Checks: the scene's title and units, tables
without raw containers, profile windows that hold the contact, an FEM section only when the FEM
ran, comparison metrics when recorded, valid self-contained HTML, inputs untouched. (The scene's
[report] sections and new sections and figures: test_report_sections.py.)"""

import copy
import json
import re
import shutil
import tomllib

import numpy as np
import pytest
from tomli_w import dumps

from validation.report import SECTIONS, main, report_results_dir
from validation.report.documents.results import load_results
from validation.report.documents.sections import run_sections
from validation.report.figures.run import profile_view
from validation.report.render import Figure, Table, build_report
from validation.report.render.style import display_unit, report_unit
from validation.run import run_scene
from validation.scene import builtin_path
from validation.units import parse_units

from .conftest import e_star, hertz
from .test_report_build import assert_valid_offline_html

SMALL = {
    "hertz": ["bem.nodes_across=16", "fem.n_contact_elements=6"],  # FEM + closed form
    "paper_elastic_rigid": ["bem.nodes_across=16", "fem.n_contact_elements=6"],  # layer + FEM
    "elliptic": ["bem.nodes_across=16"],  # BEM only + closed form, not axisymmetric
    "roller": ["bem.nodes_across=12"],  # BEM only, no reference, elongated
}


def _scene_file(name):
    with open(builtin_path(name), "rb") as fh:
        return tomllib.load(fh)


@pytest.fixture(scope="module")
def reports(tmp_path_factory):
    """name -> {"dir", "res", "sections", "built", "scene"} for every scene of SMALL."""
    root = tmp_path_factory.mktemp("runs")
    out = {}
    for name, small in SMALL.items():
        run_scene(name, root / name, overrides=small)
        res = load_results(root / name)
        work = root / f"{name}-figures"
        work.mkdir()
        sections = run_sections(res, work, SECTIONS)
        built = build_report(sections, root / f"{name}-report", title=res.title)
        out[name] = {"dir": root / name, "res": res, "sections": sections, "built": built,
                     "scene": _scene_file(name)}
    return out


def _tables(sections):
    return [item for sec in sections for item in sec.items if isinstance(item, Table)]


def _results_table(sections):
    sec = next(s for s in sections if s.title == "Results")
    return next(item for item in sec.items if isinstance(item, Table))


def _row(table, label):
    return next(r for r in table.rows if r[0] == label)


@pytest.mark.parametrize("name", list(SMALL))
def test_tables_hold_no_raw_containers(reports, name):
    for table in _tables(reports[name]["sections"]):
        for row in table.rows:
            for cell in row:
                assert "{" not in cell and "[" not in cell, (table.caption, row)
    md = reports[name]["built"].markdown.read_text(encoding="utf-8")
    table_lines = [line for line in md.splitlines() if line.startswith("|")]
    assert table_lines and not [line for line in table_lines if "{" in line or "[" in line]


@pytest.mark.parametrize("name", list(SMALL))
def test_title_is_the_scenes_and_units_are_the_reports(reports, name):
    """An SI scene's report shows lengths in mm and pressures in MPa in its tables, as in its figures
    (test_report_units.py), and its problem statement names them and the scene's units label."""
    meta = reports[name]["scene"]["scene"]
    html = reports[name]["built"].html.read_text(encoding="utf-8")
    assert f"<h1>{meta['title']}</h1>" in html.replace("&#x27;", "'") and "contactlab report: result" not in html
    assert meta["units"] == "SI (m, Pa, N)"
    units = {row[-1] for row in _results_table(reports[name]["sections"]).rows}
    assert {"MPa", "N", "mm", "mm^2"} <= units <= {"MPa", "N", "mm", "mm^2", "-"}
    problem = reports[name]["sections"][0]
    stated = [t for t in problem.text if t.startswith("Units")]
    assert problem.kind == "problem" and len(stated) == 1 and meta["units"] in stated[0]
    assert "lengths are in mm" in stated[0] and "stresses in MPa" in stated[0]


def test_problem_statement_of_the_layer_scene(reports):
    rep = reports["paper_elastic_rigid"]
    problem = rep["sections"][0]
    rows = {r[0]: r[1:] for r in problem.items[0].rows}
    bodies = rep["scene"]["bodies"]
    es = e_star(bodies["E1"], bodies["nu1"], bodies["E2"], bodies["nu2"])
    label = next(k for k in rows if k.startswith("effective modulus"))
    assert float(rows[label][0]) * 1e6 == pytest.approx(es, rel=1e-3) and rows[label][1] == "MPa"
    assert rows["gap R"] == ("10", "mm") and rows["load: total force P (force control)"] == ("100", "N")
    assert rows["interface layer"][0].startswith("elastic-rigid")
    params = rep["res"].result.layer["parameters"]
    assert float(rows["layer p_cr"][0]) * 1e6 == pytest.approx(params["p_cr"], rel=1e-3)
    assert rows["layer p_cr"][1] == "MPa" and rows["layer lam"][1] == "mm/MPa"
    assert float(rows["layer lam"][0]) * 1e-3 / 1e6 == pytest.approx(params["lam"], rel=1e-3)  # mm/MPa -> m/Pa
    in_scene_units = run_sections(load_results(rep["dir"], units="scene"), rep["dir"].parent / "scene", ["scene"])
    scene = {r[0]: r[1:] for r in in_scene_units[0].items[0].rows}
    assert scene["gap R"] == ("0.01", "m") and scene["layer lam"][1] == "m/Pa"  # --units scene
    assert not [i for i in problem.items if isinstance(i, Figure)]
    figures = [i for s in rep["sections"] if s.title == "Interface layer law" for i in s.items]
    assert len(figures) == 1 and isinstance(figures[0], Figure) and "w(p)" in figures[0].caption
    # smooth scene: a row saying so, no law figure
    hertz_problem = reports["hertz"]["sections"][0]
    assert not [i for s in reports["hertz"]["sections"] for i in s.items
                if isinstance(i, Figure) and "w(p)" in i.caption]
    assert _row(hertz_problem.items[0], "interface layer")[1].startswith("none")


def test_profile_window_holds_the_contact_normalised(reports):
    rep = reports["hertz"]
    scene = rep["scene"]
    b = scene["bodies"]
    a_h, p_h, _ = hertz(scene["load"]["force"], scene["gap"]["R"], e_star(b["E1"], b["nu1"], b["E2"], b["nu2"]))
    prof = rep["res"].result.profile
    x, p = np.array(prof.x), np.array(prof.p)
    assert not profile_view(rep["res"], [(x, p)]).normalised  # an SI scene is drawn in mm and MPa by default
    view = profile_view(load_results(rep["dir"], units="dimensionless"), [(x, p)])
    assert view.x_label == r"$x\,/\,a_H$" and view.p_label == r"contact pressure $p\,/\,p_H$"
    assert view.normalised and view.x_factor == pytest.approx(a_h, rel=1e-9)
    assert view.p_factor == pytest.approx(p_h, rel=1e-9)
    edge = np.abs(x[p > 0]).max() / view.x_factor  # the plotted contact edge
    assert 0.8 < edge < 1.2  # a Hertz contact of radius a_H (16 nodes across: within a step)
    assert view.xlim[0] < -edge and edge < view.xlim[1] <= 2.0 * edge
    assert view.xlim[0] == -view.xlim[1]


def test_profile_window_holds_the_contact_in_scene_units(reports):
    rep = reports["roller"]
    prof = rep["res"].result.profile
    for key, line in (("x", {"x": prof.x, "p": prof.p}), ("y", prof.y_axis)):
        s, p = np.array(line[key]), np.array(line["p"])
        view = profile_view(rep["res"], [(s, p)], axis=key)
        assert not view.normalised
        edge_m = np.abs(s[p > 0]).max()
        edge = edge_m / view.x_factor
        assert view.xlim[0] < -edge and edge < view.xlim[1] <= 2.0 * edge, key
        assert view.x_factor == 1e-3 and view.p_factor == 1e6  # SI scene: mm and MPa
        assert "[mm]" in view.x_label and "[MPa]" in view.p_label
    # dimensionless: divided by the peak pressure and the contact half-width (no Hertz scale for a roller)
    view = profile_view(load_results(rep["dir"], units="dimensionless"), [(np.array(prof.x), np.array(prof.p))])
    assert view.normalised and view.p_factor == pytest.approx(rep["res"].result.p_max)
    assert view.x_factor == pytest.approx(rep["res"].result.contact_extent["x"])
    assert view.x_label == r"$x\,/\,a_c$" and view.p_label == r"contact pressure $p\,/\,p_{max}$"
    length = rep["scene"]["gap"]["length"]
    x_edge = np.abs(np.array(prof.x)[np.array(prof.p) > 0]).max()
    assert 0.8 * length / 2 < x_edge <= length / 2  # the crowned roller loads nearly its whole length


def test_sections_follow_the_data(reports):
    titles = {name: [s.title for s in rep["sections"]] for name, rep in reports.items()}
    for name, rep in reports.items():  # comparison metrics exactly when the run recorded them
        assert (titles[name][-1] == "Comparison metrics") == (rep["res"].result.comparison is not None), name
        assert rep["sections"][-1].kind == "validation" or titles[name][-1] != "Comparison metrics"
        if titles[name][-1] == "Comparison metrics":
            titles[name].pop()
    every = ["Problem statement", "Results", "Solver and timings", "Pressure profiles",
             "Pressure over the contact plane", "Convergence of the BEM"]
    assert titles["hertz"] == every + ["FEM reference", "Subsurface stresses"]  # FEM and [stress]
    assert titles["paper_elastic_rigid"] == every[:1] + ["Interface layer law"] + every[1:] + ["FEM reference"]
    assert titles["elliptic"] == titles["roller"] == every
    kinds = {s.title: s.kind for rep in reports.values() for s in rep["sections"]}
    assert (kinds["Problem statement"], kinds["Interface layer law"], kinds["Convergence of the BEM"],
            kinds["FEM reference"]) == ("problem", "problem", "iterations", "fem")
    names = {name: sorted(p.name for p in rep["built"].figures) for name, rep in reports.items()}
    base = ["contact_map.png", "convergence.png", "fem_von_mises.png", "profile_x.png"]
    assert names["hertz"] == sorted(base + ["stress_profiles.png", "stress_section.png"])
    assert names["paper_elastic_rigid"] == sorted(base + ["layer_law.png"])
    assert names["elliptic"] == names["roller"] == ["contact_map.png", "convergence.png", "profile_x.png",
                                                    "profile_y.png"]


@pytest.mark.parametrize("name", ["elliptic", "roller"])
def test_bem_only_report_has_no_fem(reports, name):
    built = reports[name]["built"]
    html = built.html.read_text(encoding="utf-8")
    assert_valid_offline_html(html)
    assert "kind-fem" not in html and "FEM" not in html and "FEM" not in built.markdown.read_text()
    assert _results_table(reports[name]["sections"]).columns[1] == "BEM"


def test_fem_section_and_columns(reports):
    rep = reports["hertz"]
    data = rep["res"].result
    html = rep["built"].html.read_text(encoding="utf-8")
    assert_valid_offline_html(html)
    assert 'class="kind-fem"' in html
    table = _results_table(rep["sections"])
    assert table.columns == ("quantity", "BEM", "FEM", "closed form", "unit")
    fem_sec = next(s for s in rep["sections"] if s.kind == "fem")
    fem_rows = {r[0]: r[1] for r in fem_sec.items[0].rows}
    assert fem_rows["degrees of freedom"] == str(data.fem.n_dofs)
    assert float(fem_rows["wall time: total"]) == pytest.approx(data.fem.timings["total"], rel=1e-2)
    # ratios to Hertz: independent closed form
    scene = rep["scene"]
    b = scene["bodies"]
    a_h, p_h, d_h = hertz(scene["load"]["force"], scene["gap"]["R"], e_star(b["E1"], b["nu1"], b["E2"], b["nu2"]))
    ratio = _row(table, "p_max / p_H (Hertz peak)")
    assert float(ratio[1]) == pytest.approx(data.p_max / p_h, rel=1e-3)
    assert float(ratio[3]) == pytest.approx(1.0, rel=1e-3)  # the closed form is Hertz
    assert float(_row(table, "delta / delta_H (Hertz approach)")[3]) == pytest.approx(1.0, rel=1e-3)
    run_rows = {r[0]: r[1] for r in next(s for s in rep["sections"] if s.title == "Solver and timings").items[0].rows}
    assert run_rows["iterations (finest lattice)"] == str(data.iterations)
    assert float(run_rows["lattice step c"]) * 1e-3 == pytest.approx(data.bem.step, rel=1e-3)  # mm


def test_comparison_metrics_when_recorded(reports, tmp_path):
    d = tmp_path / "run"
    shutil.copytree(reports["hertz"]["dir"], d)
    data = json.loads((d / "result.json").read_text())
    pair = {"l2_rel": 0.0123, "max_rel": 0.02, "peak_rel": -0.0004, "contact_radius_rel": None,
            "edge_radius_rel": 0.003, "approach_rel": 1e-5, "force_rel": 0.0, "n_points": 321}
    data["comparison"] = {"bem_vs_fem": pair, "bem_vs_analytic": dict(pair, l2_rel=0.5), "fem_vs_analytic": None,
                          "force_balance": {"target": 100.0, "bem": 1e-12, "fem": 2e-4}}
    (d / "result.json").write_text(json.dumps(data))
    sections = run_sections(load_results(d), tmp_path / "fig")
    sec = next(s for s in sections if s.title == "Comparison metrics")
    pairs, balance = sec.items
    assert pairs.columns == ("metric", "BEM vs FEM", "BEM vs closed form")
    assert _row(pairs, "relative L2 error of p")[1:] == ("1.23 %", "50 %")
    assert _row(pairs, "nodes compared (union of contacts)")[1:] == ("321", "321")
    rows = {r[0]: r[1:] for r in balance.rows}
    assert rows["target force P"] == ("100", "N") and rows["force balance |F - P| / P (FEM)"] == ("0.02 %", "-")
    for table in (pairs, balance):
        assert not [c for r in table.rows for c in r if "{" in c or "[" in c]


def test_report_results_dir_and_command(reports, tmp_path, monkeypatch):
    built = report_results_dir(reports["elliptic"]["dir"], tmp_path / "rep")
    html = built.html.read_text(encoding="utf-8")
    assert_valid_offline_html(html)
    assert "<h1>Elliptic Hertz contact</h1>" in html
    # contactlab report SCENE.toml --out OUT: run into results/NAME, report into OUT
    monkeypatch.chdir(tmp_path)
    raw = _scene_file("elliptic")
    raw["bem"]["nodes_across"] = 12
    scene = tmp_path / "small.toml"
    scene.write_text(dumps(raw))
    main(str(scene), out=str(tmp_path / "out"))
    assert (tmp_path / "results" / raw["scene"]["name"] / "result.json").is_file()
    md = (tmp_path / "out" / "report.md").read_text(encoding="utf-8")
    assert md.startswith("# Elliptic Hertz contact\n")


def test_units_parsing_and_display():
    u = parse_units("SI (m, Pa, N)")
    assert (u.length, u.pressure, u.force, u.of("area"), u.of("compliance")) == ("m", "Pa", "N", "m^2", "m/Pa")
    assert parse_units("SI").as_dict() == {"length": "m", "pressure": "Pa", "force": "N"}
    assert parse_units("mm, MPa, N").as_dict() == {"length": "mm", "pressure": "MPa", "force": "N"}
    odd = parse_units("normalised: R = E* = P = 1")
    assert not odd.known and odd.of("pressure") == "-" and odd.of("area") == "-"
    assert display_unit("m", 1.87e-4) == ("µm", 1e-6) and display_unit("m", 5e-3) == ("mm", 1e-3)
    assert display_unit("Pa", 1.37e9) == ("GPa", 1e9) and display_unit("Pa", 4e5) == ("kPa", 1e3)
    assert display_unit("mm", 0.2) == ("mm", 1.0) and display_unit(None, 3.0) == ("", 1.0)
    assert report_unit("m") == ("mm", 1e-3) and report_unit("Pa") == ("MPa", 1e6)
    assert report_unit("N") == ("N", 1.0) and report_unit("mm") == ("mm", 1.0) and report_unit(None) == ("", 1.0)
    # auto: the scene's units when its label names them, dimensionless otherwise
    assert parse_units("normalised: R = E* = P = 1").known is False


def test_report_does_not_modify_the_results(reports, tmp_path):
    res = reports["paper_elastic_rigid"]["res"]
    before = copy.deepcopy(res.result), copy.deepcopy(res.scene), [a.copy() for a in res.bem_field]
    run_sections(res, tmp_path, SECTIONS)
    assert res.result == before[0] and res.scene == before[1]
    assert all(np.array_equal(a, b) for a, b in zip(res.bem_field, before[2]))
    files = sorted(p.name for p in reports["paper_elastic_rigid"]["dir"].iterdir())
    assert files == [".contactlab", "bem_field.vtu", "fem_field.vtu", "result.json", "scene.toml"]


def test_captions_say_how(reports, tmp_path):
    rep = reports["hertz"]
    data = rep["res"].result
    captions = [i.caption for s in rep["sections"] for i in s.items if isinstance(i, Figure)]
    profile = next(c for c in captions if c.startswith("Contact pressure along"))
    assert "Kalker QP" in profile and "tolerance 1e-10" in profile and f"{data.bem.n_nodes} candidate" in profile
    assert re.search(r"FEM: axisymmetric quadratic triangles, [\d.]+ elements across", profile)
    assert "p_H = " not in profile  # drawn in mm and MPa
    sections = run_sections(load_results(rep["dir"], units="dimensionless"), tmp_path)
    captions = [i.caption for s in sections for i in s.items if isinstance(i, Figure)]
    profile = next(c for c in captions if c.startswith("Contact pressure along"))
    assert "p_H = " in profile and "a_H = " in profile
