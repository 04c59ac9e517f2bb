"""Tables of a report print enough digits to show the differences they exist to show: values of
one row (BEM, FEM, closed form) that differ print differently, equal ones alike."""

from dataclasses import replace
from pathlib import Path

import pytest

from validation.report.documents.results import RunResults
from validation.report.documents.sections import results_rows
from validation.report.render.content import fmt_distinct
from validation.run import run_scene
from validation.run.parts import Scales
from validation.units import Units


@pytest.fixture(scope="module")
def hertz_result():
    """A small hertz run: the BEM, the FEM and the closed form (its numbers are replaced by the tests)."""
    return run_scene("hertz", overrides=["bem.nodes_across=12", "fem.n_contact_elements=6", "stress.n_depths=4"])


@pytest.mark.parametrize("values", [[1.37134e9, 1.37121e9, 1.37108e9], [0.99968, 1.0005, 1.0], [100.0, 100.0, 1e2],
                                    [1.8566e-4, 1.8574e-4, 1.8663e-4]])
def test_values_that_differ_print_differently(values):
    cells = fmt_distinct(values)
    assert len(set(cells)) == len(set(values))
    for cell, value in zip(cells, values):
        assert float(cell) == pytest.approx(value, rel=5e-5)


def test_short_values_stay_short_and_other_cells_pass_through():
    assert fmt_distinct([1.5, 2.5, "-", None]) == ["1.5", "2.5", "-", "-"]
    assert len(fmt_distinct([1.0, 1.0 + 1e-13])[0]) <= 8  # beyond the most digits: no endless digits


def test_results_table_tells_bem_fem_and_closed_form_apart(hertz_result):
    result = replace(hertz_result, p_max=1.37134e9, force=100.0, approach=3.4821e-6, contact_radius=1.8566e-4,
                     fem=replace(hertz_result.fem, p_max=1.37121e9, force=100.0, approach=3.4853e-6,
                                 edge_radius=1.8574e-4),
                     analytic=replace(hertz_result.analytic, p_max=1.37108e9, force=100.0, approach=3.4829e-6,
                                      contact_radius=1.8663e-4),
                     scales=Scales(p_hertz=1.37108e9, a_hertz=1.8663e-4, approach_hertz=3.4829e-6, force_hertz=100.0))
    res = RunResults(directory=Path("."), result=result, units=Units.from_dict("SI", result.unit_symbols))
    columns, rows = results_rows(res)
    assert columns == ("quantity", "BEM", "FEM", "closed form", "unit")
    for row in rows:
        if row[0].startswith(("peak pressure", "approach", "contact radius", "p_max / p_H")):
            assert len(set(row[1:4])) == 3, row
        if row[0].startswith("total force"):
            assert len(set(row[1:4])) == 1, row


def test_one_length_unit_and_one_pressure_unit_in_the_figures_and_stress_tables(tmp_path):
    """A run's figures draw lengths in mm and pressures in MPa: the stress tables and captions too."""
    import re

    from validation.report.documents.results import load_results
    from validation.report.documents.sections import report_results_dir
    from validation.run import run_scene

    run_scene("hertz", tmp_path / "r", overrides=["bem.nodes_across=16", "fem.n_contact_elements=6"])
    built = report_results_dir(tmp_path / "r", tmp_path / "rep")
    md = built.markdown.read_text(encoding="utf-8")
    stress = md[md.index("## Subsurface stresses"):]
    headers = [line for line in stress.splitlines() if line.startswith("| body |")]
    assert len(headers) == 2
    assert set(re.findall(r"/ (\w+)", " ".join(headers))) == {"mm", "MPa"}
    assert "µm" not in md and "GPa" not in md and "kPa" not in md
    depth = float(re.search(r"depths from 0 to ([\d.]+) mm", md).group(1))
    res = load_results(tmp_path / "r")
    assert depth == pytest.approx(max(res.result.stress.depths) * 1e3, rel=1e-3)  # m -> mm
