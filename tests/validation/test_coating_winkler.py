"""The coating study (validation.studies.coating_winkler) and its ring solutions (coating_rings): closed
forms, the BEM and the FEM reference as independent checks, the physics of the map, its files."""

import json
import math

import numpy as np
import pytest

from bem.coating import Coating
from validation.studies.coating_rings import ring_compliance, solve_rings
from validation.studies.coating_winkler import (QUICK, SETTINGS, WinklerRings, errors, problem, rings_truth, rule,
                                                run_case)

S = dict(SETTINGS, rings=150)


def _hertz(E_star, s):
    """``(p0, a, delta)`` of Hertz for the combined modulus ``E_star`` at the study's force."""
    P = problem(s)[1]
    a = (3 * P * s["R"] / (4 * E_star)) ** (1 / 3)
    return 3 * P / (2 * math.pi * a**2), a, a * a / s["R"]


def _check_hertz(sol, E_star, s, tol):
    p0, a, d = _hertz(E_star, s)
    assert sol.converged
    assert sol.p_max == pytest.approx(p0, rel=tol)
    assert sol.radius == pytest.approx(a, rel=tol)
    assert sol.approach == pytest.approx(d, rel=tol)


def test_rings_give_hertz_for_a_bare_pair_and_for_a_coating_of_the_substrate_itself():
    E_star = problem(S)[0]
    a = S["a_H"]
    for coating in (None, Coating(a, S["E_s"], S["nu_s"])):
        r, edges, C = ring_compliance(1.5 * a, 150, E1=S["E_s"], nu1=S["nu_s"], E2=S["E_s"], nu2=S["nu_s"],
                                      coating2=coating)
        # measured: p_max 1e-5, radius 1e-3, approach 2e-5 at 100 rings across 1.5 a
        _check_hertz(solve_rings(r, edges, C, r**2 / (2 * S["R"]), force=problem(S)[1]), E_star, S, 2e-3)


# a very thin one: the coating's oedometric compliance still moves the approach by lam_oed p_H / d_H
# = 0.9 % at a_H/t = 100 (E_c/E_s = 0.1, nu_c = 0.45); measured: radius +0.9 %, p_max -0.5 %
@pytest.mark.parametrize("a_over_t, which, tol", [(1e-3, "coating", 5e-3), (100.0, "substrate", 2e-2)])
def test_a_very_thick_coating_gives_its_own_half_space_and_a_very_thin_one_the_substrate(a_over_t, which, tol):
    ratio, nu_c = 0.1, 0.45
    sol = rings_truth((a_over_t, ratio, nu_c), S)
    E_c = ratio * S["E_s"]
    s_coat = (1 - nu_c**2) / E_c if which == "coating" else (1 - S["nu_s"] ** 2) / S["E_s"]
    E_star = 1 / ((1 - S["nu_s"] ** 2) / S["E_s"] + s_coat)
    _check_hertz(sol, E_star, S, tol)


def test_winkler_rings_agree_with_the_bem_solve_of_the_same_layer():
    import bem
    from bem.gaps import Paraboloid
    from bem.layers import Linear

    E_star, P, p_H, d_H = problem(S)
    lam = 0.5 * d_H / p_H
    ring = WinklerRings(S, S["a_H"])(lam)
    res = bem.solve(Paraboloid(S["R"]), E1=S["E_s"], nu1=S["nu_s"], E2=S["E_s"], nu2=S["nu_s"], layer=Linear(lam=lam),
                    force=P, step=S["a_H"] / 40, extent=2 * S["a_H"])
    assert res.converged and ring.converged
    assert ring.p_max == pytest.approx(res.p_max, rel=1e-3)  # measured 4e-5
    assert ring.approach == pytest.approx(res.approach, rel=1e-3)  # measured 1e-5
    assert ring.radius == pytest.approx(res.contact_radius, rel=5e-3)  # edge vs area radius; measured 2e-4
    assert ring.p_max < 0.8 * p_H  # the layer matters here


def test_equal_materials_need_no_layer_and_the_oedometric_one_is_off_by_its_compliance():
    row = run_case((1.0, 1.0, S["nu_s"]), S)
    # the truth is Hertz itself; the floor is the RMS of two ring sets' Hertz pressures near the
    # square-root edge (measured 2.7e-3 at 150 rings; p_max, radius, approach within 1e-4)
    assert row["lam_best"] == 0.0 and row["best_worst"] < 5e-3
    assert max(abs(row[f"best_{k}"]) for k in ("p_max", "radius", "approach")) < 1e-3
    assert row["oed_approach"] > 0.1  # lam_oed adds t (1 + nu)(1 - 2 nu)/((1 - nu) E) to the approach


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    from .conftest import cli

    out = tmp_path_factory.mktemp("coating") / "study"
    code, stdout, err = cli("study", "coating-winkler", "--quick", "--out", str(out))
    assert code == 0, err
    return out, json.loads((out / "coating_winkler.json").read_text()), stdout


def _row(data, a_over_t, ratio, nu):
    (row,) = [r for r in data["rows"] if (r["a_over_t"], r["modulus_ratio"], r["nu_c"]) == (a_over_t, ratio, nu)]
    return row


def test_quick_study_writes_json_markdown_and_the_map(quick):
    from PIL import Image

    out, data, stdout = quick
    assert sorted(p.name for p in out.iterdir()) == [".contactlab", "coating_winkler.json", "coating_winkler.md",
                                                      "coating_winkler_map.png"]
    n = len(QUICK["a_over_t"]) * len(QUICK["modulus_ratios"]) * len(QUICK["nu_c"])
    assert len(data["rows"]) == n and all(r["truth_converged"] for r in data["rows"])
    assert "The oedometric layer within 5 %" in (out / "coating_winkler.md").read_text()
    with Image.open(out / "coating_winkler_map.png") as img:
        arr = np.asarray(img.convert("L"), dtype=float)
    assert arr.shape[0] > 400 and arr.std() > 5


