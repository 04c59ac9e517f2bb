"""The error-time and stability studies in quick mode, and their classification rules."""

import dataclasses
import json
import math

import numpy as np
import pytest

import bem
from bem.checks import InputError
from bem.reference import hertz_sphere
from validation.report.documents.studies import study_markdown
from validation.studies import error_time, stability
from validation.studies.error_time import ErrorTimeRow, ErrorTimeStudy, run_error_time
from validation.run import execute_scene
from validation.studies.problems import get_problem, methods, stability_cases
from validation.studies.stability import STATUSES, StabilityFailure, classify, run_stability

from .conftest import cli

LADDER = error_time.LADDERS["quick"]


@pytest.fixture(scope="module")
def et():
    return run_error_time(quick=True)


@pytest.fixture(scope="module")
def st():
    return run_stability(quick=True)


def _rows(study, problem, method):
    return [r for r in study.rows if r.problem == problem and r.method == method]


def test_error_time_has_rows_for_every_method_and_level(et):
    assert et.problems == ["hertz", "paper-root"]
    expected = {"hertz": ("kalker", "fem"), "paper-root": ("newton", "augmented_gap", "variable_compliance", "fem")}
    for problem, methods in expected.items():
        for method in methods:
            levels = LADDER["fem"] if method == "fem" else LADDER["bem"]
            assert sorted({r.resolution for r in _rows(et, problem, method)}) == list(levels), (problem, method)
    # every augmented-gap attempt is a row; the failures say so
    for r in _rows(et, "paper-root", "augmented_gap"):
        assert r.relaxation is not None
        assert r.converged or r.message
    for r in et.rows:
        assert r.converged == (r.solver_status == "converged")
        assert r.wall_time_s > 0 and r.n > 0
        assert r.error_l2 is not None and math.isfinite(r.error_l2)


def test_error_time_errors_decrease_with_resolution(et):
    for problem, method in (("hertz", "kalker"), ("paper-root", "newton"), ("paper-root", "variable_compliance")):
        rows = sorted(_rows(et, problem, method), key=lambda r: r.resolution)
        assert all(r.converged for r in rows)
        for key in ("error_l2", "error_peak"):
            errs = [getattr(r, key) for r in rows]
            assert all(b < a for a, b in zip(errs, errs[1:])), (problem, method, key, errs)
    for problem in ("hertz", "paper-root"):
        rows = sorted(_rows(et, problem, "fem"), key=lambda r: r.resolution)
        assert all(r.converged for r in rows)
        peaks = [r.error_peak for r in rows]
        assert all(b < a for a, b in zip(peaks, peaks[1:])), (problem, peaks)
        assert rows[-1].error_l2 < 0.5 * rows[0].error_l2  # the L2 error at the Hertz edge is erratic


def test_error_time_hertz_error_is_the_nodal_error_against_the_closed_form(et):
    H = hertz_sphere(1.0, 1.0, force=1.0)
    row = next(r for r in _rows(et, "hertz", "kalker") if r.resolution == 20)
    res = bem.solve(bem.gaps.Paraboloid(1.0), E_star=1.0, force=1.0, step=2 * H.contact_radius / 20, extent=1.25 * H.contact_radius)
    exact = H.pressure(np.hypot(res.x, res.y))
    assert row.n == res.p.size
    assert row.error_l2 == pytest.approx(np.linalg.norm(res.p - exact) / np.linalg.norm(exact), rel=1e-9)
    assert row.error_peak == pytest.approx(abs(res.p.max() / H.p_max - 1), rel=1e-9)


def test_error_time_fine_reference_is_richardson_checked(et):
    ref = et.references["paper-root"]
    assert ref["kind"] == "bem-newton" and ref["resolution"] == 4 * max(LADDER["bem"]) and ref["converged"]
    assert 1.5 < ref["order_peak"] < 2.5 and 1.5 < ref["order_l2"] < 2.5
    best = min(r.error_l2 for r in et.rows if r.problem == "paper-root" and r.solver == "bem" and r.converged)
    assert ref["error_l2_estimate"] < 0.2 * best
    assert et.references["hertz"]["kind"] == "analytic"


