"""Scenes hand the solver options to the BEM's own check; calibrations use the robust solver."""

import re
import tomllib
from importlib import resources

import pytest

import bem
from validation.run import runner
from validation.run.calibrate import CalibrationError
from validation.scene import SceneError, load_scene

from .conftest import cli


def _scene(name, drop=("fem", "sweep", "report")):
    raw = tomllib.loads(resources.files("validation").joinpath("scenes", f"{name}.toml").read_text())
    return {k: v for k, v in raw.items() if k not in drop}


def test_check_refuses_an_option_the_solver_that_runs_does_not_take():
    code, _, err = cli("check", "hertz", "--set", 'bem.method="augmented_gap"', "--set", "bem.relaxation=0.5")
    assert code == 2
    assert "bem.relaxation = 0.5 is not allowed" in err and "Kalker's QP" in err


@pytest.mark.parametrize("override, key", [("bem.eps_p=1e-8", "bem.eps_p"),
                                           ("bem.inner_maxiter=0", "bem.inner_maxiter"),
                                           ("bem.relaxation=2.0", "bem.relaxation")])
def test_scene_solver_options_are_checked_per_method(override, key):
    with pytest.raises(SceneError, match=key.replace(".", r"\.")):
        load_scene(_scene("paper_root"), overrides=['bem.method="augmented_gap"' if "relax" in key else
                                                    'bem.method="newton"', override])


def test_scene_solver_options_reach_the_solver():
    scene = load_scene(_scene("paper_root"), overrides=['bem.method="augmented_gap"', "bem.relaxation=0.5",
                                                        "bem.eps_p=1e-9"])
    assert scene.bem["relaxation"] == 0.5 and scene.bem["eps_p"] == 1e-9


def test_calibration_does_not_depend_on_the_method():
    """alpha_b / lam_over_cnn calibrations use Newton even when the scene asks for a paper method."""
    lam = {}
    for method in ("newton", "augmented_gap"):
        out = runner.execute_scene(load_scene(_scene("paper_root"), overrides=[f'bem.method="{method}"']))
        lam[method] = out.result.layer["parameters"]["lam"]
        assert out.result.layer["reference_solves"] >= 1
    assert lam["augmented_gap"] == pytest.approx(lam["newton"], rel=1e-12)


def test_a_calibration_that_fails_stops_the_run(monkeypatch):
    real = bem.solve

    def failing(*args, **kw):
        res = real(*args, **kw)
        if kw["layer"].is_linear:  # the reference solve of the calibration
            res.converged, res.message = False, "forced failure"
        return res

    monkeypatch.setattr(runner.bem, "solve", failing)
    with pytest.raises(CalibrationError, match="forced failure"):
        runner.execute_scene(load_scene(_scene("paper_root")))


@pytest.mark.parametrize("method, note", [("augmented_gap", True), ("variable_compliance", True), ("newton", False)])
@pytest.mark.parametrize("name, size", [("hertz", "bem.nodes_across=16"), ("rough_flat", "bem.cell_nodes=32")])
def test_a_paper_method_on_a_smooth_scene_notes_the_solver_that_ran(method, note, name, size):
    """The same note on both domains: a region of the half-space and a periodic cell."""
    out = runner.execute_scene(load_scene(name, overrides=[f'bem.method="{method}"', size]))
    assert out.result.method == "kalker"
    notes = [m for m in out.result.messages if "ran as Kalker's QP" in m]
    assert notes == ([f"bem.method = {method!r} ran as Kalker's QP ('kalker'): the scene has no layer, so the "
                      "problem is a QP and the QP solves it directly."] if note else [])


def test_the_node_limit_is_one_rule_for_the_api_and_the_scenes():
    """bem.solve and a scene refuse the same region, before building it, each naming its own key."""
    step = 1.25e-4
    limit = bem.checks.max_nodes("the candidate region")
    assert bem.lattice.node_count(step, 0.5) > limit >= bem.lattice.node_count(3 * step, 0.5)
    rule = r"is not allowed: the candidate region would hold 7\.39e\+07 nodes \(limit " + re.escape(f"{limit:.3g}")
    with pytest.raises(bem.InputError, match="^step = 0.000125 " + rule):
        bem.solve(bem.gaps.Paraboloid(1.0), E_star=1.0, force=0.01, step=step, extent=0.5)
    raw = {"scene": {"name": "t"}, "bodies": {"E_star": 1.0}, "gap": {"type": "paraboloid", "R": 1.0},
           "load": {"force": 0.01}, "bem": {"step": step, "extent": 0.5}}
    with pytest.raises(SceneError, match="^bem.step = 0.000125 " + rule):
        load_scene(raw)
    raw["bem"]["step"] = 3 * step
    assert load_scene(raw).bem["n_nodes"] == bem.lattice.node_count(3 * step, 0.5)
