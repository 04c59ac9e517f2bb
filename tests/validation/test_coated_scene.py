"""Coatings in scenes: ``[bodies] coating1/coating2``, the run and result.json, sweeps over a coating, refusals."""

import json
import math

import numpy as np
import pytest

import bem
from validation.run import run_scene
from validation.report.documents.sweep import report_sweep_dir
from validation.run.runner import domain_of
from validation.run.sweep import run_sweep, sweep_points
from validation.scene import SceneError, parse_scene
from validation.scene.load import read_toml
from validation.scene.source import builtin_path

COATING = {"thickness": 1e-5, "E": 2e10, "nu": 0.3}


def _raw(coating1=COATING, **bodies):
    """The built-in rough cell at 32 x 32 nodes on coated steel (body 1) against steel."""
    raw = read_toml(builtin_path("rough_flat"))
    raw["gap"].update(grid=32)
    raw["bem"]["cell_nodes"] = 32
    raw.pop("report")
    raw["bodies"] = {"E1": 210e9, "nu1": 0.3, "E2": 210e9, "nu2": 0.3, **bodies}
    if coating1 is not None:
        raw["bodies"]["coating1"] = dict(coating1)
    return raw


def test_a_coated_scene_runs_the_coated_operator_and_records_the_coating(tmp_path):
    raw = _raw()
    scene = parse_scene(raw)
    assert scene.coatings == {"coating1": COATING, "coating2": None}
    run_scene(scene, tmp_path / "run")
    result = json.loads((tmp_path / "run" / "result.json").read_text())
    assert result["bem"]["coating1"] == COATING and result["bem"]["coating2"] is None
    assert result["converged"] and result["kkt_residual"] <= 1e-10
    # the same problem through bem.solve directly: the run solved the coated contact
    domain = domain_of(scene, [])
    kw = dict(domain=domain.bem_domain, E1=210e9, nu1=0.3, E2=210e9, nu2=0.3,
              mean_pressure=raw["load"]["mean_pressure"])
    direct = bem.solve(domain.gap, coating1=bem.Coating(**COATING), **kw)
    assert result["p_max"] == pytest.approx(direct.p_max, rel=1e-9)
    plain = bem.solve(domain.gap, **kw)
    assert abs(plain.p_max / direct.p_max - 1) > 1e-3  # the coating changes the answer


def test_a_sweep_over_coating_thickness_and_modulus(tmp_path):
    base = _raw()
    _, key, points = sweep_points(base, "bodies.coating1.thickness", [5e-6, 2e-5])
    assert key == "bodies.coating1.thickness"
    assert [p.scene.coatings["coating1"]["thickness"] for p in points] == [5e-6, 2e-5]
    summary = run_sweep(base, tmp_path / "sweep", parameter="bodies.coating1.E", values=[2e10, 1e11], workers=1)
    assert summary["failed"] == [] and len(summary["points"]) == 2
    p_max = [row["p_max"] for row in summary["points"]]
    assert p_max[1] > p_max[0]  # a stiffer coating carries the asperities on fewer, harder spots
    point = json.loads((tmp_path / "sweep" / summary["points"][1]["file"]).read_text())
    assert point["result"]["bem"]["coating1"] == {**COATING, "E": 1e11}
    built = report_sweep_dir(tmp_path / "sweep", tmp_path / "report")
    assert r"bodies.coating1.E \[MPa\]" in built.markdown.read_text()  # the swept modulus in the report's pressure unit