def test_first_to_reach_on_constructed_rows():
    def row(method, err, t, conv=True, n=10):
        return ErrorTimeRow("p", "bem", method, n, 100, err, err, t, 1, conv)

    study = ErrorTimeStudy(rows=[row("a", 5e-3, 2.0), row("b", 8e-3, 1.0), row("c", 5e-4, 3.0),
                                 row("d", 1e-4, 0.1, conv=False), row("e", 2e-2, 0.05),
                                 row("f", 9e-3, 0.5), row("f", 2e-2, 0.6, n=20), row("f", 1e-4, 0.7, n=40, conv=False)])
    assert study.first_to_reach(1e-2).method == "b"  # f at 10 is lucky: f at 20 is above the target
    assert study.first_to_reach(1e-2, sustained=False).method == "f"
    assert study.first_to_reach(1e-3).method == "c"
    assert study.first_to_reach(1e-5) is None
    assert study.first_to_reach(1e-2, metric="error_peak").method == "b"
    with pytest.raises(InputError, match="metric"):
        study.first_to_reach(1e-2, metric="speed")
    two = ErrorTimeStudy(rows=study.rows + [dataclasses.replace(study.rows[0], problem="q")])
    with pytest.raises(InputError, match="problem"):
        two.first_to_reach(1e-2)
    assert two.first_to_reach(1e-2, problem="q").problem == "q"


def test_first_to_reach_on_the_study(et):
    for problem in et.problems:
        for tol in (1e-2, 1e-3):
            best = et.first_to_reach(tol, problem=problem, sustained=False)
            ok = [r for r in et.rows if r.problem == problem and r.converged and r.error_l2 <= tol]
            if not ok:
                assert best is None
                continue
            assert best.wall_time_s == min(r.wall_time_s for r in ok)
            kept = et.first_to_reach(tol, problem=problem)
            assert kept is None or (kept in ok and kept.wall_time_s >= best.wall_time_s)
    text = study_markdown("error_time.json", json.loads(json.dumps(et.to_dict())))
    assert "reaches 1 % and 0.1 % first" in text and "augmented_gap (omega=1)" in text
    assert "variable_compliance" in text
    assert text.count("| bem | newton |") == len(LADDER["bem"])


def test_error_time_json_and_main(et, tmp_path, capsys, monkeypatch):
    path = et.to_json(tmp_path / "sub" / "et.json")
    data = json.loads(path.read_text())
    assert len(data["rows"]) == len(et.rows) and set(data["first_to_reach"]) == {"hertz", "paper-root"}
    assert [p.name for p in path.parent.iterdir()] == ["et.json"]  # no temporary file left
    run = error_time.main(scene="hertz", out=tmp_path / "cli", quick=True)
    assert run.status == 0 and capsys.readouterr().out == ""  # the library prints nothing
    written = json.loads((tmp_path / "cli" / "error_time.json").read_text())
    assert written == run.data and {r["problem"] for r in written["rows"]} == {"hertz"}
    monkeypatch.setattr(error_time, "run_error_time", lambda *a, **kw: et)
    code, out, err = cli("study", "error-time", "hertz", "--quick", "--out", tmp_path / "cmd")
    assert code == 0 and "| bem | kalker |" in out, err
    monkeypatch.undo()
    assert (tmp_path / "cmd" / "error_time.md").read_text().startswith("# Error against run time")
    with pytest.raises(InputError, match="scene"):
        error_time.main(scene="nope", out=tmp_path, quick=True)


