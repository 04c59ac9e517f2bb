"""Report documents: strict-HTML5 validity, no network references, HTML and Markdown linking
the same relative figure files (each figure stored once), written whole or not at all. (Reports of result directories:
test_report_run.py.)"""

import base64
import os
import re
from pathlib import Path

import numpy as np
import pytest

from bem.checks import InputError
from validation.io import OutputError
from validation.report import build_report, main
from validation.report.render import Figure, Section, Table, fmt, problem_section, status_class
from validation.report.render import build as build_mod

html5lib = pytest.importorskip("html5lib")

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _png(path, value=0):
    """A small real PNG written with PIL (independent of the figure code)."""
    from PIL import Image

    img = np.full((20, 30, 3), 255, dtype=np.uint8)
    img[5:15, 5 + value:25] = (31, 119, 180)
    Image.fromarray(img).save(path)
    return str(path)


def assert_valid_offline_html(text):
    """Parses in html5lib's strict mode; no http(s) in src/href; no <link>, <script>, @import, url()."""
    html5lib.HTMLParser(strict=True).parse(text)
    refs = re.findall(r'(?:src|href)\s*=\s*"([^"]*)"', text, flags=re.I)
    assert refs, "no reference at all: the check would be empty"
    assert not [r for r in refs if r.lower().startswith(("http:", "https:", "//", "ftp:"))]
    assert not re.search(r"<link\b|<script\b|@import|url\(", text, flags=re.I)
    assert "http://" not in text and "https://" not in text


@pytest.fixture()
def sections(tmp_path):
    f1 = Figure(_png(tmp_path / "one.png"), "First figure. Computed by hand & <checked>.")
    f2 = Figure(_png(tmp_path / "two.png", 3), "Second figure, a_H/c = 8.")
    table = Table(("case", "p_max / p0", "status"), (("a | b", 0.123456, "converged"), ("c", 1e-9, "diverged"),
                                                     ("d", 2, "stalled")), caption="Statuses.",
                  status_column="status")
    return [Section("Problem <statement>", kind="problem", text=("Para & graph.",), items=(f1,)),
            Section("Results", items=(table, f2))]


def figure_sources(html):
    """The ``src`` of every ``<img>`` of an HTML report, in order."""
    return re.findall(r'<img src="([^"]+)"', html)


def markdown_figures(md):
    """The file of every image of a Markdown report, in order (alt texts may hold escaped brackets)."""
    return re.findall(r"!\[(?:\\.|[^\]\\])*\]\(([^)]+)\)", md)


def test_html_is_valid_offline_and_links_every_figure(sections, tmp_path):
    built = build_report(sections, tmp_path / "rep", title="T & <t>")
    text = built.html.read_text(encoding="utf-8")
    assert_valid_offline_html(text)
    sources = figure_sources(text)
    assert [built.out_dir / s for s in sources] == list(built.figures)
    assert all(not os.path.isabs(s) and (built.out_dir / s).read_bytes().startswith(PNG_MAGIC) for s in sources)
    # escaping and status colours
    assert "Problem &lt;statement&gt;" in text and "<statement>" not in text
    assert re.search(r'<tr class="ok">.*converged', text) and re.search(r'<tr class="bad">.*diverged', text)
    assert re.search(r'<tr class="warn">.*stalled', text)


def test_each_figure_is_stored_once(sections, tmp_path):
    """The HTML and the Markdown show the same files of figures/; no figure's bytes are also in a document."""
    built = build_report(sections, tmp_path / "rep", title="T")
    html, md = built.html.read_text(encoding="utf-8"), built.markdown.read_text(encoding="utf-8")
    assert figure_sources(html) == markdown_figures(md) == ["figures/one.png", "figures/two.png"]
    assert "data:" not in html
    for path in built.figures:
        data = path.read_bytes()
        for text in (html, md):
            assert base64.b64encode(data)[:40].decode() not in text
            assert base64.b64encode(data[1:])[:40].decode() not in text  # at another alignment too
    stored = sorted(p.relative_to(built.out_dir).as_posix() for p in built.out_dir.rglob("*") if p.is_file())
    assert stored == [".contactlab", "figures/one.png", "figures/two.png", "report.html", "report.md"]


@pytest.mark.parametrize("name", ["paper", "hertz", "validation"])
def test_kept_reports_store_each_figure_once(name):
    """The repository's reports (docs/regenerate_reports.sh): each file of figures/ is shown by both
    documents, and neither embeds a figure."""
    folder = Path(__file__).resolve().parents[2] / "reports" / name
    html, md = (folder / "report.html").read_text(encoding="utf-8"), (folder / "report.md").read_text(encoding="utf-8")
    files = sorted(f"figures/{p.name}" for p in (folder / "figures").iterdir())
    assert files and "data:" not in html and "data:" not in md
    assert sorted(set(figure_sources(html))) == sorted(set(markdown_figures(md))) == files


def test_markdown_links_relative_figures_that_exist(sections, tmp_path):
    built = build_report(sections, tmp_path / "rep", title="T")
    md = built.markdown.read_text(encoding="utf-8")
    links = markdown_figures(md)
    assert links == ["figures/one.png", "figures/two.png"]
    for link in links:
        assert not os.path.isabs(link) and (built.out_dir / link).read_bytes().startswith(PNG_MAGIC)
    assert "a \\| b" in md  # pipes in cells escaped
    assert "| c | 1e-09 | diverged | FAIL |" in md and "| a \\| b | 0.1235 | converged | OK |" in md


