"""Provenance in result.json and in report footers, and no machine path in anything kept."""

import json
import platform
import re
import subprocess
from importlib import metadata
from pathlib import Path

import numpy as np
import pytest
import scipy

from validation import provenance as pv
from validation.report import report_results_dir, report_studies_dir
from validation.report.render import Section, build_report
from validation.run import run_scene

from .test_report_studies import _write as write_studies

ROOT = Path(__file__).resolve().parents[2]
MACHINE = re.compile(r"(/tmp/|/home/|/root/|/work/|/Users/|[A-Z]:\\\\)")


def _text(path):
    """A report file's text without its embedded images (base64 may spell anything)."""
    return re.sub(r"data:image/png;base64,[A-Za-z0-9+/=]+", "", Path(path).read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def elliptic_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("prov") / "elliptic"
    run_scene("elliptic", out, overrides=["bem.nodes_across=16"])
    return out


def test_result_json_records_provenance(elliptic_dir):
    prov = json.loads((elliptic_dir / "result.json").read_text())["provenance"]
    assert set(prov) == {"contactlab", "git", "python", "packages", "platform", "command"}
    assert prov["contactlab"] == metadata.version("contactlab")
    assert prov["python"] == platform.python_version()
    assert prov["packages"]["numpy"] == np.__version__ and prov["packages"]["scipy"] == scipy.__version__
    assert prov["packages"]["meshio"] == metadata.version("meshio")
    assert isinstance(prov["command"], str) and not MACHINE.search(prov["command"])
    if (ROOT / ".git").exists():
        head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
        assert prov["git"]["commit"] == head and isinstance(prov["git"]["dirty"], bool)


def test_fem_run_records_the_fem_packages(tmp_path):
    result = run_scene("hertz", overrides=["bem.nodes_across=12", "fem.n_contact_elements=6"])
    packages = result.provenance["packages"]
    assert packages["gmsh"] == metadata.version("gmsh") and packages["skfem"] == metadata.version("scikit-fem")


def test_no_git_outside_a_checkout(tmp_path, monkeypatch):
    monkeypatch.setattr(pv, "_ROOT", tmp_path)
    pv.git_state.cache_clear()
    try:
        assert pv.git_state() is None
        assert pv.provenance()["git"] is None
        assert "(git" not in pv.describe(pv.provenance())
    finally:
        pv.git_state.cache_clear()


@pytest.mark.parametrize("argv, orig, expected", [
    (["/usr/local/bin/contactlab", "run", "hertz", "--out", "/tmp/x/run1"],
     ["/usr/bin/python3", "/usr/local/bin/contactlab", "run", "hertz", "--out", "/tmp/x/run1"],
     "contactlab run hertz --out .../x/run1"),
    (["/srv/repo/validation/cli.py", "run", "/home/me/s.toml", "--out=/home/me/out"],
     ["python", "-m", "validation.cli", "run", "/home/me/s.toml", "--out=/home/me/out"],
     "python -m validation.cli run .../me/s.toml --out=.../me/out"),
    (["/venv/bin/pytest", "-m", "slow", "tests"], ["python", "/venv/bin/pytest", "-m", "slow", "tests"],
     "pytest -m slow tests"),
    (["-c", "a"], ["python", "-c", "print(1)", "a"], "python -c ... a"),
    (["docs/examples/hertz.py"], ["python", "docs/examples/hertz.py"], "python hertz.py"),
])
def test_command_line_has_no_machine_path(argv, orig, expected):
    assert pv.command_line(argv, orig) == expected


def test_display_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert pv.display_path(tmp_path / "results" / "hertz") == "results/hertz"
    assert pv.display_path("relative/dir") == "relative/dir"
    assert pv.display_path(tmp_path) == "."
    assert pv.display_path("/elsewhere/deep/a/b") == ".../a/b"
    assert pv.display_path("/") == "..."


def test_footer_records_versions_commit_and_command(tmp_path, monkeypatch):
    monkeypatch.setattr("sys.argv", ["/opt/bin/contactlab", "report", "paper", "--out", "/work/x/reports/paper"])
    built = build_report([Section("One", text=("text",))], tmp_path / "rep", title="T")
    prov = pv.provenance()
    for path in (built.html, built.markdown):
        text = _text(path)
        footer = text[text.index("Generated on"):]
        assert f"contactlab {prov['contactlab']}" in footer
        assert f"numpy {np.__version__}" in footer and f"scipy {scipy.__version__}" in footer
        assert f"Python {platform.python_version()}" in footer
        assert "command: contactlab report paper --out .../reports/paper" in footer
        if prov["git"]:
            assert f"git {prov['git']['commit'][:7]}" in footer
        assert not MACHINE.search(text)


def test_reports_name_no_machine_path(elliptic_dir, tmp_path, monkeypatch):
    """Result and study directories outside the working directory are shown by their last parts only."""
    monkeypatch.chdir(tmp_path)
    built = report_results_dir(elliptic_dir, tmp_path / "run-report")
    studies = report_studies_dir(write_studies(tmp_path), tmp_path / "study-report")
    for path in (built.html, built.markdown, studies.html, studies.markdown):
        text = _text(path)
        assert not MACHINE.search(text), MACHINE.search(text).group(0)
        assert str(tmp_path) not in text and str(elliptic_dir) not in text
    assert re.search(r"results read from \.\.\./prov\d*/elliptic", _text(built.markdown))
    assert "Studies read from studies" in _text(studies.markdown)


def test_kept_reports_name_no_machine_path():
    kept = [p for p in (ROOT / "reports").rglob("*") if p.suffix in (".md", ".html", ".json")]
    assert kept
    for path in kept:
        match = MACHINE.search(_text(path))
        assert match is None, f"{path.relative_to(ROOT)} names the machine path {match.group(0)!r}: regenerate it"