def test_stability_quick_has_no_nan_and_no_wrong_answer(st):
    assert st.wrong() == [] and st.check() is st
    names = [c["scene"]["title"] for c, _ in stability_cases(quick=True)]
    for case, _ in stability_cases(quick=True):
        rows = [r for r in st.rows if r.case == case["scene"]["title"]]
        assert {r.method for r in rows if r.solver == "bem"} == set(methods(case))
        assert any(r.solver == "fem" for r in rows) == ("fem" in case)
    assert {r.case for r in st.rows} == set(names)
    for r in st.rows:
        assert r.status in STATUSES
        if r.status == "converged":
            assert r.solver_status == "converged"
        if r.status == "reported failure" and r.solver_status is not None:
            assert r.solver_status != "converged"
        assert r.kkt_residual is None or math.isfinite(r.kkt_residual)
        if r.status == "reported failure":
            assert r.message and (r.kkt_residual is None or r.kkt_residual > 1e-7)
        if r.status == "converged" and r.solver == "bem":
            assert r.kkt_residual <= 1e-7
        if r.reference == "Newton, same lattice" and r.status == "converged":
            assert r.error_vs_reference <= 1e-6
    newton = [r for r in st.rows if r.method == "newton"]
    assert all(r.status == "converged" for r in newton)
    # the augmented gap method stalls or diverges on soft layers and must say so
    assert any(r.method == "augmented_gap" and r.status == "reported failure"
               and r.solver_status in ("stalled", "diverged") for r in st.rows)
    json.dumps(st.to_dict(), allow_nan=False)
    assert "| bem newton |" in study_markdown("stability.json", json.loads(json.dumps(st.to_dict())))


def test_classify_rules():
    res = execute_scene(get_problem("hertz"), overrides={"bem.method": "kalker", "bem.nodes_across": 10}).bem
    assert classify(res, converged=True, error=1e-9, tolerance=1e-6)[0] == "converged"
    assert classify(res, converged=True, error=None, tolerance=None)[0] == "converged"
    assert classify(res, converged=True, error=1e-3, tolerance=1e-6)[0] == "wrong"
    assert classify(res, converged=False, error=1e-3, tolerance=1e-6)[0] == "reported failure"
    assert classify(None, converged=False, error=None, tolerance=None)[0] == "reported failure"
    nan = dataclasses.replace(res, p=np.where(res.p > 0, np.nan, 0.0))
    assert classify(nan, converged=False, error=None, tolerance=None)[0] == "wrong"
    assert classify(nan, converged=True, error=None, tolerance=None)[0] == "wrong"


def _case():
    return next(c for c in stability_cases(quick=True) if c[0]["scene"]["title"] == "linear k=1000")


def test_a_wrong_result_called_converged_makes_the_study_raise(monkeypatch):
    real = bem.solve

    def fake(*args, method="newton", **kw):
        res = real(*args, method=method, **kw)
        if method == "variable_compliance":
            return dataclasses.replace(res, p=res.p * 1.01, p_max=res.p_max * 1.01, converged=True)
        return res

    monkeypatch.setattr(bem, "solve", fake)
    with pytest.raises(StabilityFailure, match="variable_compliance") as info:
        run_stability([_case()])
    (row,) = info.value.rows
    assert row.status == "wrong" and row.error_vs_reference == pytest.approx(0.01, rel=1e-6)
    study = run_stability([_case()], check=False)
    assert [r.method for r in study.wrong()] == ["variable_compliance"]


def test_a_nan_result_makes_the_study_raise_even_when_not_converged(monkeypatch):
    real = bem.solve

    def fake(*args, method="newton", **kw):
        res = real(*args, method=method, **kw)
        if method == "kalker":
            p = res.p.copy()
            p[0] = np.nan
            return dataclasses.replace(res, p=p, converged=False, status="maxiter")
        return res

    monkeypatch.setattr(bem, "solve", fake)
    with pytest.raises(StabilityFailure, match="kalker"):
        run_stability([_case()])


def test_stability_main_writes_then_fails(monkeypatch, tmp_path, st):
    bad = dataclasses.replace(st.rows[0], status="wrong", error_vs_reference=0.5, tolerance=1e-6)
    study = stability.StabilityStudy(rows=[bad] + st.rows[1:], settings=st.settings)
    monkeypatch.setattr(stability, "run_stability", lambda **kw: study)
    code, out, err = cli("study", "stability", "--quick", "--out", tmp_path)
    assert code == 1 and "wrong outcome(s) in the stability study" in err and "Traceback" not in err
    assert json.loads((tmp_path / "stability.json").read_text())["counts"]
    assert "## Stability" in out and "## Stability" in (tmp_path / "stability.md").read_text()
    monkeypatch.setattr(stability, "run_stability", lambda **kw: st)
    assert stability.main(out=tmp_path, quick=True).status == 0
