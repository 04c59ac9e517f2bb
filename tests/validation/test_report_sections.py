"""The sections of a run's report: a scene's [report] sections are honoured (exactly those, in that
order), a new section or figure is one function and one registry line, and the scene schema
knows the sections by the registry's names."""

import json
import re
import shutil

import pytest

from validation.report import FIGURES, SECTIONS, report_results_dir
from validation.report.documents.results import load_results
from validation.run.record import ResultFileError
from validation.report.documents.sections import run_sections
from validation.report.render import Figure, Section, Table
from validation.run import run_scene

from .test_report_build import _png, assert_valid_offline_html


@pytest.fixture(scope="module")
def elliptic_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("sections") / "elliptic"
    run_scene("elliptic", out, overrides=["bem.nodes_across=12"])
    return out


def _with_report(src, dst, report):
    """A copy of the result directory ``src`` whose result.json holds ``report`` (None: no [report])."""
    shutil.copytree(src, dst)
    data = json.loads((dst / "result.json").read_text())
    data["report"] = report
    (dst / "result.json").write_text(json.dumps(data))
    return dst


def _headings(built):
    return re.findall(r"<h2>(.*?)</h2>", built.html.read_text(encoding="utf-8"))


def test_report_sections_are_exactly_the_scenes(elliptic_dir, tmp_path):
    # the built-in scene asks for ["scene", "summary", "profile", "pressure_map", "comparison", "convergence"]
    assert json.loads((elliptic_dir / "result.json").read_text())["report"]["sections"] == [
        "scene", "summary", "profile", "pressure_map", "comparison", "convergence"]
    built = report_results_dir(elliptic_dir, tmp_path / "builtin")
    assert _headings(built) == ["Problem statement", "Results", "Pressure profiles", "Pressure over the contact plane",
                                "Comparison metrics", "Convergence of the BEM"]
    d = _with_report(elliptic_dir, tmp_path / "two", {"sections": ["summary", "profile"], "format": "html"})
    built = report_results_dir(d, tmp_path / "two-report")
    assert_valid_offline_html(built.html.read_text(encoding="utf-8"))
    assert _headings(built) == ["Results", "Pressure profiles"]
    assert sorted(p.name for p in built.figures) == ["profile_x.png", "profile_y.png"]
    # in the order given
    d = _with_report(elliptic_dir, tmp_path / "order", {"sections": ["profile", "scene", "summary"], "format": "html"})
    assert [s.title for s in run_sections(load_results(d), tmp_path / "w")] == [
        "Pressure profiles", "Problem statement", "Results"]


def test_without_report_every_supported_section(elliptic_dir, tmp_path):
    d = _with_report(elliptic_dir, tmp_path / "all", None)
    built = report_results_dir(d, tmp_path / "all-report")
    # no layer, no FEM, no [stress], not a sweep: those sections are left out
    assert _headings(built) == ["Problem statement", "Results", "Solver and timings", "Pressure profiles",
                                "Pressure over the contact plane", "Convergence of the BEM", "Comparison metrics"]


def test_a_new_section_and_a_new_figure_are_one_function_and_one_line_each(elliptic_dir, tmp_path, monkeypatch):
    def toy_section(res, work):
        """A section of its own: a table of two numbers of the results."""
        return Section("Toy section", items=(Table(("quantity", "value"), (("toy p_max", res.result.p_max),
                                                                            ("toy force", res.result.force))),))

    def toy_figure(res, work):
        """A figure placed in the Results section."""
        return Figure(_png(work / "toy.png"), "A toy figure of the summary.")

    monkeypatch.setitem(SECTIONS, "toy", toy_section)
    monkeypatch.setitem(FIGURES, "toy", ("summary", toy_figure))
    d = _with_report(elliptic_dir, tmp_path / "toy", None)  # every registered section
    built = report_results_dir(d, tmp_path / "toy-report")
    html = built.html.read_text(encoding="utf-8")
    assert_valid_offline_html(html)
    assert _headings(built)[-1] == "Toy section" and "toy p_max" in html and "toy force" in html
    results = html[html.index("<h2>Results</h2>"):html.index("<h2>Solver and timings</h2>")]
    assert "A toy figure of the summary." in results
    assert (built.out_dir / "figures" / "toy.png").is_file()
    # a scene may name it, alone
    d = _with_report(elliptic_dir, tmp_path / "toy-only", {"sections": ["toy"], "format": "html"})
    assert _headings(report_results_dir(d, tmp_path / "toy-only-report")) == ["Toy section"]


def test_unknown_section_is_refused(elliptic_dir, tmp_path):
    from bem.checks import InputError

    d = _with_report(elliptic_dir, tmp_path / "bad", {"sections": ["nonsense"], "format": "html"})
    with pytest.raises(InputError, match="nonsense"):
        report_results_dir(d, tmp_path / "bad-report")


def test_scene_schema_names_the_registered_sections():
    from validation.scene import schema

    assert schema.report_sections() == tuple(SECTIONS)


def test_units_are_the_recorded_symbols(elliptic_dir, tmp_path):
    """The report draws in result.json's unit_symbols, whatever its units label says; a result without
    them is refused, naming the missing field."""
    d = _with_report(elliptic_dir, tmp_path / "symbols", None)
    data = json.loads((d / "result.json").read_text())
    assert data["unit_symbols"] == {"length": "m", "pressure": "Pa", "force": "N"}
    data["units"] = "mm, MPa, N"  # a label that disagrees: the recorded symbols win
    (d / "result.json").write_text(json.dumps(data))
    res = load_results(d)
    assert (res.units.length, res.units.pressure, res.units.force) == ("m", "Pa", "N")
    assert [r[-1] for r in run_sections(res, tmp_path / "w", ["summary"])[0].items[0].rows][:2] == ["MPa", "N"]
    del data["unit_symbols"]
    (d / "result.json").write_text(json.dumps(data))
    with pytest.raises(ResultFileError, match=r"result\.unit_symbols is missing in .*result\.json"):
        load_results(d)
