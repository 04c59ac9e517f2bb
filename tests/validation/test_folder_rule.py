"""contactlab replaces only what it wrote: the files its marker lists (sub-folders included), its own
marked hidden folders beside a target, a study's own files, and never the repository's kept reports
by default."""

import json
import subprocess
import sys
import types
from pathlib import Path

import pytest

from validation.folders import leftover_prefixes
from validation.io import MARKER, OutputError, atomic_directory, check_output_dir

from .conftest import cli

ROOT = Path(__file__).resolve().parents[2]
FAST = ("--set", "bem.nodes_across=16")


def _tree(folder):
    """Every path below ``folder`` with its content (files) or None (folders)."""
    return {str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else None) for p in sorted(folder.rglob("*"))}


def _one_line_error(err):
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("contactlab: error: ") and "Traceback" not in err, err
    return lines[0]


def _dead_pid():
    proc = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    return int(proc.stdout)


def _user_leftovers(parent, target):
    """Hidden folders of the user beside ``target``, named like a writer's leftovers but unmarked."""
    new, old = leftover_prefixes(target)
    folders = [parent / f".{target.name}.old-1", parent / f".{target.name}.tmp-2",
               parent / f"{new}{_dead_pid()}-mine", parent / f"{old}{_dead_pid()}-mine"]
    for folder in folders:
        (folder / "previous").mkdir(parents=True)
        (folder / "previous" / "draft.tex").write_text("my own draft")
    return {folder.name: _tree(folder) for folder in folders}


def test_hidden_folders_of_the_user_beside_the_target_are_kept(tmp_path):
    thesis = tmp_path / "thesis"
    thesis.mkdir()
    (thesis / "chapter.tex").write_text("mine")
    before = _user_leftovers(tmp_path, thesis)
    code, _out, err = cli("run", "elliptic", "--out", thesis, *FAST)  # refused: a user's folder
    assert code == 2 and "chapter.tex" in _one_line_error(err)
    assert {name: _tree(tmp_path / name) for name in before} == before
    paper = tmp_path / "paper"
    before = _user_leftovers(tmp_path, paper)
    assert cli("run", "elliptic", "--out", paper, *FAST)[0] == 0  # written, twice (a replacement)
    assert cli("run", "elliptic", "--out", paper, *FAST)[0] == 0
    assert {name: _tree(tmp_path / name) for name in before} == before


def test_a_user_file_in_a_sub_folder_stops_the_replacement(tmp_path):
    out = tmp_path / "r"
    assert cli("run", "elliptic", "--out", out, *FAST)[0] == 0
    assert cli("report", out)[0] == 0  # out/report: a report folder inside the result folder
    (out / "report" / "my_notes.md").write_text("mine")
    (out / "report" / "figures" / "sketch.png").write_bytes(b"mine")
    before = _tree(out)
    code, _out, err = cli("run", "elliptic", "--out", out, *FAST)
    line = _one_line_error(err)
    assert code == 2 and "report/my_notes.md" in line and "report/figures/sketch.png" in line
    code, _out, err = cli("report", out)  # the report folder itself
    assert code == 2 and "my_notes.md" in _one_line_error(err)
    assert _tree(out) == before
    (out / "report" / "my_notes.md").unlink()
    (out / "report" / "figures" / "sketch.png").unlink()
    assert cli("run", "elliptic", "--out", out, *FAST)[0] == 0  # what contactlab wrote is replaced
    assert sorted(json.loads((out / MARKER).read_text())["files"]) == sorted(
        p.name for p in out.iterdir() if p.name != MARKER)


def test_a_folder_where_a_file_was_written_is_not_replaced(tmp_path):
    from validation.layer_law import NAMES

    out = tmp_path / "law"
    with atomic_directory(out, "layer-law", NAMES) as tmp:
        for name in NAMES:
            (tmp / name).write_text("written")
    (out / "layer_law.toml").unlink()
    (out / "layer_law.toml").mkdir()
    (out / "layer_law.toml" / "mine.txt").write_text("mine")
    before = _tree(out)
    with pytest.raises(OutputError, match=r"layer_law\.toml/"):
        with atomic_directory(out, "layer-law", NAMES) as tmp:
            (tmp / "layer_law.toml").write_text("new")
    assert _tree(out) == before


