"""Output folders: contactlab writes only into new, empty or its own folders; clear errors for unusable paths."""

import errno
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import validation.run.runner as runner
from validation.folders import leftover_prefixes
from validation.io import MARKER, recover_output_dir, write_marker

from .conftest import cli

ROOT = Path(__file__).resolve().parents[2]
FAST = ("--set", "bem.nodes_across=16")


def _tree(folder):
    """Every path below ``folder`` with its content (files) or None (folders)."""
    return {str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else None) for p in sorted(folder.rglob("*"))}


def _hidden(parent):
    return sorted(p.name for p in parent.iterdir() if p.name.startswith("."))


def _one_line_error(err):
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("contactlab: error: ") and "Traceback" not in err, err
    return lines[0]


def _user_folder(folder):
    folder.mkdir()
    (folder / "result.json").write_text('{"mine": true}')
    (folder / "my_scene.toml").write_text("[scene]\nname = 'x'\n")
    (folder / "notes.txt").write_text("notes")
    (folder / "thesis.tex").write_text("precious")
    (folder / "data").mkdir()
    (folder / "data" / "measured.csv").write_text("1,2\n")
    return _tree(folder)


def test_run_refuses_a_user_folder_that_holds_a_result_json(tmp_path):
    out = tmp_path / "mine"
    before = _user_folder(out)
    code, stdout, err = cli("run", "elliptic", "--out", out, *FAST)
    line = _one_line_error(err)
    assert code == 2 and stdout == "" and f"--out = {str(out)!r}" in line and "notes.txt" in line
    assert _tree(out) == before
    assert _hidden(tmp_path) == []


def test_report_refuses_a_folder_of_dotfiles(tmp_path):
    assert cli("run", "elliptic", "--out", tmp_path / "r", *FAST)[0] == 0
    rep = tmp_path / "rep"
    rep.mkdir()
    (rep / ".git").mkdir()
    (rep / ".git" / "HEAD").write_text("ref: refs/heads/main\n")
    (rep / ".env").write_text("SECRET=1\n")
    before = _tree(rep)
    code, _out, err = cli("report", tmp_path / "r", "--out", rep)
    line = _one_line_error(err)
    assert code == 2 and str(rep) in line and ".git" in line
    assert _tree(rep) == before


def test_own_folders_are_marked_and_replaced_other_kinds_refused(tmp_path):
    out = tmp_path / "r"
    assert cli("run", "elliptic", "--out", out, *FAST)[0] == 0
    marker = json.loads((out / MARKER).read_text())
    assert marker["kind"] == "result" and marker["version"]
    assert cli("report", out)[0] == 0  # default: out/report, a report folder inside the result folder
    assert json.loads((out / "report" / MARKER).read_text())["kind"] == "report"
    assert cli("run", "elliptic", "--out", out, "--set", "bem.nodes_across=20")[0] == 0  # its own: replaced
    assert json.loads((out / "result.json").read_text())["overrides"] == ["bem.nodes_across=20"]
    code, _out, err = cli("report", out, "--out", out)  # a result folder is not a report folder
    assert code == 2 and "result folder, not a report folder" in _one_line_error(err)
    assert (out / "result.json").is_file()


def test_a_user_file_in_a_result_folder_stops_its_replacement(tmp_path):
    out = tmp_path / "r"
    assert cli("run", "elliptic", "--out", out, *FAST)[0] == 0
    (out / "notes.txt").write_text("mine")
    code, _out, err = cli("run", "elliptic", "--out", out, *FAST)
    assert code == 2 and "notes.txt" in _one_line_error(err)
    assert (out / "notes.txt").read_text() == "mine"


def test_sweep_refuses_a_foreign_folder_and_resumes_its_own(tmp_path):
    foreign = tmp_path / "f"
    foreign.mkdir()
    (foreign / "summary.json").write_text('{"mine": true}')
    before = _tree(foreign)
    argv = ("sweep", "elliptic", "--param", "load.force", "--values", "50,100", "--workers", "1", *FAST)
    code, stdout, err = cli(*argv, "--out", foreign)
    assert code == 2 and stdout == "" and str(foreign) in _one_line_error(err)
    assert _tree(foreign) == before
    own = tmp_path / "s"
    assert cli(*argv, "--out", own)[0] == 0
    assert json.loads((own / MARKER).read_text())["kind"] == "sweep"
    code, stdout, _err = cli(*argv, "--out", own)
    assert code == 0 and "computed 0, reused 2" in stdout


