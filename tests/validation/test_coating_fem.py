"""The coated BEM against the FEM reference with the coating meshed (validation.studies.coating_fem): one
small case at one level of each method (scalars, p(r), interface stresses), the study's Richardson rule and
the edge-aware FEM profile on closed forms."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from validation.studies.coating_fem import (EDGE_BAND, SETTINGS, _coating, bem_levels, fem_levels, fem_profile,
                                            richardson, rms_nodes, rms_parts)
from validation.studies.coating_fem_stress import interface_stresses

# a_H/t = 1, E_c/E_s = 10, nu_c = 0.25: the study's --quick case
CASE = (1.0, 10.0, 0.25)
# Distances of each method's level to the extrapolated values of the study (docs/coatings.md, "Against the
# FEM"), measured at this case: BEM a_H/step = 20: p_max +0.024 %, radius -0.163 %, approach -0.019 %;
# FEM 12 elements across a (with its edge band): p_max -0.060 %, radius +0.066 %, approach +0.003 %.
# Tolerances: twice their sum.
TOLERANCE = dict(p_max=1.7e-3, radius=4.6e-3, approach=4.5e-4)
# The same levels' interface stresses (the FEM's one-sided recovery, of the largest traction on the bond) and
# von Mises maxima, measured: sigma_zz 0.29 %, sigma_rz 0.09 %, von Mises coating +0.19 %, substrate +0.017 %
# (0.044 %, 0.025 %, -0.028 %, -0.047 % at the study's finest levels). Tolerances: three times those at this pair.
STRESS_TOLERANCE = dict(szz=9e-3, srz=3e-3, vm_coating=6e-3, vm_substrate=5e-4)


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
    parts = rms_parts(b, f)  # measured 1.43 %: the edge band 1.43 %, the interior 0.11 %
    assert parts["total"] < 0.02 and parts["interior"] < 0.004
    stress, _ = interface_stresses(b, f, _coating(CASE, s), s)
    for q, tol in STRESS_TOLERANCE.items():
        assert abs(stress[q]) < tol, (q, stress[q])


def _square_root_edge(a, nodes):
    """A FEM-like profile with a square-root edge at ``a``: ``p = sqrt(a - r)`` on ``nodes`` radii."""
    r = np.asarray(nodes, float)
    return SimpleNamespace(r=r, p=np.sqrt(np.maximum(a - r, 0.0)), edge_radius=a)


def test_edge_aware_profile_is_exact_for_a_square_root_edge_and_the_linear_one_is_not():
    fem = _square_root_edge(0.93, np.linspace(0.0, 1.5, 16))  # the edge between two nodes
    r = np.linspace(0.0, 1.2, 241)
    exact = np.sqrt(np.maximum(0.93 - r, 0.0))
    np.testing.assert_allclose(fem_profile(fem, r, edge_aware=True), exact, rtol=0, atol=1e-12)
    assert np.abs(fem_profile(fem, r) - exact).max() > 0.05


def test_rms_parts_split_the_edge_band_from_the_interior():
    fem = _square_root_edge(1.0, np.linspace(0.0, 2.0, 21))
    x = np.linspace(-1.5, 1.5, 61)
    X, Y = np.meshgrid(x, x)
    r = np.hypot(X, Y)
    exact = np.sqrt(np.maximum(1.0 - r, 0.0))
    assert rms_parts(SimpleNamespace(x=X, y=Y, p=exact), fem)["total"] < 1e-12
    band = r >= (1.0 - EDGE_BAND)
    parts = rms_parts(SimpleNamespace(x=X, y=Y, p=exact + 0.01 * band * (r < 1.0)), fem)
    assert parts["interior"] < 1e-12 and parts["edge"] > 1e-3
    assert parts["total"] == pytest.approx(math.hypot(parts["interior"], parts["edge"]), rel=1e-12)


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


def test_the_cases_above_refine_above_and_only_they_are_solved_one_level_finer(monkeypatch):
    from validation.report.documents.coating_fem import refined_table
    from validation.studies import coating_fem

    # (RMS of p(r), radius difference): the first above by its RMS, the last by its radius only; a_H/t = 0.5
    # below both, but its coarsest FEM level did not converge (its FEM orders rest on two levels)
    worst = {(0.1, 10.0, 0.25): (0.0073, 0.001), (0.5, 10.0, 0.25): (0.001, 0.001), (1.0, 10.0, 0.25): (0.0040, -0.004),
             (10.0, 10.0, 0.25): (0.001, -0.006)}

    def case_row(case, s, *, layer=None, keep=None):
        diff = {q: dict(extrapolated=worst[case][1] if q == "radius" else 0.0) for q in coating_fem.QUANTITIES}
        fem = [dict(converged=case[0] != 0.5), dict(converged=True), dict(converged=True)]
        return dict(a_over_t=case[0], modulus_ratio=case[1], nu_c=case[2], layer=None, diff=diff,
                    pressure={"total": {"finest": worst[case][0]}}, bem=[dict(converged=True)] * 3, fem=fem)

    def finer(row, s, *, finest=None):
        case = (row["a_over_t"], row["modulus_ratio"], row["nu_c"])
        return dict(a_over_t=case[0], modulus_ratio=case[1], nu_c=case[2],
                    rows=[dict(bem=40, fem=24, linear=0.01, total=worst[case][0], interior=1e-4, edge=worst[case][0])])

    monkeypatch.setattr(coating_fem, "compare_case", case_row)
    monkeypatch.setattr(coating_fem, "refined_pressure", finer)
    data = coating_fem.run_coating_fem(dict(a_over_t=(0.1, 0.5, 1.0, 10.0), modulus_ratios=(10.0,), nu_c=(0.25,),
                                            root_case=None, refine_above=0.005))
    assert [(c["a_over_t"], c["modulus_ratio"], c["nu_c"]) for c in data["refined"]] == [
        (0.1, 10.0, 0.25), (0.5, 10.0, 0.25), (10.0, 10.0, 0.25)]
    heads, rows = refined_table(data)
    assert len(rows) == 3 and rows[0][:3] == ("0.1", "10", "0.25") and rows[2][0] == "10"
    quick = coating_fem.run_coating_fem(dict(a_over_t=(0.1,), modulus_ratios=(10.0,), nu_c=(0.25,)), quick=True)
    assert quick["refined"] == []  # the quick run refines nothing


def test_one_level_finer_extends_each_methods_sequence_for_its_orders_and_extrapolations(monkeypatch):
    """refined_pressure's ``after``: the orders and Richardson values from the last three levels of each method,
    the coarser two from the case's row; values q = q0 (1 + c / n^2) give order 2 and q0 exactly."""
    from types import SimpleNamespace

    from validation.studies import coating_fem

    q0 = {"bem": dict(p_max=2.0, radius=1.0, approach=3.0), "fem": dict(p_max=2.02, radius=0.99, approach=3.0)}

    def level(method, n, c):
        return dict(level=n, converged=True, **{q: v * (1.0 + c / n**2) for q, v in q0[method].items()})

    calls, across = [], []

    def levels(method, c):
        def run(case, s, layer=None, keep=None):
            ns = s[f"{method}_levels"]
            calls.append((method, tuple(ns)))
            if method == "fem":  # the coating's elements at the study's scale: 4 n / 6 across
                across.extend(coating_fem._across(s, n) for n in ns)
            keep.extend(SimpleNamespace(n=n, converged=True) for n in ns)
            return [level(method, n, c) for n in ns], None
        return run

    monkeypatch.setattr(coating_fem, "bem_levels", levels("bem", 0.5))
    monkeypatch.setattr(coating_fem, "fem_levels", levels("fem", -2.0))
    monkeypatch.setattr(coating_fem, "rms_nodes", lambda b, f: 0.0)
    s = dict(coating_fem.SETTINGS, bem_levels=(10, 20, 40), fem_levels=(6, 12, 24))
    # the case's row: its coarse levels perturbed beyond the quadratic law, so only the last three can give order 2
    row = dict(a_over_t=1.0, modulus_ratio=10.0, nu_c=0.25,
               bem=[level("bem", 10, 9.0), level("bem", 20, 0.5), level("bem", 40, 0.5)],
               fem=[level("fem", 6, 7.0), level("fem", 12, -2.0), level("fem", 24, -2.0)])
    solved = []
    parts = dict(total=0.0, interior=0.0, edge=0.0)
    monkeypatch.setattr(coating_fem, "rms_parts", lambda b, f: solved.append((b.n, f.n)) or parts)
    finest = dict(bem=SimpleNamespace(n=40, converged=True), fem=SimpleNamespace(n=24, converged=True))
    for given in (None, finest):  # the finest levels solved again, or taken from compare_case's keep
        solved.clear(), calls.clear(), across.clear()
        out = coating_fem.refined_pressure(row, s, finest=given)
        again = [("bem", (40,)), ("fem", (24,))] if given is None else []
        assert calls == again + [("bem", (80,)), ("fem", (48,))]
        assert across == ([16] if given is None else []) + [32]
        assert [r["level"] for r in out["bem"]] == [40, 80] and [r["level"] for r in out["fem"]] == [24, 48]
        assert [(r["bem"], r["fem"]) for r in out["rows"]] == [(40, 24), (40, 48), (80, 24), (80, 48)] == solved
        after = out["after"]
        for q in coating_fem.QUANTITIES:
            for method in ("bem", "fem"):
                x = after[f"{method}_x"][q]
                assert abs(x["order"] - 2.0) < 1e-9 and abs(x["extrapolated"] / q0[method][q] - 1.0) < 1e-12
            assert abs(after["diff"][q]["extrapolated"] - (q0["bem"][q] / q0["fem"][q] - 1.0)) < 1e-12