def test_build_replaces_previous_report_whole(sections, tmp_path):
    out = tmp_path / "rep"
    build_report(sections, out, title="first")
    build_report(sections[:1], out, title="second")
    assert sorted(os.listdir(out)) == [".contactlab", "figures", "report.html", "report.md"]
    assert os.listdir(out / "figures") == ["one.png"]  # the old figure is gone
    assert "second" in (out / "report.html").read_text()
    assert sorted(os.listdir(tmp_path)) == ["one.png", "rep", "two.png"]  # no temporary directories


def test_build_interrupted_leaves_previous_report(sections, tmp_path, monkeypatch):
    out = tmp_path / "rep"
    build_report(sections, out, title="first")
    before = {p: (out / p).read_bytes() for p in ("report.html", "report.md")}

    def boom(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(build_mod, "render_markdown", boom)
    with pytest.raises(KeyboardInterrupt):
        build_report(sections, out, title="second")
    assert {p: (out / p).read_bytes() for p in before} == before
    assert sorted(os.listdir(tmp_path)) == ["one.png", "rep", "two.png"]


def test_build_refuses_directory_with_other_files(sections, tmp_path):
    out = tmp_path / "results"
    out.mkdir()
    (out / "result.json").write_text("{}")
    with pytest.raises(OutputError, match="did not write .result.json"):
        build_report(sections, out, title="T")
    assert os.listdir(out) == ["result.json"]
    with pytest.raises(InputError, match="at least one section"):
        build_report([], tmp_path / "x", title="T")


def test_section_validation(tmp_path):
    with pytest.raises(InputError, match="existing PNG"):
        Figure(str(tmp_path / "missing.png"), "c")
    with pytest.raises(InputError, match="kind"):
        Section("x", kind="bogus")
    with pytest.raises(InputError, match="cells"):
        Table(("a", "b"), (("1",),))
    assert Figure(_png(tmp_path / "f.png"), "See Fig. 5 of the paper. Then more.").alt_text == "See Fig. 5 of the paper"


def test_every_solver_status_colours_its_cell():
    import bem
    import fem_reference

    expected = {"converged": "ok", "maxiter": "warn", "stalled": "warn", "diverged": "bad", "nonfinite": "bad",
                "singular": "bad", "boundary": "bad"}
    statuses = set(bem.STATUSES) | set(fem_reference.STATUSES)
    assert {s: status_class(s) for s in statuses} == {s: expected[s] for s in statuses}


def test_every_study_outcome_colours_its_cell():
    from validation.studies import STATUSES

    assert [status_class(s) for s in STATUSES] == ["ok", "bad", "bad"]


def test_status_and_format():
    assert [status_class(s) for s in ("converged", "stalled", "error", "reported failure", "pending")] \
        == ["ok", "warn", "bad", "bad", "other"]
    # a cell is a status word or nothing: a message that merely contains one colours nothing
    assert [status_class(s) for s in ("Converged (KKT 1e-9)", "diverged: x", "no", "maxiter reached")] \
        == ["other"] * 4
    assert fmt(0.000123456) == "0.0001235" and fmt(2.5e-9) == "2.5e-09" and fmt(12.34567) == "12.35"
    assert fmt(3) == "3" and fmt(True) == "yes" and fmt(None) == "-"


def test_table_from_rows():
    from validation.report.render import table_from_rows

    t = table_from_rows([{"case": "a", "status": "diverged", "extra": {"x": 1}}, {"case": "b", "n": 3}])
    assert t.columns == ("case", "status", "n") and t.status_column == "status"
    assert t.rows == (("a", "diverged", "-"), ("b", "-", "3")) and [t.status(r) for r in t.rows] == ["bad", "other"]
    assert table_from_rows([{"a": 1}]).status_column is None


def test_problem_section_lists_inputs(tmp_path):
    import bem

    sec = problem_section(gap=bem.gaps.Paraboloid(2.0), materials={"E1": 210e3, "nu1": 0.3},
                          load={"force": 100.0}, units={"length": "mm", "pressure": "MPa", "force": "N"},
                          layers=[("root", bem.layers.Root(0.5))])
    rows = {r[0]: r[1:] for r in sec.items[0].rows}
    assert rows["gap h(x, y)"] == ("paraboloid: R = 2", "mm")
    assert rows["material E1"] == ("2.1e+05", "MPa") and rows["material nu1"] == ("0.3", "-")
    assert rows["load: force"] == ("100", "N") and rows["layer: root"][0] == "root: lam = 0.5"


# ---------------------------------------------------------------- command

@pytest.mark.parametrize("target, options, word", [
    ("hertz", {"quick": True}, "quick = True"),  # paper only
    ("paper", {"units": "scene"}, "units = 'scene'"),
    ("paper", {"overrides": ["load.force=2"]}, "overrides = ['load.force=2']"),  # scenes only
])
def test_build_refuses_a_keyword_that_does_not_apply_to_the_target(target, options, word, tmp_path, monkeypatch):
    from validation.report.command import build

    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match=re.escape(word) + ".* is not allowed with target"):
        build(target, out=tmp_path / "rep", **options)
    assert list(tmp_path.iterdir()) == []  # nothing ran, nothing written


def test_main_rejects_unknown_target(tmp_path):
    with pytest.raises(InputError, match="built-in scene name, a scene TOML file, a results directory"):
        main(str(tmp_path / "no-such-scene.toml"))
