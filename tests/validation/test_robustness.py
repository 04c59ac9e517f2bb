"""The robustness grid on its corners: nothing wrong, Newton converges, the paper's methods where they can."""

import json
import logging

import pytest

from validation.report.documents.studies import study_markdown
from validation.studies.robustness import _json_row, run_robustness


@pytest.fixture(scope="module")
def rows():
    logging.disable(logging.WARNING)  # the failures of the paper methods are expected here
    try:
        return run_robustness(exponents=(0.2, 3.0), compliances=(1e-6, 1e6), moduli=(1e-3, 1e12))
    finally:
        logging.disable(logging.NOTSET)


def test_no_outcome_is_wrong(rows):
    assert len(rows) == 2 * 2 * 2 * 2 * 3
    assert not [r for r in rows if r.status == "wrong"]


def test_newton_converges_on_every_corner(rows):
    bad = [r for r in rows if r.method == "newton" and (r.status, r.solver_status) != ("converged", "converged")]
    assert not bad, bad


def test_variable_compliance_converges_where_its_map_contracts(rows):
    """Layer-dominated: the secant map contracts for s < 2 only; stiff layers: always."""
    for r in rows:
        if r.method == "variable_compliance" and (r.s < 2 or r.k < 1):
            assert r.status == "converged", r
        if r.method == "variable_compliance" and r.s >= 2 and r.k > 1:
            assert r.status == "reported failure", r


def test_augmented_gap_fails_loudly_where_the_layer_dominates(rows):
    for r in rows:
        if r.method == "augmented_gap" and r.k > 1:
            assert r.status == "reported failure" and r.message, r
            assert r.solver_status in (None, "maxiter", "stalled", "diverged", "nonfinite"), r
        if r.method == "augmented_gap" and r.k < 1:
            assert r.status == "converged", r


def test_summary_lists_every_failure(rows):
    text = study_markdown("robustness.json", json.loads(json.dumps([_json_row(r) for r in rows])))
    failures = [r for r in rows if r.status != "converged"]
    listed = text.split("Every outcome that is not converged.")[1]
    assert listed.count("| reported failure |") == len(failures) > 0
