"""Every built-in scene runs from the CLI; result contract; BEM against FEM and closed forms; Fig. 5.

The scenes run once per session with small settings (conftest.SMALL). BEM-FEM differences are
computed here from result.json (the FEM reference is an independent method).
"""

import math

import numpy as np
import pytest

from .conftest import SMALL, STEEL_E, STEEL_NU, e_star, hertz

AXISYMMETRIC_WITH_FEM = ("hertz", "paper_smooth", "paper_linear", "paper_elastic_rigid", "paper_bilinear",
                         "paper_root", "punch", "rough_sphere")
ES_STEEL = e_star(STEEL_E, STEEL_NU, STEEL_E, STEEL_NU)


@pytest.mark.parametrize("name", sorted(SMALL))
def test_builtin_scene_runs_and_writes_the_contract(builtin_runs, name):
    run = builtin_runs[name]
    assert run["code"] == 0, run["stderr"]
    r = run["result"]  # read back through RunResult.read: every field of the schema is there
    assert r.scene == name and r.converged is True
    assert r.kkt_residual <= 1e-8
    assert (r.contact_radius is not None) == (name not in ("roller", "elliptic"))
    assert r.wall_time_s_by_part["bem"] > 0
    assert (r.wall_time_s_by_part["fem"] is not None) == (name in AXISYMMETRIC_WITH_FEM)
    assert (r.fem is not None) == (name in AXISYMMETRIC_WITH_FEM)
    for f in r.files.values():
        assert (run["dir"] / f).is_file()
    assert "p_max" in run["stdout"] and str(run["dir"]) in run["stdout"]


@pytest.mark.parametrize("name", AXISYMMETRIC_WITH_FEM)
def test_bem_matches_fem_within_2_percent(builtin_runs, name):
    r = builtin_runs[name]["result"]
    fem = r.fem
    assert fem.converged
    rel = (r.p_max - fem.p_max) / fem.p_max
    assert abs(rel) <= 0.02
    cmp = r.comparison.bem_vs_fem  # signed (BEM - FEM) / FEM, from the same result.json values
    assert cmp.peak_rel == pytest.approx(rel, rel=1e-9, abs=1e-15)
    assert cmp.approach_rel == pytest.approx((r.approach - fem.approach) / fem.approach, rel=1e-9,
                                                abs=1e-15)
    assert cmp.force_rel == pytest.approx((r.force - fem.force) / fem.force, rel=1e-9, abs=1e-15)
    assert 0 <= cmp.l2_rel <= 0.05 and cmp.n_points > 0
    assert r.contact_radius == pytest.approx(fem.edge_radius, rel=0.03)
    assert cmp.edge_radius_rel == pytest.approx(r.contact_radius / fem.edge_radius - 1, rel=1e-9)
    assert r.approach == pytest.approx(fem.approach, rel=0.01)
    assert r.force == pytest.approx(fem.force, rel=1e-6)


@pytest.mark.parametrize("name", ("hertz", "paper_smooth"))
def test_smooth_sphere_matches_hertz(builtin_runs, name):
    r = builtin_runs[name]["result"]
    a, p0, delta = hertz(100.0, 0.01, ES_STEEL)
    assert r.p_max == pytest.approx(p0, rel=0.01)
    assert r.contact_radius == pytest.approx(a, rel=0.03)
    assert r.approach == pytest.approx(delta, rel=0.01)
    assert r.scales.p_hertz == pytest.approx(p0, rel=1e-12)


def test_hertz_analytic_section(builtin_runs):
    r = builtin_runs["hertz"]["result"]
    a, p0, delta = hertz(100.0, 0.01, ES_STEEL)
    assert r.analytic.kind == "hertz"
    assert r.analytic.p_max == pytest.approx(p0, rel=1e-12)
    assert r.analytic.contact_radius == pytest.approx(a, rel=1e-12)


def test_elliptic_matches_hertz_ellipse(builtin_runs):
    r = builtin_runs["elliptic"]["result"]
    ref = r.analytic
    assert ref.kind == "hertz_elliptic" and ref.a > ref.b  # long axis along the larger radius
    assert r.p_max == pytest.approx(ref.p_max, rel=0.02)
    assert r.contact_area == pytest.approx(ref.contact_area, rel=0.05)
    # force balance of the closed form: P = 2/3 p0 pi a b (independent of the code under test)
    assert 2 / 3 * ref.p_max * math.pi * ref.a * ref.b == pytest.approx(100.0, rel=1e-10)