@pytest.mark.parametrize("change, message", [
    ({"E_star": 1e11}, r"bodies.coating1 is not allowed with bodies.E_star"),
    ({"coating1": {"thickness": 1e-5, "E": 2e10}}, r"bodies.coating1.nu is missing|give thickness"),
    ({"coating1": {"thickness": -1e-5, "E": 2e10, "nu": 0.3}}, r"bodies.coating1.thickness = -1e-05 is not allowed"),
    ({"coating1": {"thickness": 1e-5, "E": 2e10, "nu": 0.6}}, r"bodies.coating1.nu = 0.6 is not allowed"),
    ({"coating1": {"thickness": 1e-5, "E": 2e10, "nu": 0.3, "mu": 1.0}}, r"bodies.coating1.mu = 1.0 is not allowed"),
    ({"coating2": 3.0}, r"bodies.coating2 = 3.0 is not allowed: it must be a table"),
])
def test_bad_coatings_are_refused_naming_the_key(change, message):
    raw = _raw()
    if "E_star" in change:
        raw["bodies"] = {"E_star": 1e11, "coating1": COATING}
    else:
        raw["bodies"].update(change)
    with pytest.raises(SceneError, match=message):
        parse_scene(raw)


def test_a_coated_scene_refuses_the_homogeneous_closed_forms_and_takes_stress():
    raw = read_toml(builtin_path("hertz"))
    raw.pop("fem", None)
    raw["bodies"]["coating1"] = dict(COATING)
    raw.setdefault("analytic", {"kind": "hertz"})
    with pytest.raises(SceneError, match=r"analytic = \{\.\.\.\} is not allowed with bodies.coating1"):
        parse_scene(raw)
    raw.pop("analytic")
    assert parse_scene(raw).stress["bodies"] == ["body1", "body2"]  # bem.coated_stress (test_coated_stress_scene.py)


def test_the_cli_sets_a_coating(tmp_path):
    from .conftest import cli

    raw = _raw(coating1=None)
    path = tmp_path / "scene.toml"
    import tomli_w

    path.write_text(tomli_w.dumps(raw))
    code, out, _ = cli("run", str(path), "--out", str(tmp_path / "run"), "--set", "bodies.coating1.thickness=1e-5",
                       "--set", "bodies.coating1.E=2e10", "--set", "bodies.coating1.nu=0.3")
    assert code == 0, out
    result = json.loads((tmp_path / "run" / "result.json").read_text())
    assert result["bem"]["coating1"] == COATING
    assert math.isfinite(result["p_max"]) and np.isfinite(result["approach"])


def _half_space_coated():
    import inspect

    return "bodies" in inspect.signature(bem.InfluenceOperator).parameters


@pytest.mark.skipif(not _half_space_coated(), reason="the coated half-space kernel (bem.InfluenceOperator(bodies=)) "
                                                     "is not in this build")
def test_a_coated_hertz_scene_agrees_with_the_coated_fem_reference(tmp_path):
    """The built-in Hertz scene on a coated body 1 (t = 20 um, E_c = E_s / 10): the BEM's coated half-space
    and the FEM's meshed coating, both through the runner."""
    raw = read_toml(builtin_path("hertz"))
    for section in ("analytic", "stress", "report"):
        raw.pop(section, None)
    raw["bodies"]["coating1"] = {"thickness": 2e-5, "E": 2.1e10, "nu": 0.3}
    scene = parse_scene(raw, overrides=["bem.nodes_across=16", "fem.n_contact_elements=8"])
    run_scene(scene, tmp_path / "run")
    result = json.loads((tmp_path / "run" / "result.json").read_text())
    assert result["bem"]["coating1"] == raw["bodies"]["coating1"] and result["converged"]
    comparison = result["comparison"]["bem_vs_fem"]
    assert abs(comparison["peak_rel"]) < 5e-3  # measured 1.4e-3 (coarse: 16 nodes, 8 elements across)
    assert abs(comparison["approach_rel"]) < 2e-3  # measured 4.5e-4
    plain = bem.solve(scene.gap, step=result["bem"]["step"], extent=result["bem"]["extent"], E1=210e9, nu1=0.3,
                      E2=210e9, nu2=0.3, force=raw["load"]["force"])
    assert abs(plain.p_max / result["p_max"] - 1) > 0.05  # the coating changes the answer
