"""validation.compare on constructed fields with known answers, and on small real solves."""

import copy
import dataclasses
import json
import math

import numpy as np
import pytest

import bem
from bem.checks import InputError
from bem.gaps import Paraboloid
from fem_reference.result import FemResult
from bem.reference import hertz_elliptic, hertz_sphere
from validation.compare import PAIR_KEYS, RADIUS_KEYS, compare, pair_metrics, relative_l2, ring_weights

H = hertz_sphere(1.0, 1.0, force=1.0)
H_A = H.contact_radius
EPS = 0.01


@pytest.fixture(scope="module")
def base():
    """A real BEM result on a lattice of 20 steps across the Hertz contact."""
    return bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=2 * H_A / 20, extent=1.4 * H_A)


def _with_p(res, p, **kw):
    """``res`` with nodal pressures ``p`` (and consistent p_max, force)."""
    a = res.lattice.node_area
    fields = {"p": p, "p_max": float(p.max()), "force": float(a * p.sum()),
              "contact_area": float(a * np.count_nonzero(p > 0)), **kw}
    return dataclasses.replace(res, **fields)


def _fem(r, p, **kw):
    """A FemResult holding the profile ``p(r)``."""
    fields = dict(r=r, p=p, overlap=np.zeros_like(r), initial_gap=r**2 / 2, approach=H.approach, force=H.force,
                  force_reaction=H.force, p_max=float(p.max()), edge_radius=H_A, converged=True, message="",
                  status="converged",
                  iterations=1, timings={"total": 0.0}, n_dofs=0, n_elements=0, n_interface_nodes=r.size,
                  n_elements_across_contact=0.0, penalty={}, truncation={}, mesh={}, E_star=1.0)
    fields.update(kw)
    return FemResult(**fields)


def _radius(res):
    return np.hypot(res.x, res.y)


def test_scaled_hertz_field_has_the_scale_as_l2_error(base):
    p_exact = H.pressure(_radius(base))
    fake = _with_p(base, (1 + EPS) * p_exact, approach=1.02 * H.approach)
    m = compare(fake, analytic=H)["bem_vs_analytic"]
    assert m["l2_rel"] == pytest.approx(EPS, rel=1e-10)
    assert m["max_rel"] == pytest.approx(EPS, rel=1e-10)
    assert m["peak_rel"] == pytest.approx(EPS, rel=1e-10)  # the origin is a node
    assert m["approach_rel"] == pytest.approx(0.02, rel=1e-10)
    n_in = np.count_nonzero(p_exact > 0)
    assert m["n_points"] == n_in
    assert m["contact_radius_rel"] == pytest.approx(math.sqrt(n_in * base.lattice.node_area / math.pi) / H_A - 1)


def test_local_bump_and_pressure_outside_the_contact_count_in_the_union(base):
    r = _radius(base)
    p_exact = H.pressure(r)
    inner = r < H_A / 2
    outer = (r > 1.1 * H_A) & (r < 1.3 * H_A)
    q = 0.05 * H.p_max
    p = p_exact + q * inner + q * outer
    m = compare(_with_p(base, p), analytic=H)["bem_vs_analytic"]
    expected = q * math.sqrt(inner.sum() + outer.sum()) / math.sqrt(np.sum(p_exact**2))
    assert m["l2_rel"] == pytest.approx(expected, rel=1e-10)
    assert m["max_rel"] == pytest.approx(q / H.p_max, rel=1e-10)
    assert m["n_points"] == np.count_nonzero(p_exact > 0) + outer.sum()


def test_bem_against_fem_profile_interpolated_in_r(base):
    r_fem = np.sort(np.append(np.linspace(0.0, 3.0, 61), H_A))  # a node at the kink r = a
    cone = np.maximum(1.0 - r_fem / H_A, 0.0)
    fem = _fem(r_fem, cone, approach=0.5, force=2.0, edge_radius=H_A)
    p_bem = (1 + EPS) * np.maximum(1.0 - _radius(base) / H_A, 0.0)
    fake = _with_p(base, p_bem, approach=0.55)
    out = compare(fake, fem=fem, force=2.0)
    m = out["bem_vs_fem"]
    assert m["l2_rel"] == pytest.approx(EPS, rel=1e-9)
    assert m["approach_rel"] == pytest.approx(0.1, rel=1e-12)
    assert m["force_rel"] == pytest.approx(fake.force / 2.0 - 1, rel=1e-12)
    assert out["force_balance"] == {"target": 2.0, "bem": pytest.approx(abs(fake.force - 2) / 2),
                                    "fem": pytest.approx(0.0)}
    assert "bem_vs_analytic" not in out and "fem_vs_analytic" not in out


def test_the_bem_area_radius_against_the_fem_edge_is_named_edge_radius_rel(base):
    """BEM sqrt(A / pi) against the FEM's interpolated edge: two estimators, a key naming both."""
    r_fem = np.linspace(0.0, 3.0, 61)
    fem = _fem(r_fem, H.pressure(r_fem), edge_radius=1.1 * H_A)
    out = compare(base, fem=fem, analytic=H)
    assert out["bem_vs_fem"]["edge_radius_rel"] == pytest.approx(base.contact_radius / (1.1 * H_A) - 1, rel=1e-12)
    assert out["fem_vs_analytic"]["edge_radius_rel"] == pytest.approx(0.1, rel=1e-12)
    assert out["bem_vs_analytic"]["contact_radius_rel"] == pytest.approx(base.contact_radius / H_A - 1, rel=1e-12)
    assert "contact_radius_rel" not in out["bem_vs_fem"] and "edge_radius_rel" not in out["bem_vs_analytic"]


