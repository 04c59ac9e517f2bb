"""The scripts of docs/examples run, and say what they claim (examples as tests)."""

import math
import runpy
from pathlib import Path

import numpy as np
import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"


def run_example(name):
    """Load ``docs/examples/<name>.py`` (as a module, not as ``__main__``) and call its ``main()``."""
    return runpy.run_path(str(EXAMPLES / f"{name}.py"), run_name="example")["main"]()


def test_every_example_is_tested():
    tested = {"hertz", "paper_problem", "user_gap", "measured_layer", "sweep", "paper_report"}
    assert {p.stem for p in EXAMPLES.glob("*.py")} == tested  # paper_report: tests/validation/test_report_paper.py


def test_hertz_example_matches_the_closed_form(capsys):
    out = run_example("hertz")
    errors = out["errors"]
    assert out["result"].converged
    assert abs(errors["p_max"]) < 2e-4 and abs(errors["approach"]) < 2e-4
    assert abs(errors["contact_radius"]) < 2 * out["result"].step / out["hertz"].contact_radius  # within two steps
    assert "relative errors" in capsys.readouterr().out


def test_paper_problem_example_orders_the_layers_as_the_paper():
    out = run_example("paper_problem")
    peaks = out["peaks"]
    assert all(res.converged for res in out["results"].values())
    assert abs(peaks["smooth"] - 1) < 2e-3  # smooth paraboloids: Hertz
    # a layer lowers the peak; the elastic-rigid layer stops closing at p_cr, so it lowers it least
    assert peaks["smooth"] > peaks["elastic_rigid"] > peaks["root"] > peaks["linear"]
    assert out["root_variable_compliance"].converged and out["agreement"] < 1e-6


def test_user_gap_example_runs_the_callable():
    out = run_example("user_gap")
    wavy, smooth = out["wavy"], out["smooth"]
    assert wavy.converged and smooth.converged
    assert math.isclose(wavy.force, 100.0, rel_tol=1e-9)
    assert out["peak_ratio"] > 1.2  # the waviness concentrates the load on its crests
    assert wavy.contact_area < smooth.contact_area


def test_measured_layer_example_follows_the_table():
    out = run_example("measured_layer")
    rough, smooth, layer = out["rough"], out["smooth"], out["layer"]
    assert rough.converged
    assert rough.p_max < 0.9 * smooth.p_max and rough.contact_radius > 1.2 * smooth.contact_radius
    # the closure at every node is the interpolated law at its pressure, and the table is honoured
    np.testing.assert_allclose(rough.closure, layer.w(rough.p), rtol=1e-12, atol=0)
    np.testing.assert_allclose(layer.w(np.array([1e8, 4e8])), [5.493e-07, 1.099e-06], rtol=1e-12)


def test_sweep_example_scales_as_hertz(tmp_path):
    summary = runpy.run_path(str(EXAMPLES / "sweep.py"), run_name="example")["main"](tmp_path / "sweep")
    rows = summary["points"]
    assert [r["status"] for r in rows] == ["converged"] * 4
    for row in rows:
        expected = rows[0]["p_max"] * (row["value"] / rows[0]["value"]) ** (1 / 3)
        assert row["p_max"] == pytest.approx(expected, rel=1e-3)
    assert (tmp_path / "sweep" / "summary.csv").is_file()
    assert len(list((tmp_path / "sweep" / "points").glob("point-*.json"))) == 4
