"""The contactlab command line: help, listing, check, run exit codes, dispatch to studies/reports."""

import json
import sys
import types
from pathlib import Path

import pytest

from validation.cli import build_parser, main
from validation.run.record import RunResult

from .conftest import cli

SUBCOMMANDS = ("run", "scenes", "check", "sweep", "study", "report", "layer-law")


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


@pytest.mark.parametrize("cmd, kind", [("run", "result"), ("sweep", "sweep"), ("report", "report"),
                                       ("layer-law", "layer-law")])
def test_out_is_the_directory_written_in_every_help(cmd, kind, capsys):
    assert main([cmd, "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert f"--out DIR the {kind} directory written" in text and "DIR/.contactlab" in text


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
                         "--set", "fem.n_contact_elements=8")
    assert code == 0, err
    result = json.loads((tmp_path / "r" / "result.json").read_text())
    for label in ("p_max", "contact", "approach", "converged  yes", "time", "files", "alpha_b", "FEM"):
        assert label in out
    assert f"{result['p_max']:.6g} Pa" in out
    assert "units SI (m, Pa, N)" in out


def test_run_not_converged_exits_1_and_writes(tmp_path):
    code, out, _ = cli("run", "rough_sphere", "--out", tmp_path / "r", "--set", "bem.nodes_across=16",
                       "--set", "bem.maxiter=1", "--set", "fem.n_contact_elements=8")
    assert code == 1
    assert json.loads((tmp_path / "r" / "result.json").read_text())["converged"] is False
    assert "converged  NO" in out


def test_run_bad_input_exits_2_and_writes_nothing(tmp_path):
    code, out, err = cli("run", "hertz", "--out", tmp_path / "r", "--set", "bodies.nu1=0.7")
    assert code == 2 and "bodies.nu1" in err and out == ""
    assert not (tmp_path / "r").exists()


def test_sweep_names_its_own_option_in_a_bad_worker_count(tmp_path):
    code, _, err = cli("sweep", "hertz", "--param", "load.force", "--values", "1,2", "--workers", 0,
                       "--out", tmp_path / "s")
    assert code == 2 and err.startswith("contactlab: error: --workers = 0 is not allowed"), err
    assert not (tmp_path / "s").exists()


@pytest.mark.parametrize("argv, name", [
    (("check", "a\x00b.toml"), "SCENE = 'a\\x00b.toml'"),
    (("run", "elliptic", "--out", "o\x00ut"), "--out = 'o\\x00ut'"),
    (("sweep", "elliptic", "--param", "load.force", "--values", "1,2", "--out", "s\x00"), "--out = 's\\x00'"),
    (("report", "x\x00y"), "SCENE_OR_DIR = 'x\\x00y'"),
    (("layer-law", "s\x00.npy", "--E-star", "1e9", "--out", "law"), "SURFACE = 's\\x00.npy'"),
], ids=["check", "run", "sweep", "report", "layer-law"])
def test_a_file_argument_with_a_nul_byte_exits_2_naming_it(argv, name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = cli(*argv)
    assert code == 2 and out == "" and err == (f"contactlab: error: {name} is not allowed: it must be a file name "
                                               "without a NUL byte (no file system accepts one).\n")
    assert list(tmp_path.iterdir()) == []


def test_an_empty_out_is_refused_not_taken_for_the_default(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = cli("run", "elliptic", "--out", "", "--set", "bem.nodes_across=8")
    assert code == 2 and out == ""
    assert err == "contactlab: error: --out = '' is not allowed: it must be a file name, not empty.\n"
    assert list(tmp_path.iterdir()) == []  # not results/elliptic


def test_sweep_names_the_param_option_it_was_given(tmp_path):
    code, _, err = cli("sweep", "hertz", "--param", "nope", "--values", "1", "--out", tmp_path / "s")
    assert code == 2 and err.startswith("contactlab: error: --param = 'nope' is not allowed: it must be alpha_a")


@pytest.mark.parametrize("name", ["result.json", "summary.json"])
def test_a_result_or_sweep_file_nested_too_deep_exits_2(name, tmp_path):
    folder = tmp_path / "received"
    folder.mkdir()
    if name == "summary.json":
        (folder / "points").mkdir()
    (folder / name).write_text("[" * 100_000 + "]" * 100_000)
    code, out, err = cli("report", folder, "--out", tmp_path / "rep")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert err.startswith(f"contactlab: error: {folder / name} is not allowed: it must be a readable JSON file")


def test_run_into_foreign_directory_exits_2(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    code, _out, err = cli("run", "elliptic", "--out", tmp_path, "--set", "bem.nodes_across=16")
    assert code == 2 and "did not write (notes.txt)" in err and str(tmp_path) in err
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
    (["study", "error-time", "hertz", "--out", "x", "--quick"], "validation.studies.error_time"),
    (["study", "stability"], "validation.studies.stability"),
])
def test_study_dispatches_its_arguments(argv, module, monkeypatch, tmp_path):
    from validation.studies import save

    monkeypatch.chdir(tmp_path)
    seen = {}
    fake = types.ModuleType(module)
    fake.STEM = module.rsplit(".", 1)[1]

    def main(**kw):
        seen.update(kw)
        return save(kw["out"], "stability", {"rows": []}, status=7)

    fake.main = main
    monkeypatch.setitem(sys.modules, module, fake)
    monkeypatch.setattr("validation.report.documents.studies.study_markdown", lambda name, data: "# tables\n")
    code, out, _err = cli(*argv)
    folder = tmp_path / ("x" if "--out" in argv else f"results/{argv[1]}")
    assert code == 7 and out == "# tables\n" and (folder / "stability.md").read_text() == "# tables\n"
    assert Path(seen["out"]).parent == folder.parent  # the hidden folder assembled beside it
    assert seen["scene"] == (argv[2] if len(argv) > 2 and not argv[2].startswith("-") else None)
    assert seen["quick"] == ("--quick" in argv)


def test_report_dispatches_its_arguments_and_prints_where(monkeypatch, tmp_path):
    from pathlib import Path

    from validation.report import command
    from validation.report.render import BuiltReport

    seen = {}

    def fake(target, progress=None, **kw):
        seen["args"] = dict(kw, target=target)
        for k in range(3):
            progress(f"stage {k}", k, 3)
        out = Path(kw["out"])
        return BuiltReport(out, out / "report.html", out / "report.md", (out / "figures" / "a.svg",))

    monkeypatch.setattr(command, "build", fake)
    (tmp_path / "hertz").mkdir()
    (tmp_path / "hertz" / "result.json").write_text("{}")
    code, out, err = cli("report", tmp_path / "hertz", "--out", tmp_path / "rep", "--format", "svg", "--units",
                         "dimensionless")
    assert code == 0, err
    args = seen["args"]
    assert (args["target"], args["out"], args["fmt"], args["units"]) == (str(tmp_path / "hertz"), str(tmp_path / "rep"),
                                                                         "svg", "dimensionless")
    assert f"report written to {tmp_path / 'rep' / 'report.html'}" in out
    assert "1 figures" in out


@pytest.mark.parametrize("argv, word", [
    (["study", "error-time", "hertz", "--levels", "3"], "--levels"),  # refused, not ignored
    (["study", "stability", "--set", "bem.rtol=1e-6"], "--set"),  # studies have no scene keys
    (["report", "paper", "--bogus"], "--bogus"),
    (["check", "hertz", "--quick"], "--quick"),
    (["report", "hertz", "--format", "jpg"], "jpg"),
])
def test_unknown_options_are_refused(argv, word):
    code, out, err = cli(*argv)
    assert code == 2 and word in err and out == ""


@pytest.mark.parametrize("argv, word", [
    (["report", "hertz", "--quick"], "--quick"),  # paper only
    (["report", "paper", "--units", "scene"], "--units"),  # the paper report is normalised
    (["report", "paper", "--set", "load.force=2"], "--set"),  # scenes only
])
def test_options_that_do_not_apply_to_the_target_are_refused(argv, word, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = cli(*argv)
    assert code == 2 and word in err and out == ""
    assert list(tmp_path.iterdir()) == []  # nothing ran, nothing written


def test_report_of_a_scene_applies_set(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = cli("report", "elliptic", "--out", tmp_path / "e", "--set", "bem.nodes_across=12",
                         "--set", "load.force=50.0")
    assert code == 0, err
    result = json.loads((tmp_path / "results" / "elliptic" / "result.json").read_text())
    assert result["force"] == pytest.approx(50.0) and result["overrides"] == ["bem.nodes_across=12",
                                                                              "load.force=50.0"]
    assert f"report written to {tmp_path / 'e' / 'report.html'}" in out


def test_report_help_describes_quick_and_points_to_the_measured_times(capsys):
    import re

    assert main(["report", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "a_H/c = 8" in text and "docs/performance.md" in text
    assert not re.search(r"\d\s*(s|ms|min)\b", text), "machine timings belong in docs/performance.md"
    assert "sweep" in text and "--format" in text and "--units" in text


def test_parser_is_buildable_without_heavy_imports():
    assert build_parser().prog == "contactlab"


def test_report_progress_bar_shows_the_stages_on_stderr(monkeypatch):
    import io

    from validation.cli.common import ProgressBar

    err = io.StringIO()
    monkeypatch.setattr(sys, "stderr", err)
    bar = ProgressBar("report", "stage", False)
    for k, stage in enumerate(("layer laws", "parameter sweeps", "figures")):
        bar(stage, k, 3)
    bar("done", 3, 3)
    bar.close()
    text = err.getvalue()
    assert "layer laws" in text and "parameter sweeps" in text and "2/3" in text


@pytest.fixture
def core_install(monkeypatch):
    """gmsh and scikit-fem missing, as in a core install (validation.extras.missing answers so)."""
    from validation import extras

    real = extras.missing
    monkeypatch.setattr(extras, "missing", lambda extra: [("gmsh", "not installed"), ("skfem", "not installed")]
                        if extra == "fem" else real(extra))
    monkeypatch.setitem(sys.modules, "skfem", None)  # an import of the FEM would fail
    monkeypatch.setitem(sys.modules, "gmsh", None)


def test_no_fem_runs_a_builtin_scene_on_a_core_install(tmp_path, core_install):
    small = ["--set", "bem.nodes_across=16"]
    code, out, err = cli("run", "hertz", "--out", tmp_path / "fem", *small)
    assert code == 2 and "install contactlab[fem]" in err and not (tmp_path / "fem").exists()
    code, out, err = cli("run", "hertz", "--no-fem", "--out", tmp_path / "r", *small)
    assert code == 0, err
    result = RunResult.read(tmp_path / "r" / "result.json")
    assert result.converged and result.fem is None and result.analytic.kind == "hertz"
    assert "FEM reference skipped" in out and "FEM reference skipped" in " ".join(result.messages)
    assert "[fem]" not in (tmp_path / "r" / "scene.toml").read_text()
    code, out, err = cli("sweep", "hertz", "--no-fem", "--param", "load.force", "--values", "50,100",
                         "--workers", "1", "--out", tmp_path / "s", *small)
    assert code == 0, err
    code, out, err = cli("check", "hertz")
    assert code == 2 and "--no-fem" in err


def test_run_summary_prints_any_value_of_a_result():
    from dataclasses import replace

    from validation.cli.run import _summary
    from validation.run import run_scene

    base = run_scene("hertz", overrides=["bem.nodes_across=12", "fem.n_contact_elements=6"])
    body = replace(base.stress.bodies["body1"], location_of_max=[0.0, 0.0, 1e308], max_von_mises=None,
                   max_tresca=None)
    result = replace(base, p_max=None, fem=replace(base.fem, p_max=0.0), analytic=replace(base.analytic, p_max=None),
                     contact_area=1e308, approach=None, kkt_residual=None, converged=False,
                     wall_time_s_by_part={"bem": 0.5, "fem": None}, messages=["BEM did not converge"],
                     stress=replace(base.stress, bodies={"body1": body}), files={"result": "result.json"})
    text = _summary(result, "out")
    assert "p_max      - Pa   (FEM 0)   (hertz -)" in text and "approach - m" in text
    assert "area 1e+308 m^2" in text and "at depth 1e+308 m" in text and "KKT residual -" in text


def test_a_newton_runs_history_holds_its_counts_beside_its_lists(builtin_runs):
    history = builtin_runs["paper_root"]["result"].bem.history
    steps = len(history["step"])
    assert steps >= 1 and len(history["residual"]) == steps + 1
    assert history["inner_missed"] == 0 and history["inner_worst"] == 0.0
    assert isinstance(history["closure_moves"], int) and 1 <= history["closure_moves"] <= steps