def test_fem_against_analytic_uses_ring_area_weights():
    r = np.concatenate([np.linspace(0, 0.5, 3), np.linspace(0.6, 3.0, 40)])  # non-uniform
    p_exact = H.pressure(r)
    bump = (r > 0.3) & (r < 0.7)
    fem = _fem(r, p_exact * (1 + EPS * bump))
    m = pair_metrics(fem, H)
    A = ring_weights(r)
    expected = EPS * math.sqrt(np.sum(A * bump * p_exact**2) / np.sum(A * p_exact**2))
    assert m["l2_rel"] == pytest.approx(expected, rel=1e-10)
    unweighted = EPS * math.sqrt(np.sum(bump * p_exact**2) / np.sum(p_exact**2))
    assert abs(m["l2_rel"] - unweighted) > 0.05 * unweighted  # the weights matter here


def test_ring_weights_integrate_linear_functions_exactly():
    rng = np.random.default_rng(3)
    r = np.sort(np.concatenate([[0.0], rng.uniform(0, 2.0, 30), [2.0]]))
    A = ring_weights(r)
    assert A.sum() == pytest.approx(math.pi * 4.0, rel=1e-13)  # 2 pi int_0^2 r dr
    assert np.dot(A, r) == pytest.approx(2 * math.pi * 8 / 3, rel=1e-13)  # 2 pi int_0^2 r^2 dr
    with pytest.raises(InputError, match="r"):
        ring_weights([0.0, 1.0, 0.5])


def test_elliptic_reference_is_compared_in_x_y(base):
    He = hertz_elliptic(1.5, 0.8, 1.0, force=1.0)
    fake = _with_p(base, (1 - EPS) * He.pressure(base.x, base.y))
    m = compare(fake, analytic=He)["bem_vs_analytic"]
    assert m["l2_rel"] == pytest.approx(EPS, rel=1e-10)
    assert m["peak_rel"] == pytest.approx(-EPS, rel=1e-10)
    fem = _fem(np.linspace(0, 3, 31), H.pressure(np.linspace(0, 3, 31)))
    out = compare(fake, fem=fem, analytic=He)
    assert "fem_vs_analytic" not in out  # the FEM is axisymmetric
    with pytest.raises(InputError, match="axisymmetric"):
        pair_metrics(fem, He)


def test_small_bem_solve_against_hertz_and_fem(base):
    fem = _fem(np.linspace(0, 3, 6001), H.pressure(np.linspace(0, 3, 6001)))
    out = compare(base, fem=fem, analytic=H)
    a = out["bem_vs_analytic"]
    assert a["l2_rel"] < 0.03 and abs(a["peak_rel"]) < 2e-3
    assert abs(a["contact_radius_rel"]) < 0.05 and abs(a["approach_rel"]) < 5e-3
    assert out["force_balance"]["bem"] < 1e-10
    assert out["fem_vs_analytic"]["l2_rel"] < 1e-3  # a fine exact profile, linear between nodes
    assert out["bem_vs_fem"]["l2_rel"] == pytest.approx(a["l2_rel"], rel=0.05)
    json.dumps(out, allow_nan=False)
    for pair in ("bem_vs_fem", "bem_vs_analytic", "fem_vs_analytic"):
        assert set(out[pair]) - set(PAIR_KEYS) == {RADIUS_KEYS[pair != "bem_vs_analytic"]}
        assert all(v is None or type(v) in (float, int) for v in out[pair].values())


def test_finer_lattice_is_closer_to_hertz():
    errs = []
    for n in (10, 40):
        res = bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=2 * H_A / n, extent=1.3 * H_A)
        errs.append(compare(res, analytic=H)["bem_vs_analytic"])
    assert errs[1]["l2_rel"] < 0.6 * errs[0]["l2_rel"]
    assert abs(errs[1]["peak_rel"]) < 0.2 * abs(errs[0]["peak_rel"])


def test_nodal_pressure_of_a_solve_follows_hertz():
    res = bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=2 * H_A / 40, extent=1.3 * H_A)
    r = np.hypot(res.x, res.y)
    inside = r < 0.9 * H_A
    assert np.max(np.abs(res.p[inside] - H.pressure(r[inside]))) < 0.02 * H.p_max
    assert np.all(res.p[r > 1.1 * H_A] == 0)


def test_bad_input_is_refused(base):
    with pytest.raises(InputError, match="bem.ContactResult"):
        compare("result")
    with pytest.raises(InputError, match="fem"):
        compare(base, fem=H)
    with pytest.raises(InputError, match="analytic"):
        compare(base, analytic=42)
    with pytest.raises(InputError, match="force"):
        compare(base, analytic=H, force=-1.0)
    assert relative_l2([1.0], [0.0]) is None


def test_inputs_are_not_modified(base):
    fem = _fem(np.linspace(0, 3, 31), H.pressure(np.linspace(0, 3, 31)))
    saved = copy.deepcopy((base.p, base.x, base.y, fem.r, fem.p))
    compare(base, fem=fem, analytic=H)
    ring_weights(fem.r)
    for a, b in zip(saved, (base.p, base.x, base.y, fem.r, fem.p)):
        assert np.array_equal(a, b)
