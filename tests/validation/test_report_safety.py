"""Reports of untrusted result and sweep folders: only files inside the folder are read, and the
texts of a scene (title, description, units) reach report.md as plain text, never as Markdown
structure or raw HTML."""

import json
import logging
import re
import shutil
import tomllib

import pytest
from tomli_w import dumps

from validation.report.documents.results import load_results
from validation.report.documents.sections import report_results_dir
from validation.report.documents.sweep import load_sweep, report_sweep_dir
from validation.report.render import Section, Table, build_report
from validation.run import run_scene

SECRET = "SECRET-OUTSIDE-4711"
HOSTILE_TITLE = 'Evil <script>alert("t")</script> [click](javascript:alert(1))\n# Injected heading'
HOSTILE_TEXT = ("<iframe src=\"https://example.org\"></iframe> see [here](javascript:alert(2))\n"
                "# Heading from a description\n- a list item\n<img src=x onerror=alert(3)>")


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("safety") / "elliptic"
    run_scene("elliptic", out, overrides=["bem.nodes_across=12"])
    return out


def _copy(run_dir, tmp_path):
    d = tmp_path / "res"
    shutil.copytree(run_dir, d)
    return d


def _outside_scene(run_dir, tmp_path):
    """A valid scene.toml outside the result folder whose description is the secret."""
    scene = tomllib.loads((run_dir / "scene.toml").read_text())
    scene.setdefault("scene", {})["description"] = SECRET
    path = tmp_path / "outside" / "scene.toml"
    path.parent.mkdir()
    path.write_text(dumps(scene))
    return path


@pytest.mark.parametrize("how", ["absolute", "relative", "link"])
def test_result_files_outside_the_folder_are_not_read(run_dir, tmp_path, caplog, how):
    d = _copy(run_dir, tmp_path)
    outside = _outside_scene(run_dir, tmp_path)
    data = json.loads((d / "result.json").read_text())
    if how == "link":
        (d / "linked.toml").symlink_to(outside)
        name = "linked.toml"
    else:
        name = str(outside) if how == "absolute" else "../outside/scene.toml"
    data.setdefault("files", {})["scene"] = name
    (d / "result.json").write_text(json.dumps(data))
    with caplog.at_level(logging.WARNING):
        res = load_results(d)
        built = report_results_dir(d, tmp_path / "rep")
    assert SECRET not in json.dumps(res.scene)
    assert SECRET not in built.html.read_text() and SECRET not in built.markdown.read_text()
    assert any("files.scene" in r.getMessage() and "outside" in r.getMessage() for r in caplog.records)


def test_result_fields_outside_the_folder_are_not_read(run_dir, tmp_path, caplog):
    d = _copy(run_dir, tmp_path)
    other = _copy(run_dir, tmp_path / "other")
    data = json.loads((d / "result.json").read_text())
    data["files"]["bem_field"] = str(other / "bem_field.vtu")
    (d / "result.json").write_text(json.dumps(data))
    with caplog.at_level(logging.WARNING):
        assert load_results(d).bem_field is None
        assert load_results(other).bem_field is not None  # the same file inside its own folder is read
    assert any("files.bem_field" in r.getMessage() for r in caplog.records)


def _sweep_dir(run_dir, tmp_path, file):
    """A sweep folder of one point whose stored file name is ``file``; the point's data hold the secret."""
    d = tmp_path / "sweep"
    (d / "points").mkdir(parents=True)
    result = json.loads((run_dir / "result.json").read_text())
    scene = tomllib.loads((run_dir / "scene.toml").read_text())
    scene["scene"]["description"] = SECRET
    (tmp_path / "outside.json").write_text(json.dumps({"scene": scene, "result": result}))
    (d / "points" / "point-000.json").write_text(json.dumps({"scene": scene, "result": result}))
    summary = {"key": "load.force", "scene": "elliptic", "values": [1.0],
               "points": [{"value": 1.0, "status": "converged", "file": file, "p_max": result.get("p_max")}]}
    (d / "summary.json").write_text(json.dumps(summary))
    return d


