"""The typed run result (validation.run.record.RunResult): written by the runner, read back by the report.

A result reads back equal to the one written; a file of another schema, with a missing or an
unknown field, is refused with a message naming the file, the field or the schema.
"""

import json
import re
import shutil

import numpy as np
import pytest

from validation.report.documents.results import load_results, results_of
from validation.report.documents.sections import run_sections
from validation.run import execute_scene, write_outputs
from validation.run.record import SCHEMA, ResultFileError, RunResult

from .conftest import cli

SMALL = ["bem.nodes_across=12", "fem.n_contact_elements=6", "stress.n_depths=4"]


@pytest.fixture(scope="module")
def hertz_run(tmp_path_factory):
    """A small hertz run (BEM, FEM, closed form, comparison, stresses) and its written result directory."""
    outcome = execute_scene("hertz", overrides=SMALL)
    out = tmp_path_factory.mktemp("record") / "hertz"
    write_outputs(outcome, out)
    return outcome, out


def _copy(run_dir, tmp_path):
    d = tmp_path / "run"
    shutil.copytree(run_dir, d)
    return d, json.loads((d / "result.json").read_text())


def test_a_result_reads_back_equal_to_the_one_written(hertz_run, tmp_path):
    outcome, _ = hertz_run
    path = outcome.result.write(tmp_path)
    assert path == tmp_path / "result.json"
    back = RunResult.read(path)
    assert back == outcome.result
    assert json.loads(path.read_text())["schema"] == SCHEMA
    assert RunResult.from_json(back.to_json()) == back


def test_the_written_result_holds_the_solvers_numbers(hertz_run):
    outcome, out = hertz_run
    r = RunResult.read(out / "result.json")
    bem, fem, ref = outcome.bem, outcome.fem, outcome.analytic
    assert (r.p_max, r.force, r.approach, r.contact_area) == (bem.p_max, bem.force, bem.approach, bem.contact_area)
    assert r.contact_radius == bem.contact_radius and r.bem.n_nodes == bem.p.size
    assert r.bem.n_contact == np.count_nonzero(bem.p > 0) and r.iterations == bem.iterations
    assert r.fem.edge_radius == fem.edge_radius and r.fem.p_max == fem.p_max
    assert r.fem_profile.r == fem.r.tolist() and r.fem_profile.p == fem.p.tolist()
    assert r.analytic.kind == "hertz" and r.analytic.p_max == ref.p_max and r.analytic.a is None
    # the BEM radius sqrt(A / pi) against the FEM's interpolated edge, against Hertz's radius
    assert r.comparison.bem_vs_fem.edge_radius_rel == pytest.approx(bem.contact_radius / fem.edge_radius - 1)
    assert r.comparison.bem_vs_fem.contact_radius_rel is None
    assert r.comparison.bem_vs_analytic.contact_radius_rel == pytest.approx(bem.contact_radius / ref.contact_radius - 1)
    assert r.comparison.bem_vs_analytic.edge_radius_rel is None
    assert r.periodic is None and set(r.stress.bodies) == {"body1", "body2"}
    assert r.wall_time_s_by_part["bem"] > 0 and r.wall_time_s_by_part["layer_reference"] is None


@pytest.mark.parametrize("schema", ["contactlab.result/3", "contactlab.result/5", None])
def test_a_result_of_another_schema_is_refused(hertz_run, tmp_path, schema):
    d, data = _copy(hertz_run[1], tmp_path)
    data["schema"] = schema
    (d / "result.json").write_text(json.dumps(data))
    with pytest.raises(ResultFileError) as info:
        RunResult.read(d / "result.json")
    message = str(info.value)
    assert isinstance(info.value, ValueError)
    assert f"schema = {schema!r}" in message and repr(SCHEMA) in message and str(d / "result.json") in message
    code, _, err = cli("report", d)  # the command line: one line, exit 2, no traceback
    assert code == 2 and repr(SCHEMA) in err and "Traceback" not in err


@pytest.mark.parametrize(("path", "field"), [(("comparison",), "result.comparison"),
                                             (("bem", "step"), "result.bem.step"),
                                             (("fem", "mesh", "domain_factor"), "result.fem.mesh.domain_factor"),
                                             (("stress", "bodies", "body2", "fem"), "result.stress.bodies.body2.fem")])
def test_a_missing_field_is_refused_by_name(hertz_run, tmp_path, path, field):
    d, data = _copy(hertz_run[1], tmp_path)
    node = data
    for key in path[:-1]:
        node = node[key]
    del node[path[-1]]
    (d / "result.json").write_text(json.dumps(data))
    with pytest.raises(ResultFileError, match=rf"^{re.escape(field)} is missing in .*result\.json"):
        load_results(d)


def test_an_unknown_field_is_refused_by_name(hertz_run, tmp_path):
    d, data = _copy(hertz_run[1], tmp_path)
    data["fem"]["contact_radius"] = data["fem"]["edge_radius"]
    (d / "result.json").write_text(json.dumps(data))
    with pytest.raises(ResultFileError, match=r"result\.fem\.contact_radius in .* has no such field"):
        RunResult.read(d / "result.json")


def test_the_report_of_a_written_result_equals_the_report_of_the_run(hertz_run, tmp_path):
    """The report's tables from result.json read back are those of the run in memory, and show its numbers."""
    outcome, out = hertz_run

    def tables(res, work):
        return [(s.title, item.columns, item.rows) for s in run_sections(res, work)
                for item in s.items if hasattr(item, "rows")]

    written = tables(load_results(out), tmp_path / "a")
    in_memory = tables(results_of(outcome), tmp_path / "b")
    assert written == in_memory
    results = next(rows for title, _, rows in written if title == "Results")
    peak = next(row for row in results if row[0] == "peak pressure p_max")
    assert float(peak[1]) == pytest.approx(outcome.bem.p_max / 1e6, rel=1e-3)  # MPa, 4 digits
    assert float(peak[2]) == pytest.approx(outcome.fem.p_max / 1e6, rel=1e-3)
    radius = next(row for row in results if row[0] == "edge radius of the loaded zone r_edge")
    assert float(radius[2]) == pytest.approx(outcome.fem.edge_radius * 1e3, rel=1e-3)  # the FEM's edge, mm
