"""Nonlinear layers: the three methods against each other, against KKT, and the paper's findings."""

import numpy as np
import pytest

import bem
from bem import layers

from .conftest import E_STAR, FORCE, R, paper_laws

METHODS = ("newton", "augmented_gap", "variable_compliance")


def _agree(a, b, tol=1e-6):
    assert abs(a.p_max / b.p_max - 1) <= tol
    assert np.linalg.norm(a.p - b.p) / np.linalg.norm(b.p) <= tol


@pytest.mark.parametrize("law", list(paper_laws(1.0)))
def test_variable_compliance_agrees_with_newton_on_the_paper_problem(paper, law):
    layer = paper_laws(10.0)[law]  # the paper's Fig. 5 stiffness: lam = 10 C_nn
    newton = paper(layer)
    vc = paper(layer, "variable_compliance")
    assert newton.converged and vc.converged
    _agree(vc, newton)


@pytest.mark.parametrize("law", list(paper_laws(1.0)))
def test_augmented_gap_agrees_with_newton_where_it_converges(paper, law):
    layer = paper_laws(0.3)[law]
    newton = paper(layer)
    ag = paper(layer, "augmented_gap", relaxation=0.5)
    assert newton.converged
    assert ag.converged, ag.message
    _agree(ag, newton)


@pytest.mark.parametrize("law", list(paper_laws(1.0)))
def test_augmented_gap_reports_failure_for_a_soft_layer(paper, law):
    """lam = 10 C_nn: the fixed point map has spectral radius ~ lam / C_nn > 1."""
    res = paper(paper_laws(10.0)[law], "augmented_gap", maxiter=100)
    assert not res.converged
    assert res.status in ("diverged", "stalled")
    assert np.all(np.isfinite(res.p))


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("law", ["root", "elastic_rigid"])
def test_kkt_of_eq14_holds_at_every_returned_solution(paper, method, law):
    layer = paper_laws(0.3)[law]
    res = paper(layer, method, relaxation=0.5) if method == "augmented_gap" else paper(layer, method)
    assert res.converged
    C = bem.InfluenceOperator(res.lattice, E_STAR).dense()  # independent of the FFT path
    gap = C @ res.p + layer.w(res.p) + bem.gaps.Paraboloid(R)(res.x, res.y) - res.approach
    scale = np.abs(C @ res.p + layer.w(res.p)).max()
    tol = 1e-10  # every method meets rtol on the KKT residual
    assert res.p.min() >= 0
    assert np.abs(gap[res.p > 0]).max() <= tol * scale
    assert gap[res.p == 0].min() >= -tol * scale
    assert res.lattice.node_area * res.p.sum() == pytest.approx(FORCE, rel=1e-10)


def test_kalker_refuses_a_nonlinear_layer(paper):
    with pytest.raises(bem.InputError, match="method"):
        paper(layers.Root(1.0), "kalker")


def test_all_methods_share_one_result_type(paper):
    layer = paper_laws(0.3)["linear"]
    for method in METHODS + ("kalker",):
        res = paper(layer, method, **({"relaxation": 0.5} if method == "augmented_gap" else {}))
        ran = "kalker" if method in ("newton", "kalker") else method  # a linear layer is a QP for Newton
        assert isinstance(res, bem.ContactResult) and res.method == ran
        assert set(res.history) >= {"residual", "p_max", "n_contact", "changes"}
        np.testing.assert_allclose(res.closure, layer.w(res.p))


def test_record_keeps_the_iterates(paper):
    res = paper(paper_laws(10.0)["elastic_rigid"], "variable_compliance", record=True)
    assert len(res.history["p"]) == res.iterations
    np.testing.assert_allclose(res.history["p"][-1], res.p)


def test_newton_retries_with_a_majorised_model_where_a_step_finds_no_descent(paper, monkeypatch):
    """Where the line search finds no useful descent, Newton solves the model again with the majorised
    compliance from the closure made anew, and still meets the KKT conditions: the first line search of the
    finest level is made to find none."""
    import bem.newton as newton

    calls, real = [], newton.line_search

    def first_finds_none(*args):
        calls.append(args)
        return 0.0 if len(calls) == 1 else real(*args)

    layer = paper_laws(0.3)["root"]
    reference = paper(layer, nested=False)  # one level: the first search is the finest level's
    monkeypatch.setattr(newton, "line_search", first_finds_none)
    res = paper(layer, nested=False)
    assert len(calls) >= 2  # the refused search and the retry's
    assert res.converged and res.kkt_residual <= 1e-10
    _agree(res, reference, tol=1e-7)
