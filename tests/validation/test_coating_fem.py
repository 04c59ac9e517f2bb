"""The coated BEM against the FEM reference with the coating meshed (validation.studies.coating_fem): one
small case at one level of each method, the study's Richardson rule on closed forms."""

import math

import pytest

from validation.studies.coating_fem import SETTINGS, bem_levels, fem_levels, richardson, rms_nodes

# a_H/t = 1, E_c/E_s = 10, nu_c = 0.25: the study's --quick case
CASE = (1.0, 10.0, 0.25)
# Distances of each method's level to the extrapolated values of the study (docs/coatings.md, "Against the
# FEM"), measured at this case: BEM a_H/step = 20: p_max +0.05 %, radius -0.04 %, approach -0.01 %;
# FEM 12 elements across a: p_max -0.06 %, radius +0.2 %, approach +0.01 %. Tolerances: twice their sum.
TOLERANCE = dict(p_max=2.2e-3, radius=4.8e-3, approach=4e-4)


def test_richardson_recovers_order_and_limit_of_a_power_law():
    for order in (1.0, 2.0, 3.0):
        found, limit = richardson([5.0 + 0.3 * h**order for h in (1.0, 0.5, 0.25)])
        assert found == pytest.approx(order, rel=1e-12)
        assert limit == pytest.approx(5.0, rel=1e-12)
    assert richardson([1.0, 2.0, 1.5])[1] is None  # oscillating: no extrapolation
    assert richardson([1.0, 1.0, 1.0]) == (None, None)


def test_coated_bem_agrees_with_the_fem_within_the_measured_discretisation_errors():
    s = dict(SETTINGS, bem_levels=(20,), fem_levels=(12,))
    (b_row,), b = bem_levels(CASE, s)
    (f_row,), f = fem_levels(CASE, s)
    assert b_row["converged"] and f_row["converged"], (b_row["message"], f_row["message"])
    for q, tol in TOLERANCE.items():
        assert math.isclose(b_row[q], f_row[q], rel_tol=tol), (q, b_row[q] / f_row[q] - 1.0)
    assert rms_nodes(b, f) < 0.03


@pytest.mark.slow
def test_quick_study_writes_json_markdown_and_figure(tmp_path):
    import json

    from .conftest import cli

    out = tmp_path / "study"
    code, stdout, err = cli("study", "coating-fem", "--quick", "--out", str(out))
    assert code == 0, err
    assert sorted(p.name for p in out.iterdir()) == [".contactlab", "coating_fem.json", "coating_fem.md",
                                                     "coating_fem.png"]
    (row,) = json.loads((out / "coating_fem.json").read_text())["rows"]
    assert row["converged"] and (row["a_over_t"], row["modulus_ratio"], row["nu_c"]) == CASE
    assert row["worst_extrapolated"] < 5e-3  # the study's target
    assert "The coated BEM against the FEM" in (out / "coating_fem.md").read_text()
