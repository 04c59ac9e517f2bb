"""One list of the files a run writes (validation.run.runner.FILES): the runner, the report, the
command line's summary and docs/results.md all follow it."""

import re
from pathlib import Path

import pytest

from validation.report.documents.results import load_results
from validation.run.runner import FILES

from .conftest import SMALL, cli

DOCS = Path(__file__).resolve().parents[2] / "docs" / "results.md"


@pytest.fixture(scope="module")
def hertz_run(tmp_path_factory):
    """The built-in hertz scene (BEM, FEM, closed form, [stress]) run small from the command line."""
    out = tmp_path_factory.mktemp("files") / "hertz"
    args = ["run", "hertz", "--out", out]
    for s in SMALL["hertz"]:
        args += ["--set", s]
    code, stdout, stderr = cli(*args)
    assert code == 0, stderr
    return out, stdout


def test_every_written_file_is_in_the_list(hertz_run):
    out, _ = hertz_run
    written = {p.name for p in out.iterdir()} - {".contactlab"}
    assert written == set(FILES.values())  # the scene has [fem] and [stress]: every file is written


def test_the_report_finds_every_file_of_the_run(hertz_run):
    out, _ = hertz_run
    res = load_results(out)
    assert set(res.files) == set(FILES)
    assert {key: path.name for key, path in res.files.items()} == FILES
    assert res.files["stress_field"].is_file()


def test_the_report_finds_the_files_without_the_stored_list(hertz_run, tmp_path):
    """A result.json whose ``files`` is null: the report falls back to the same list."""
    import json
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(hertz_run[0], copy)
    data = json.loads((copy / "result.json").read_text())
    data["files"] = None
    (copy / "result.json").write_text(json.dumps(data))
    res = load_results(copy)
    assert {key: path.name for key, path in res.files.items()} == FILES
    assert res.bem_field is not None and res.fem_field is not None


def test_the_command_line_summary_names_every_file(hertz_run):
    _, stdout = hertz_run
    line = next(line for line in stdout.splitlines() if line.startswith("files"))
    assert set(re.search(r"\((.*)\)", line).group(1).split(", ")) == set(FILES.values())


def test_the_docs_table_lists_every_file():
    text = DOCS.read_text(encoding="utf-8")
    table = text[:text.index("\n## ")]
    listed = set(re.findall(r"^\| `([^`]+)` \|", table, re.M))
    assert listed == set(FILES.values()) | {".contactlab"}


def test_the_command_line_help_names_every_file(capsys):
    from validation.cli import build_parser

    with pytest.raises(SystemExit):
        build_parser().parse_args(["--help"])
    text = capsys.readouterr().out
    assert all(name in text for name in FILES.values())