def test_report_out_is_the_report_folder_for_every_target(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli("report", "elliptic", "--out", "rep_scene", *FAST)[0] == 0
    assert (tmp_path / "rep_scene" / "report.html").is_file()
    result = json.loads((tmp_path / "results" / "elliptic" / "result.json").read_text())
    assert result["overrides"] == ["bem.nodes_across=16"]
    assert cli("report", "results/elliptic", "--out", "rep_result")[0] == 0
    assert (tmp_path / "rep_result" / "report.html").is_file()
    assert sorted(p.name for p in (tmp_path / "rep_scene").iterdir()) == sorted(
        p.name for p in (tmp_path / "rep_result").iterdir())


@pytest.mark.parametrize("err_no, reason", [(errno.ENOSPC, "full"), (errno.EROFS, "read-only")])
def test_a_full_or_read_only_file_system_is_a_clear_error(tmp_path, monkeypatch, err_no, reason):
    out = tmp_path / "r"
    assert cli("run", "elliptic", "--out", out, *FAST)[0] == 0
    before = _tree(out)

    def failing(path, *args, **kwargs):
        raise OSError(err_no, os.strerror(err_no), str(path))

    monkeypatch.setattr(runner, "write_text", failing)
    code, stdout, err = cli("run", "elliptic", "--out", out, *FAST)
    line = _one_line_error(err)
    assert code == 2 and stdout == "" and str(out) in line and reason in line
    assert _tree(out) == before and _hidden(tmp_path) == []


@pytest.mark.skipif(not Path("/sys/kernel").is_dir(), reason="needs Linux sysfs (not writable even by root)")
def test_an_unwritable_location_is_a_clear_error():
    code, _out, err = cli("run", "elliptic", "--out", "/sys/contactlab-output", *FAST)
    line = _one_line_error(err)
    assert code == 2 and "'/sys/contactlab-output'" in line and "permission" in line


def test_an_output_path_under_a_file_is_refused_before_the_run(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    code, _out, err = cli("run", "elliptic", "--out", tmp_path / "notes.txt" / "r", *FAST)
    line = _one_line_error(err)
    assert code == 2 and f"{str(tmp_path / 'notes.txt')!r} is a file" in line
    assert (tmp_path / "notes.txt").read_text() == "mine"


def test_an_output_name_longer_than_the_file_system_allows_is_refused(tmp_path):
    long = tmp_path / ("o" * 300)
    for argv in (("run", "elliptic"), ("sweep", "elliptic", "--param", "load.force", "--values", "50")):
        code, _out, err = cli(*argv, "--out", long, *FAST)
        line = _one_line_error(err)
        assert code == 2 and line.startswith("contactlab: error: --out = ") and "300 bytes" in line
        assert "at most 255 bytes" in line


def test_a_scene_name_too_long_for_the_default_folder_is_refused(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    text = (ROOT / "validation" / "scenes" / "elliptic.toml").read_text()
    scene = tmp_path / "long.toml"
    scene.write_text(text.replace('name = "elliptic"', f'name = "{"n" * 300}"', 1))
    for argv in (("run", scene), ("report", scene), ("sweep", scene, "--param", "load.force", "--values", "50")):
        code, stdout, err = cli(*argv, *FAST)
        line = _one_line_error(err)
        assert code == 2 and stdout == "" and "scene.name = 'nnnn" in line and "at most 255 bytes" in line
        assert "--out" in line
    assert not (tmp_path / "results").exists() or list((tmp_path / "results").iterdir()) == []


def _dead_pid():
    proc = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    return int(proc.stdout)


def test_recovery_restores_a_previous_folder_moved_aside_by_a_killed_writer(tmp_path):
    target = tmp_path / "r"
    assert cli("run", "elliptic", "--out", target, *FAST)[0] == 0
    before = _tree(target)
    (new, moved), dead = leftover_prefixes(target), _dead_pid()
    old, tmp = tmp_path / f"{moved}{dead}-abc", tmp_path / f"{new}{dead}-def"
    for folder in (old, tmp):  # the hidden folders as contactlab makes them: marked at once
        folder.mkdir()
        write_marker(folder, "result")
    os.replace(target, old / "previous")  # the state between the two renames of a replacement
    assert recover_output_dir(target) is True
    assert _tree(target) == before and _hidden(tmp_path) == []


def test_recovery_leaves_the_folders_of_a_running_writer(tmp_path):
    new = leftover_prefixes(tmp_path / "r")[0]
    live = tmp_path / f"{new}{os.getpid()}-abc"
    live.mkdir()
    write_marker(live, "result")
    dead = tmp_path / f"{new}{_dead_pid()}-def"
    (dead / "half").mkdir(parents=True)
    write_marker(dead, "result")
    assert recover_output_dir(tmp_path / "r") is False
    assert _hidden(tmp_path) == [live.name]