def test_a_marker_without_a_list_of_files_is_not_replaced(tmp_path):
    out = tmp_path / "r"
    out.mkdir()
    (out / MARKER).write_text(json.dumps({"kind": "result", "version": "0.1.0"}))
    (out / "result.json").write_text("{}")
    with pytest.raises(OutputError, match="lists no files"):
        check_output_dir(out, "result", ("result.json",))


def _fake_study(monkeypatch, module, stem):
    """Replace the study ``module`` by one that writes ``{stem}.json`` at once."""
    from validation.studies import save

    fake = types.ModuleType(module)
    fake.STEM = stem
    fake.main = lambda **kw: save(kw["out"], stem, {"rows": [], "by": stem})
    monkeypatch.setitem(sys.modules, module, fake)
    monkeypatch.setattr("validation.report.documents.studies.study_markdown", lambda name, data: f"# {name}\n")


def test_a_study_writes_its_own_folder_and_keeps_the_other_studies(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _fake_study(monkeypatch, "validation.studies.two_scale", "two_scale")
    (tmp_path / "two_scale.md").write_text("my notes")
    assert cli("study", "two-scale")[0] == 0  # default folder results/two-scale
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results", "two_scale.md"]
    assert (tmp_path / "two_scale.md").read_text() == "my notes"
    folder = tmp_path / "results" / "two-scale"
    assert json.loads((folder / MARKER).read_text())["kind"] == "study"
    assert (folder / "two_scale.md").read_text() == "# two_scale.json\n"

    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "two_scale.md").write_text("my notes")
    code, _out, err = cli("study", "two-scale", "--out", mine)
    assert code == 2 and "two_scale.md" in _one_line_error(err) and str(mine) in err
    assert _tree(mine) == {"two_scale.md": b"my notes"}

    _fake_study(monkeypatch, "validation.studies.stability", "stability")
    assert cli("study", "stability", "--out", folder)[0] == 0  # another study into the same folder
    assert json.loads((folder / "two_scale.json").read_text())["by"] == "two_scale"
    assert json.loads((folder / "stability.json").read_text())["by"] == "stability"
    assert sorted(json.loads((folder / MARKER).read_text())["files"]) == [
        "stability.json", "stability.md", "two_scale.json", "two_scale.md"]


def _report_folder(folder, text):
    from validation.report.render import REPORT_FILES

    with atomic_directory(folder, "report", REPORT_FILES) as tmp:
        (tmp / "report.md").write_text(text)


def test_the_paper_report_never_replaces_the_kept_reports_by_default(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a repository root with its kept reports/paper
    _report_folder(tmp_path / "reports" / "paper", "kept")
    before = _tree(tmp_path / "reports")
    written = []

    def fake(out, *, quick, fmt="png", progress=None):
        written.append(Path(out))
        _report_folder(out, "quick preview")

        class Built:
            html = markdown = out_dir = Path(out)
            figures = notes = ()

        return Built()

    monkeypatch.setattr("validation.report.documents.paper.report_paper_problem", fake)
    code, _out, err = cli("report", "paper", "--quick")
    assert code == 0, err
    assert _tree(tmp_path / "reports") == before
    assert len(written) == 1 and not written[0].absolute().is_relative_to(tmp_path / "reports")
    assert (written[0] / "report.md").read_text() == "quick preview"


@pytest.mark.parametrize("folder, kind", [("paper", "report"), ("hertz", "report"), ("validation", "report"),
                                          ("studies", "study")])
def test_the_kept_reports_may_be_regenerated_into_their_folders(folder, kind):
    """docs/regenerate_reports.sh writes each kept folder with an explicit --out: the folder rule allows it."""
    from validation.cli.study import STUDIES, study_files
    from validation.report.render import REPORT_FILES

    names = REPORT_FILES if kind == "report" else (*(n for s in STUDIES for n in study_files(s)), "report")
    check_output_dir(ROOT / "reports" / folder, kind, names)
    assert f"--out reports/{folder}" in (ROOT / "docs" / "regenerate_reports.sh").read_text()