def test_the_after_table_reads_each_refined_cases_finer_levels_and_differences():
    from validation.report.documents.coating_fem import after_table

    x = {q: dict(order=2.0, extrapolated=1.0, finest=1.0) for q in ("p_max", "radius", "approach")}
    case = dict(a_over_t=0.1, modulus_ratio=100.0, nu_c=0.25, rows=[],
                bem=[dict(p_max=2.0, radius=0.5, approach=3.0), dict(p_max=2.5, radius=0.75, approach=3.5)],
                fem=[dict(p_max=1.0, radius=0.25, approach=4.0), dict(p_max=1.5, radius=0.125, approach=4.5)],
                after=dict(bem_x=x, fem_x=x, diff={q: dict(extrapolated=0.001 * k, finest=-0.002 * k)
                                                   for k, q in enumerate(("p_max", "radius", "approach"))}))
    heads, rows = after_table({"refined": [case, dict(case, after=None)]})
    assert len(rows) == 3 and [r[3] for r in rows] == ["p_max", "radius", "approach"]
    assert rows[1][:3] == ("0.1", "100", "0.25") and rows[1][4] == "0.5 / 0.75" and rows[1][6] == "0.25 / 0.125"
    assert rows[2][-2:] == ("+0.200%", "-0.400%")


def test_the_bem_edge_with_a_layer_is_where_the_overlap_changes_sign():
    """``bem_edge(layer=True)`` against the overlap's sign change read independently along the x axis
    (linear between the last node with ``w(p) > 0`` and the first with ``-gap < 0``): within a quarter step
    on lattices ``a_H/40`` and ``a_H/80`` (the root layer's case of the study). A first fit over 0.4 area
    radii puts it 3.6 steps inside at ``a_H/80``."""
    import bem
    from validation.studies.coating_fem import _gap, _root, bem_edge, problem

    s = dict(SETTINGS)
    for n in (40, 80):
        res = bem.solve(_gap(s), E1=s["E_s"], nu1=s["nu_s"], E2=s["E_s"], nu2=s["nu_s"],
                        coating2=_coating(s["root_case"], s), force=problem(s)[1], step=s["a_H"] / n, extent="auto",
                        layer=_root(s))
        ray = (np.abs(res.y) < 1e-3 * res.step) & (res.x >= 0)
        x, p, gap = res.x[ray], res.p[ray], res.gap[ray]
        order = np.argsort(x)
        x, y = x[order], np.where(p[order] > 0, res.layer.w(p[order]), -gap[order])
        k = int(np.nonzero(y > 0)[0][-1])
        crossing = x[k] + (x[k + 1] - x[k]) * y[k] / (y[k] - y[k + 1])
        assert abs(bem_edge(res, layer=True) - crossing) < 0.25 * res.step, n


def test_a_level_that_stops_is_solved_again_on_a_mesh_sized_by_the_finest_converged_radius(monkeypatch):
    """fem_levels: a level that did not converge is solved once more with ``a_est`` = the contact radius of the
    finest converged level; its row keeps the first attempt (``first``)."""
    from validation.studies import coating_fem

    calls = []

    def level(case, s, layer, n, a_est=None):
        calls.append((n, a_est))
        ok = n > 6 or a_est is not None
        res = SimpleNamespace(converged=ok, edge_radius=1e-4 * n / 12, r=np.zeros(2), p=np.zeros(2))
        return dict(level=n, converged=ok, a_est=a_est), res

    monkeypatch.setattr(coating_fem, "_fem_level", level)
    keep = []
    rows, finest = coating_fem.fem_levels(CASE, dict(SETTINGS), keep=keep)
    assert calls == [(6, None), (12, None), (24, None), (6, 2e-4)]
    assert [r["converged"] for r in rows] == [True] * 3 and rows[0]["first"] == dict(level=6, converged=False,
                                                                                        a_est=None)
    assert [k.converged for k in keep] == [True] * 3 and finest.edge_radius == 2e-4