def test_a_thin_compressible_soft_coating_is_its_oedometric_layer_and_more_so_the_thinner(quick):
    # thin-layer limit: the coating on a stiff substrate compresses laterally confined, its compliance
    # tends to lam_oed with corrections of order t/a (the pressure varies over a, not over t)
    _, data, _ = quick
    worst = [_row(data, x, 0.01, 0.3)["oed_worst"] for x in (0.2, 5.0, 20.0)]
    assert worst[0] > worst[1] > worst[2]
    assert worst[2] < 0.02  # measured 0.7 %
    assert _row(data, 20.0, 0.01, 0.3)["lam_best"] == pytest.approx(_row(data, 20.0, 0.01, 0.3)["lam_oed"], rel=0.05)


def test_an_almost_incompressible_coating_is_far_from_its_oedometric_layer_and_stays_finite(quick):
    _, data, _ = quick
    p_H = problem(SETTINGS)[2]
    for x in (0.2, 5.0):
        soft = _row(data, x, 0.01, 0.49)
        assert soft["oed_worst"] > 0.2  # lam_oed ~ (1 - 2 nu): far too stiff; measured 160 % and 28 %
        assert soft["oed_worst"] > 5 * _row(data, x, 0.01, 0.3)["oed_worst"]
        assert soft["lam_best"] > 2 * soft["lam_oed"]
        assert 0.05 * p_H < soft["p_max"] < p_H and math.isfinite(soft["approach"])


def test_a_stiff_coating_has_no_positive_layer_and_the_bare_substrate_is_the_best(quick):
    _, data, _ = quick
    for x in QUICK["a_over_t"]:
        assert _row(data, x, 10.0, 0.3)["lam_best"] == 0.0
    assert _row(data, 0.2, 10.0, 0.3)["best_worst"] > 0.2


def test_the_fem_reference_with_the_coating_meshed_agrees_with_the_rings(quick):
    _, data, _ = quick
    (row,) = data["fem_check"]
    assert row["converged"]
    # measured at 8 elements across a: p_max -0.21 %, approach +0.09 %, radius -0.34 %
    assert abs(row["vs_rings_p_max"]) < 5e-3 and abs(row["vs_rings_approach"]) < 5e-3
    assert abs(row["vs_rings_radius"]) < 1e-2


def test_errors_of_a_profile_against_itself_and_a_scaled_one():
    from validation.studies.coating_winkler import Profile

    r = np.linspace(0, 1, 101)
    p = np.sqrt(np.clip(1 - r**2, 0, None))
    base = Profile(r, p, 1.0, 1.0, 2.0)
    assert errors(base, base) == dict(p_max=0.0, radius=0.0, approach=0.0, rms=0.0, worst=0.0)
    e = errors(Profile(r, 1.1 * p, 1.1, 1.0, 2.0), base)
    assert e["p_max"] == pytest.approx(0.1) and e["rms"] == pytest.approx(0.1, rel=1e-9) and e["worst"] == e["rms"]


def test_rule_is_the_smallest_thickness_ratio_from_which_every_larger_one_stays_within():
    rows = [dict(nu_c=0.3, modulus_ratio=0.1, a_over_t=x, oed_worst=w)
            for x, w in ((1, 0.3), (2, 0.04), (5, 0.06), (10, 0.02), (20, 0.01))]
    rows += [dict(nu_c=0.3, modulus_ratio=10, a_over_t=x, oed_worst=0.5) for x in (1, 20)]
    assert rule(rows) == {"0.3": {"0.1": 10, "10": None}}


def test_the_studies_report_shows_the_map_and_the_rule(quick, tmp_path):
    from validation.report.documents.studies import report_studies_dir

    out, _, _ = quick
    report_studies_dir(out, tmp_path / "report")
    md = (tmp_path / "report" / "report.md").read_text()
    assert "Coatings: when a linear Winkler layer stands for a coating" in md
    assert "figures/coating_winkler_map.png" in md
    assert (tmp_path / "report" / "figures" / "coating_winkler_map.png").is_file()
    assert "The oedometric layer within 5 %" in md


def test_the_truth_is_an_argument_and_the_fem_gives_the_rings_answer():
    from validation.studies.coating_winkler import fem_truth

    case = (1.0, 0.1, 0.35)
    calls = []

    def fem(c, s):
        calls.append(c)
        return fem_truth(c, s, n_contact_elements=8)

    by_fem, by_rings = run_case(case, S, fem), run_case(case, S)
    assert calls == [case]
    # the two truths differ by 2e-3 (peak) and 3e-3 (radius) at 8 elements: so do the layers' errors
    # (measured 2.2e-3, 3.7e-3, 9e-4; lam_best 1 %)
    for k in ("p_max", "radius", "approach"):
        assert by_fem[f"oed_{k}"] == pytest.approx(by_rings[f"oed_{k}"], abs=5e-3)
    assert by_fem["lam_best"] == pytest.approx(by_rings["lam_best"], rel=0.05)


def test_the_study_refuses_a_scene():
    from .conftest import cli

    code, _, err = cli("study", "coating-winkler", "hertz")
    assert code == 2 and "scene = 'hertz' is not allowed" in err and "Traceback" not in err
