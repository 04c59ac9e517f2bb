"""The scripts of docs/examples run, and say what they claim (examples as tests)."""

import math
import re
import runpy
from pathlib import Path

import numpy as np
import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"


def run_example(name):
    """Load ``docs/examples/<name>.py`` (as a module, not as ``__main__``) and call its ``main()``."""
    return runpy.run_path(str(EXAMPLES / f"{name}.py"), run_name="example")["main"]()


def test_every_example_is_tested():
    tested = {"hertz", "paper_problem", "user_gap", "measured_layer", "sweep", "paper_report", "rough_walkthrough"}
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


def _walkthrough_blocks():
    """``[(language, text)]`` of the code blocks of docs/rough.md's walk-through."""
    text = (EXAMPLES.parent / "rough.md").read_text()
    section = text[text.index("\n## A walk-through"):]
    return re.findall(r"```(\w+)\n(.*?)```", section, re.S)


@pytest.mark.slow
def test_rough_walkthrough_runs_the_commands_of_its_page(tmp_path):
    """The commands and the scene of docs/rough.md's walk-through are the script's, they run, the output
    the page quotes is theirs, and the macro contact behaves as a softening layer must."""
    pytest.importorskip("SurfaceTopography")
    pytest.importorskip("matplotlib")
    from bem.reference import hertz_sphere
    from bem.rough import read_layer_law

    script = runpy.run_path(str(EXAMPLES / "rough_walkthrough.py"), run_name="example")
    blocks = _walkthrough_blocks()
    commands = [line for lang, block in blocks if lang == "bash" for line in block.splitlines()
                if line.startswith("contactlab ")]
    assert commands == script["COMMANDS"]
    assert [block for lang, block in blocks if lang == "toml"] == [script["SCENE"]]

    out = script["main"](tmp_path / "work", tmp_path / "figures")
    printed = "\n".join(out["printed"].values())
    for lang, block in blocks:
        if lang == "text":
            for line in block.splitlines():
                assert line in printed, f"docs/rough.md quotes {line!r}, which the commands do not print"
    for path in out["figures"]:
        assert 10_000 < path.stat().st_size < 400_000, path

    removed, kept = (read_layer_law(tmp_path / "work" / f / "layer_law.toml") for f in ("law", "law_spikes"))
    assert removed.preparation["spikes_removed"] and not kept.preparation["spikes_removed"]
    assert removed.stats.rms_height < 0.5 * kept.stats.rms_height  # the spikes carry most of the rms height
    p = np.geomspace(1e5, 9e8, 30)
    assert (kept.law.w(p) > removed.law.w(p)).all()  # the particles add closure at every pressure

    R, E_star, P = 1.0, 115.4e9, 1.0
    a = (3 * P * R / (4 * E_star)) ** (1 / 3)  # Hertz's smooth ball, written out here
    assert hertz_sphere(R, E_star, force=P).contact_radius == pytest.approx(a, rel=1e-12)
    p0 = 3 * P / (2 * math.pi * a**2)
    ball, spikes = out["results"]["ball"], out["results"]["ball_spikes"]
    for res in (ball, spikes):
        assert res["converged"] and res["force"] == pytest.approx(P, rel=1e-9)
    # a compliant layer spreads the load: lower peak, wider contact, larger approach; more so the softer law
    assert spikes["p_max"] < ball["p_max"] < p0
    assert a < ball["contact_radius"] < spikes["contact_radius"]
    assert a**2 / R < ball["approach"] < spikes["approach"]
    # the closure at the centre is the law's at the local pressure, inside its data
    profile = ball["profile"]
    centre = int(np.argmin(np.abs(np.array(profile["x"]))))
    assert profile["closure"][centre] == pytest.approx(float(removed.law.w(profile["p"][centre])), rel=1e-9)
    assert ball["p_max"] < removed.mean_pressure[-1]
