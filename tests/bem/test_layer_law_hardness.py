"""The layer law of plastic asperities (bem.rough.layer_from_topography with a hardness): its checks, the
comparison with the elastic law at the same mean pressures, the elastic limit (large hardness), the
rigid-plastic limit (the bearing-area curve) and the table file."""

import math
import re
import tomllib

import numpy as np
import pytest

from bem import InputError, rough

pytest.importorskip("SurfaceTopography")

E_STAR = 1.0
N = 64  # grid points and lattice nodes across the cell


@pytest.fixture(scope="module")
def surface():
    """Hurst 0.8, roll-off at L/4, cut-off at L/16 (4 lattice steps), rms height 0.05 L."""
    return rough.self_affine((N, N), (1.0, 1.0), hurst=0.8, rms_height=0.05, long_cutoff=0.25, short_cutoff=1 / 16,
                             seed=2)


@pytest.fixture(scope="module")
def ladder(surface):
    """Mean pressures 3e-3 .. 0.3 E* h'_rms, and the hardness 0.5 E* h'_rms: the elastic peaks exceed it."""
    scale = E_STAR * surface.stats.rms_slope
    return np.geomspace(3e-3, 0.3, 8) * scale, 0.5 * scale


@pytest.fixture(scope="module")
def laws(surface, ladder):
    p, hardness = ladder
    elastic = rough.layer_from_topography(surface, E_STAR, pressures=p, n_cols=N)
    plastic = rough.layer_from_topography(surface, E_STAR, pressures=p, n_cols=N, hardness=hardness)
    return elastic, plastic


@pytest.mark.parametrize("value, rule", [(0.0, "> 0"), (-1.0, "> 0"), (math.nan, "finite"), (math.inf, "finite"),
                                         ("1e9", "a real number"), (True, "a real number")])
def test_a_bad_hardness_is_refused_by_name_before_any_solve(surface, ladder, value, rule):
    calls = []
    with pytest.raises(InputError, match=r"^hardness = .* is not allowed: it must be " + re.escape(rule)):
        rough.layer_from_topography(surface, E_STAR, pressures=ladder[0], n_cols=N, hardness=value,
                                    progress=lambda *a: calls.append(a))
    assert not calls


def test_a_ladder_reaching_the_hardness_is_refused_naming_both(surface, ladder):
    p = ladder[0]
    with pytest.raises(InputError, match=r"^pressures\[7\] = .* must be < hardness = "):
        rough.layer_from_topography(surface, E_STAR, pressures=p, n_cols=N, hardness=float(p[-1]))


def test_plastic_asperities_close_more_and_touch_more_than_elastic_ones(laws):
    """At the same mean pressure the capped pressure spreads the load: a larger real contact area, a
    larger approach (the flattening), so a larger closure and a smaller mean gap; the cell flows
    where the elastic peaks exceed the hardness."""
    elastic, plastic = laws
    ubar0 = elastic.first_touch_gap
    assert plastic.first_touch_gap == elastic.first_touch_gap  # the same surface, the same first touch
    tol = 1e-8 * ubar0  # the solver's tolerance on the mean gap
    assert np.all(plastic.closure >= elastic.closure - tol)
    assert np.all(plastic.mean_gap <= elastic.mean_gap + tol)
    assert np.all(plastic.contact_fraction >= elastic.contact_fraction)
    assert plastic.closure[-1] > elastic.closure[-1] * 1.05  # a real effect, not the tolerance
    assert plastic.contact_fraction[-1] > elastic.contact_fraction[-1] * 1.1
    assert np.all(plastic.plastic_fraction <= plastic.contact_fraction)
    assert plastic.plastic_fraction[-1] > 0 and np.all(np.diff(plastic.plastic_fraction) >= 0)
    assert np.all(np.diff(plastic.closure) > 0)  # still a convex layer energy
    assert elastic.hardness is None and elastic.plastic_fraction is None
    assert plastic.hardness == pytest.approx(0.5 * E_STAR * plastic.stats.rms_slope, rel=1e-15)


def test_a_hardness_far_above_the_peaks_gives_the_elastic_law(surface, ladder, laws):
    elastic = laws[0]
    stiff = rough.layer_from_topography(surface, E_STAR, pressures=ladder[0], n_cols=N, hardness=1e6 * ladder[1])
    np.testing.assert_array_equal(stiff.plastic_fraction, 0.0)
    np.testing.assert_allclose(stiff.closure, elastic.closure, rtol=0, atol=1e-8 * elastic.first_touch_gap)
    np.testing.assert_array_equal(stiff.contact_fraction, elastic.contact_fraction)


def test_soft_asperities_follow_the_bearing_area_curve(surface):
    """Rigid-plastic limit: with a hardness far below ``E* h'_rms`` the elastic displacements are
    negligible (of order ``H L / E*``), every node in contact flows, ``A/A0 = p/H``, and the approach is
    the height at which the share ``p/H`` of the cell lies above the plane: the quantile of the initial
    gap ``h`` (Abbott and Firestone's bearing-area curve), computed here from the lattice's heights."""
    hardness = 1e-3 * E_STAR * surface.stats.rms_slope
    share = np.array([0.02, 0.05, 0.1, 0.2, 0.4])
    law = rough.layer_from_topography(surface, E_STAR, pressures=share * hardness, n_cols=N, hardness=hardness)
    h = np.sort(surface.to_lattice(N).gap().ravel())
    bearing = h[np.ceil(share * h.size).astype(int) - 1]  # the share of the nodes at or below the plane
    elastic_scale = hardness * surface.size[0] / E_STAR  # displacements under a pressure <= H over the cell
    rms = surface.stats.rms_height
    assert elastic_scale < 0.05 * rms
    np.testing.assert_allclose(law.contact_fraction, share, atol=0.01)
    np.testing.assert_allclose(law.plastic_fraction, law.contact_fraction, atol=0.01)
    np.testing.assert_allclose(law.closure, bearing, atol=0.05 * rms)


def test_the_table_file_records_the_hardness_and_reads_it_back(laws, tmp_path):
    elastic, plastic = laws
    path = plastic.save(tmp_path / "plastic.toml")
    text = path.read_text(encoding="utf-8")
    assert "hardness H = " in text  # the head comment names it
    topo = tomllib.loads(text)["topography"]
    assert topo["hardness"] == plastic.hardness and len(topo["plastic_fraction"]) == plastic.mean_pressure.size
    back = rough.read_layer_law(path)
    assert back.hardness == plastic.hardness
    np.testing.assert_array_equal(back.plastic_fraction, plastic.plastic_fraction)
    np.testing.assert_array_equal(back.closure, plastic.closure)
    assert "hardness" not in tomllib.loads(elastic.save(tmp_path / "elastic.toml").read_text())["topography"]
    assert rough.read_layer_law(tmp_path / "elastic.toml").hardness is None
