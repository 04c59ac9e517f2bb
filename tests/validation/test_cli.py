"""The contactlab command line: help, listing, check, run exit codes, dispatch to studies/reports."""

import json
import sys
import types

import pytest

from validation.cli import build_parser, main

from .conftest import cli

SUBCOMMANDS = ("run", "scenes", "check", "sweep", "study", "report")


def test_help_teaches(capsys):
    assert main(["--help"]) == 0
    text = capsys.readouterr().out
    assert "examples:" in text and "Units" in text and "Pa" in text
    for cmd in SUBCOMMANDS:
        assert f"contactlab {cmd}" in text
    assert "Exit codes" in text


@pytest.mark.parametrize("cmd", SUBCOMMANDS)
def test_every_subcommand_has_examples(cmd, capsys):
    assert main([cmd, "--help"]) == 0
    text = capsys.readouterr().out
    assert "example" in text and f"contactlab {cmd}" in text


def test_scenes_lists_builtins():
    code, out, _ = cli("scenes")
    assert code == 0
    names = [line.split()[0] for line in out.splitlines() if line.strip() and not line.startswith("run one")]
    assert {"hertz", "paper_elastic_rigid", "paper_root", "paper_bilinear", "paper_linear", "roller", "punch",
            "rough_sphere"} <= set(names)


def test_check_ok():
    code, out, err = cli("check", "paper_bilinear")
    assert code == 0 and "paper_bilinear: OK" in out and "sweep" in out and err == ""


def test_run_prints_a_summary(tmp_path):
    code, out, err = cli("run", "paper_root", "--out", tmp_path / "r", "--set", "bem.nodes_across=16",
                         "--set", "fem.n_contact=8")
    assert code == 0, err
    result = json.loads((tmp_path / "r" / "result.json").read_text())
    for label in ("p_max", "contact", "approach", "converged  yes", "time", "files", "alpha_b", "FEM"):
        assert label in out
    assert f"{result['p_max']:.6g} Pa" in out
    assert "units SI (m, Pa, N)" in out


def test_run_not_converged_exits_1_and_writes(tmp_path):
    code, out, _ = cli("run", "rough_sphere", "--out", tmp_path / "r", "--set", "bem.nodes_across=16",
                       "--set", "bem.maxiter=1", "--set", "fem.n_contact=8")
    assert code == 1
    assert json.loads((tmp_path / "r" / "result.json").read_text())["converged"] is False
    assert "converged  NO" in out


def test_run_bad_input_exits_2_and_writes_nothing(tmp_path):
    code, out, err = cli("run", "hertz", "--out", tmp_path / "r", "--set", "bodies.nu1=0.7")
    assert code == 2 and "bodies.nu1" in err and out == ""
    assert not (tmp_path / "r").exists()


def test_run_into_foreign_directory_exits_2(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    code, _out, err = cli("run", "elliptic", "--out", tmp_path, "--set", "bem.nodes_across=16")
    assert code == 2 and "not a contactlab result" in err
    assert (tmp_path / "notes.txt").read_text() == "mine"


def test_region_that_cannot_hold_the_load_exits_2(tmp_path):
    code, _out, err = cli("run", "roller", "--out", tmp_path / "r", "--set", "bem.nodes_across=12",
                          "--set", "load.force=9000.0")
    assert code == 2 and "end of the gap's domain" in err
    assert not (tmp_path / "r").exists()


def test_unknown_option_exits_2():
    code, _out, err = cli("run", "hertz", "--frobnicate")
    assert code == 2 and "frobnicate" in err


def test_default_output_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, _ = cli("run", "elliptic", "--set", "bem.nodes_across=16")
    assert code == 0 and (tmp_path / "results" / "elliptic" / "result.json").is_file()


@pytest.mark.parametrize("argv, module", [
    (["study", "error-time", "hertz", "--out", "x", "--levels", "3"], "validation.studies.error_time"),
    (["study", "stability"], "validation.studies.stability"),
    (["report", "results/hertz", "--out", "rep"], "validation.report"),
])
def test_study_and_report_dispatch_their_arguments(argv, module, monkeypatch):
    seen = {}
    fake = types.ModuleType(module)
    fake.main = lambda args: seen.setdefault("args", args) and 7
    monkeypatch.setitem(sys.modules, module, fake)
    code, _out, _err = cli(*argv)
    assert code == 7
    args = seen["args"]
    if argv[0] == "report":
        assert args.target == "results/hertz" and args.out == "rep"
    else:
        assert args.study == argv[1]
        assert getattr(args, "scene", None) == (argv[2] if len(argv) > 2 else None)
    if "--levels" in argv:
        assert args.extra == ["--levels", "3"]


def test_parser_is_buildable_without_heavy_imports():
    assert build_parser().prog == "contactlab"