def test_roller_carries_the_line_contact_pressure(builtin_runs):
    """Lundberg's crown (designed for 1.5 P): the middle carries about Hertz's line-contact pressure."""
    r = builtin_runs["roller"]["result"]
    q = 5000.0 / 0.01  # N/m
    b = math.sqrt(4 * q * 0.004 / (math.pi * ES_STEEL))
    p_line = 2 * q / (math.pi * b)
    x, p = np.array(r.profile.x), np.array(r.profile.p)
    middle = np.abs(x) < 0.0025
    assert np.median(p[middle]) == pytest.approx(p_line, rel=0.05)
    assert r.contact_extent["x"] > 0.9 * 0.005  # the crown spreads the load over the length
    assert r.p_max < 1.1 * p_line  # no end peaks
    assert p[middle].max() - p[middle].min() < 0.02 * p_line  # flat in the middle


def test_punch_pressure_peaks_near_the_edge_of_the_flat(builtin_runs):
    r = builtin_runs["punch"]["result"]
    x, p = np.array(r.profile.x), np.array(r.profile.p)
    x_peak = abs(x[np.argmax(p)])
    assert 0.8 * 0.0005 < x_peak < 1.3 * 0.0005
    assert p[np.argmin(np.abs(x))] < 0.9 * r.p_max  # lower in the middle


def test_rough_sphere_layer_lowers_and_spreads(builtin_runs):
    r, s = builtin_runs["rough_sphere"]["result"], builtin_runs["paper_smooth"]["result"]
    assert r.p_max < 0.95 * s.p_max and r.contact_radius > 1.05 * s.contact_radius


# --- the paper's Fig. 5 (qualitative findings), all at the same settings -------------------------------

def _res(runs, name):
    return runs[name]["result"]


def test_every_layer_lowers_the_peak_and_widens_the_contact(builtin_runs):
    smooth = _res(builtin_runs, "paper_smooth")
    for name in ("paper_linear", "paper_elastic_rigid", "paper_bilinear", "paper_root"):
        r = _res(builtin_runs, name)
        assert r.p_max < smooth.p_max, name
        assert r.contact_radius > 1.05 * smooth.contact_radius, name


def test_elastic_rigid_peak_between_linear_and_smooth(builtin_runs):
    smooth, lin, er = (_res(builtin_runs, n) for n in ("paper_smooth", "paper_linear", "paper_elastic_rigid"))
    assert lin.p_max < er.p_max < smooth.p_max
    # p_max^lambda is the peak of the linear-layer scene (solved independently there)
    assert er.layer["p_max_lambda"] == pytest.approx(lin.p_max, rel=1e-8)
    p_cr = er.layer["parameters"]["p_cr"]
    assert p_cr == pytest.approx(0.5 * lin.p_max, rel=1e-12)
    # region II (rigid branch, p > p_cr) is a central zone inside region I
    x, p = np.array(er.profile.x), np.array(er.profile.p)
    rigid = np.abs(x[p > p_cr])
    assert rigid.size > 0 and rigid.max() < 0.8 * er.contact_radius
    closure = np.array(er.profile.closure)
    np.testing.assert_allclose(closure[p > p_cr], er.layer["parameters"]["lam"] * p_cr, rtol=1e-12)


def test_bilinear_with_small_alpha_c_is_close_to_elastic_rigid(builtin_runs):
    lin, er, bil = (_res(builtin_runs, n) for n in ("paper_linear", "paper_elastic_rigid", "paper_bilinear"))
    assert lin.p_max < bil.p_max < er.p_max
    assert er.p_max - bil.p_max < 0.3 * (er.p_max - lin.p_max)
    p_er, p_bil = np.array(er.profile.p), np.array(bil.profile.p)
    assert np.abs(p_er - p_bil).max() < 0.15 * er.p_max


def _max_edge_slope(r):
    """max |dp/dx| along the axial section, in units of p_max / contact radius."""
    x, p = np.array(r.profile.x), np.array(r.profile.p)
    return (np.abs(np.diff(p)) / np.diff(x)).max() * r.contact_radius / r.p_max


def test_root_law_is_smoother_at_the_edge(builtin_runs):
    smooth, lin, root = (_res(builtin_runs, n) for n in ("paper_smooth", "paper_linear", "paper_root"))
    assert _max_edge_slope(root) < 0.95 * _max_edge_slope(lin) < _max_edge_slope(smooth)
    assert root.contact_radius > lin.contact_radius
    assert root.alpha_b == pytest.approx(root.p_max / lin.p_max, rel=1e-8)