@pytest.mark.parametrize("file", ["../outside.json", "ABSOLUTE"])
def test_sweep_points_outside_the_folder_are_not_read(run_dir, tmp_path, caplog, file):
    file = str(tmp_path / "outside.json") if file == "ABSOLUTE" else file
    d = _sweep_dir(run_dir, tmp_path, file)
    with caplog.at_level(logging.WARNING):
        _summary, points = load_sweep(d)
        built = report_sweep_dir(d, tmp_path / "rep")
    assert points[0][1] is None
    assert SECRET not in built.html.read_text() and SECRET not in built.markdown.read_text()
    assert any("points[0].file" in r.getMessage() for r in caplog.records)


def test_sweep_points_inside_the_folder_are_read(run_dir, tmp_path):
    _summary, points = load_sweep(_sweep_dir(run_dir, tmp_path, "points/point-000.json"))
    assert points[0][1] is not None and points[0][1].section("scene")["description"] == SECRET


def _markdown_structure(md):
    """The Markdown lines that are headings, and the raw HTML tags and links of ``md``."""
    headings = [line for line in md.splitlines() if re.match(r"#{1,6} ", line)]
    tags = re.findall(r"<(script|iframe|img)\b", md, flags=re.I)
    links = re.findall(r"(?<!\\)\[[^\]]*(?<!\\)\]\((javascript:[^)]*)", md, flags=re.I)
    return headings, tags, links


def test_hostile_scene_texts_reach_markdown_as_plain_text(run_dir, tmp_path):
    d = _copy(run_dir, tmp_path)
    scene = tomllib.loads((d / "scene.toml").read_text())
    scene["scene"]["description"] = HOSTILE_TEXT
    (d / "scene.toml").write_text(dumps(scene))
    data = json.loads((d / "result.json").read_text())
    data["title"] = HOSTILE_TITLE
    (d / "result.json").write_text(json.dumps(data))
    built = report_results_dir(d, tmp_path / "rep")
    md = built.markdown.read_text()
    headings, tags, links = _markdown_structure(md)
    assert headings[0].startswith("# Evil") and "Injected heading" in headings[0]  # one line, the title's
    assert not any("Injected" in h or "Heading from" in h for h in headings[1:])
    assert tags == [] and links == []
    assert not re.search(r"^\s*- a list item", md, flags=re.M)
    assert "&lt;script&gt;" in md and "&lt;iframe" in md
    html = built.html.read_text()
    assert "<script" not in html and "<iframe" not in html and "&lt;script&gt;" in html


def test_hostile_units_captions_and_cells(tmp_path):
    from .test_report_build import _png

    png = _png(tmp_path / "f.png")
    from validation.report.render import Figure

    sections = [Section("Plain <b>title</b>\n## two", text=("1. numbered\n> quote", "*x* `y` _z_ a\\b"), items=(
        Table(("unit [<i>mm</i>]", "b|c"), (("<script>", "[x](javascript:y)"),), caption="cap\n# h"),
        Figure(str(png), "Figure <iframe> caption\n# heading"))), Section("Other")]
    md = build_report(sections, tmp_path / "rep", title="T", footer="f").markdown.read_text()
    headings, tags, links = _markdown_structure(md)
    assert headings == ["# T", "## Plain &lt;b&gt;title&lt;/b&gt; ## two", "## Other"]
    assert tags == [] and links == [] and "<b>" not in md and "<i>" not in md
    assert "1\\. numbered &gt; quote" in md and "\\*x\\* \\`y\\` \\_z\\_ a\\\\b" in md
    assert "| &lt;script&gt; | \\[x\\](javascript:y) |" in md


@pytest.mark.parametrize("text", ["p_max = 3 Pa", "sqrt(A / pi)", "R = 0.01 m, E1 = 2.1e+11 Pa", "-0.5"])
def test_plain_texts_stay_readable(text):
    from validation.report.render.markdown import md_escape

    assert md_escape(text, block=False) == text
