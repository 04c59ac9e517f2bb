"""Tests of the interface-layer laws (bem.layers) against closed forms and independent methods."""

import json
import re

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from bem.checks import InputError
from bem.layers import (
    LAWS,
    Bilinear,
    Custom,
    ElasticRigid,
    Layer,
    Linear,
    Power,
    Root,
    Series,
    Tabulated,
    from_dict,
)

# ---------------------------------------------------------------------------------------------
# Laws under test: (factory, kinks [pressure], largest pressure where inverse(w(p)) == p)
# ---------------------------------------------------------------------------------------------

TABLE_P = np.linspace(0.0, 10.0, 21)
TABLE_W = 0.3 * TABLE_P**0.7


def smooth_custom_w(p):
    return 0.5 * np.sqrt(p) + 0.1 * p


LAW_CASES = {
    "linear": (lambda: Linear(2.5), [], np.inf),
    "power_0.4": (lambda: Power(1.3, 0.4), [], np.inf),
    "power_2": (lambda: Power(0.8, 2.0), [], np.inf),
    "root": (lambda: Root(0.6), [], np.inf),
    "elastic_rigid": (lambda: ElasticRigid(2.0, 1.5), [1.5], 1.5),
    "bilinear_soft": (lambda: Bilinear(1.0, 0.25, 0.8), [0.8], np.inf),
    "bilinear_stiff": (lambda: Bilinear(1.0, 4.0, 0.8), [0.8], np.inf),
    "tabulated": (lambda: Tabulated(TABLE_P, TABLE_W), list(TABLE_P[1:]), np.inf),
    "custom_numeric": (lambda: Custom(smooth_custom_w), [], np.inf),
    "series_root_linear": (lambda: Series(Root(1.0), Linear(0.2)), [], np.inf),
    "series_rigid_power": (lambda: ElasticRigid(2.0, 1.5) + Power(0.5, 1.5), [1.5], np.inf),
}
IDS = list(LAW_CASES)

# points away from every kink and table node
P_SMOOTH = np.array([0.013, 0.37, 1.13, 2.29, 4.71, 9.3, 13.7])


def law_of(name):
    return LAW_CASES[name][0]()


# ---------------------------------------------------------------------------------------------
# Closed forms derived by hand
# ---------------------------------------------------------------------------------------------

P_GRID = np.array([0.0, 0.05, 0.3, 0.79, 1.0, 1.49, 1.51, 2.7, 10.0])

CLOSED = {
    # name: (law, w, dw, W, inverse)
    "linear": (
        Linear(2.5),
        lambda p: 2.5 * p,
        lambda p: 2.5 + 0 * p,
        lambda p: 1.25 * p**2,
        lambda c: c / 2.5,
    ),
    "power_0.4": (
        Power(1.3, 0.4),
        lambda p: 1.3 * p**0.4,
        lambda p: 0.52 * p**-0.6,
        lambda p: 1.3 * p**1.4 / 1.4,
        lambda c: (c / 1.3) ** 2.5,
    ),
    "power_2": (
        Power(0.8, 2.0),
        lambda p: 0.8 * p**2,
        lambda p: 1.6 * p,
        lambda p: 0.8 * p**3 / 3,
        lambda c: np.sqrt(c / 0.8),
    ),
    "root": (
        Root(0.6),
        lambda p: 0.6 * np.sqrt(p),
        lambda p: 0.3 / np.sqrt(p),
        lambda p: 0.4 * p**1.5,
        lambda c: (c / 0.6) ** 2,
    ),
    "elastic_rigid": (
        ElasticRigid(2.0, 1.5),
        lambda p: np.where(p < 1.5, 2.0 * p, 3.0),
        lambda p: np.where(p < 1.5, 2.0, 0.0),
        lambda p: np.where(p < 1.5, p**2, 2.25 + 3.0 * (p - 1.5)),
        lambda c: np.where(c <= 3.0, c / 2.0, np.inf),
    ),
    "bilinear": (
        Bilinear(1.0, 0.25, 0.8),
        lambda p: np.where(p <= 0.8, p, 0.8 + 0.25 * (p - 0.8)),
        lambda p: np.where(p < 0.8, 1.0, 0.25),
        lambda p: np.where(p <= 0.8, p**2 / 2, 0.32 + 0.8 * (p - 0.8) + 0.125 * (p - 0.8) ** 2),
        lambda c: np.where(c <= 0.8, c, 0.8 + (c - 0.8) / 0.25),
    ),
}


@pytest.mark.parametrize("name", list(CLOSED))
def test_closed_forms(name):
    law, w, dw, energy, inverse = CLOSED[name]
    p = P_GRID[1:]
    np.testing.assert_allclose(law.w(p), w(p), rtol=1e-14)
    np.testing.assert_allclose(law.dw(p), dw(p), rtol=1e-14)
    np.testing.assert_allclose(law.energy(p), energy(p), rtol=1e-14)
    c = np.array([0.01, 0.4, 1.7, 2.9, 3.5, 12.0])
    np.testing.assert_allclose(law.inverse(c), inverse(c), rtol=1e-14)
    np.testing.assert_allclose(law.secant(p), w(p) / p, rtol=1e-14)


def test_only_linear_is_linear():
    assert Linear(1.0).is_linear
    for name in IDS:
        if name != "linear":
            assert not law_of(name).is_linear, name
    assert not Power(1.0, 1.0).is_linear


# ---------------------------------------------------------------------------------------------
# Properties checked for every law by independent methods
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", IDS)
def test_dw_matches_central_difference(name):
    law = law_of(name)
    h = 1e-6 * P_SMOOTH
    fd = (law.w(P_SMOOTH + h) - law.w(P_SMOOTH - h)) / (2 * h)
    # truncation ~ (h/p)^2 ~ 1e-12, rounding ~ eps / 1e-6 ~ 1e-10 relative
    np.testing.assert_allclose(law.dw(P_SMOOTH), fd, rtol=1e-7)


@pytest.mark.parametrize("name", IDS)
def test_energy_matches_quadrature_of_w(name):
    law = law_of(name)
    kinks = LAW_CASES[name][1]
    for p in (0.37, 1.13, 4.71, 13.7):
        points = [k for k in kinks if 0 < k < p] or None
        ref = quad(lambda s: float(law.w(s)), 0.0, p, points=points, epsabs=0, epsrel=1e-13, limit=200)[0]
        assert law.energy(p) == pytest.approx(ref, rel=1e-10), p


@pytest.mark.parametrize("name", IDS)
def test_inverse_round_trip(name):
    law = law_of(name)
    p_max = LAW_CASES[name][2]
    p = np.geomspace(1e-9, 1e3, 241)
    p = p[p <= p_max]
    np.testing.assert_allclose(law.inverse(law.w(p)), p, rtol=1e-12, atol=0)


@pytest.mark.parametrize("name", IDS)
def test_zero_pressure_and_monotone(name):
    law = law_of(name)
    assert law.w(0.0) == 0.0
    assert law.energy(0.0) == 0.0
    assert law.inverse(0.0) == 0.0
    assert law.w(-3.0) == 0.0  # p < 0 is clipped to 0
    assert np.all(law.inverse([-1.0, -1e-300]) == 0.0)
    p = np.concatenate((np.geomspace(1e-12, 1e-2, 400), np.linspace(0.0, 20.0, 200_001)))
    p.sort()
    w = law.w(p)
    assert np.all(np.diff(w) >= 0.0)
    assert np.all(np.diff(law.energy(p)) >= 0.0)
    assert np.all(law.dw(p) >= 0.0)


@pytest.mark.parametrize("name", IDS)
def test_secant_is_w_over_p_and_dw0_at_zero(name):
    law = law_of(name)
    np.testing.assert_allclose(law.secant(P_SMOOTH), law.w(P_SMOOTH) / P_SMOOTH, rtol=1e-14)
    assert law.secant(0.0) == law.dw(0.0)


@pytest.mark.parametrize(
    "law, expected",
    [
        (Root(0.6), np.inf),
        (Power(1.0, 0.3), np.inf),
        (Power(1.0, 0.99), np.inf),
        (Power(2.0, 1.0), 2.0),
        (Power(1.0, 1.5), 0.0),
        (Linear(2.5), 2.5),
        (ElasticRigid(2.0, 1.5), 2.0),
        (Bilinear(1.5, 0.2, 0.8), 1.5),
        (Custom(np.sqrt), np.inf),
        (Custom(lambda p: 3.0 * p), 3.0),
        (Series(Root(1.0), Linear(0.2)), np.inf),
        (Series(Linear(1.0), Linear(0.2)), 1.2),
    ],
    ids=lambda v: re.sub(r" at 0x[0-9a-f]+", "", repr(v)),  # stable across processes
)
def test_dw_at_zero(law, expected):
    assert law.dw(0.0) == pytest.approx(expected, rel=1e-12)
    assert law.dw(np.zeros(3)) == pytest.approx(np.full(3, expected), rel=1e-12)


def test_custom_dw_at_zero_of_smooth_nonlinear_law():
    law = Custom(lambda p: p + p**2)  # w'(0) = 1; the secant at h = 2**-40 is 1 + 2**-40
    assert law.dw(0.0) == pytest.approx(1.0, rel=1e-11)
    assert np.isfinite(Tabulated(TABLE_P, TABLE_W).dw(0.0))


@pytest.mark.parametrize("name", IDS)
def test_special_inputs_and_shapes(name):
    law = law_of(name)
    p = np.array([-1.0, -0.0, 0.0, 1.0, 1e300, np.nan])
    for method in (law.w, law.dw, law.energy, law.secant, law.inverse):
        out = method(p)
        assert out.shape == p.shape
        assert np.isnan(out[-1]), method.__name__  # NaN propagates
        assert not np.isnan(out[:-1]).any(), method.__name__
        assert np.ndim(method(0.5)) == 0
        assert method(np.full((2, 3), 0.7)).shape == (2, 3)
    assert law.w(np.inf) > 0 and law.energy(np.inf) == np.inf
    assert law.inverse(np.inf) == np.inf


@pytest.mark.parametrize("name", IDS)
def test_inputs_not_modified(name):
    law = law_of(name)
    p = np.array([-0.5, 0.0, 0.2, 1.7, 8.0])
    p.setflags(write=False)  # any in-place write would raise
    ref = p.copy()
    for method in (law.w, law.dw, law.energy, law.secant, law.inverse):
        method(p)
        method(p.tolist())
    assert np.array_equal(p, ref)


def test_tabulated_constructor_does_not_modify_inputs():
    p, w = np.array([0.5, 1.0, 2.0]), np.array([0.1, 0.3, 0.35])
    p.setflags(write=False)
    w.setflags(write=False)
    law = Tabulated(p, w)
    assert np.array_equal(p, [0.5, 1.0, 2.0]) and np.array_equal(w, [0.1, 0.3, 0.35])
    assert law.to_dict()["p"] == [0.5, 1.0, 2.0]


# ---------------------------------------------------------------------------------------------
# Law-specific checks
# ---------------------------------------------------------------------------------------------


def test_elastic_rigid_inverse_beyond_rigid_closure():
    law = ElasticRigid(2.0, 1.5)
    w_cr = 2.0 * 1.5
    assert law.inverse(w_cr) == 1.5  # smallest pressure reaching the rigid closure
    assert law.inverse(np.nextafter(w_cr, np.inf)) == np.inf
    assert np.all(law.inverse([3.1, 10.0, np.inf]) == np.inf)
    assert law.w(1e6) == w_cr
    assert law.inverse(law.w(7.0)) == 1.5
    assert Bilinear(2.0, 0.0, 1.5).inverse(3.1) == np.inf
    assert law.dw(1.5) == 0.0 and law.dw(np.nextafter(1.5, 0)) == 2.0  # right derivative


def test_bilinear_continuity_at_p_star():
    law = Bilinear(1.0, 0.25, 0.8)
    below, above = np.nextafter(0.8, 0.0), np.nextafter(0.8, 1.0)
    assert abs(law.w(above) - law.w(below)) <= 4e-16
    assert law.w(0.8) == 0.8
    assert abs(law.energy(above) - law.energy(below)) <= 4e-16
    assert law.energy(0.8) == pytest.approx(0.32, rel=1e-15)
    assert law.dw(below) == 1.0 and law.dw(0.8) == 0.25  # right derivative at the kink
    assert law.inverse(0.8) == 0.8


@pytest.mark.parametrize(
    "law, parts",
    [
        (Series(Root(1.0), Linear(0.2)), lambda p: np.sqrt(p) + 0.2 * p),
        (ElasticRigid(2.0, 1.5) + Power(0.5, 1.5), lambda p: 2.0 * min(p, 1.5) + 0.5 * p**1.5),
        (
            Series(Series(ElasticRigid(1.0, 1.0), ElasticRigid(2.0, 0.5)), Linear(1e-2)),
            lambda p: min(p, 1.0) + 2.0 * min(p, 0.5) + 1e-2 * p,
        ),
    ],
    ids=["root+linear", "rigid+power", "(rigid+rigid)+linear"],
)
def test_series_inverse_matches_brentq(law, parts):
    closures = np.array([1e-6, 0.05, 0.9, 1.99, 2.5, 7.0])
    ref = [brentq(lambda p: parts(p) - c, 0.0, 1e4, xtol=1e-300, rtol=1e-15) for c in closures]
    np.testing.assert_allclose(law.inverse(closures), ref, rtol=1e-12)


def test_series_of_rigid_layers_is_rigid_beyond_reach():
    law = ElasticRigid(1.0, 1.0) + ElasticRigid(2.0, 0.5)  # closes at most 1 + 1
    assert law.inverse(1.999) == pytest.approx(0.999, rel=1e-12)
    assert np.all(law.inverse([2.001, 5.0]) == np.inf)


def test_add_builds_series():
    law = Root(1.0) + Linear(0.2)
    assert isinstance(law, Series)
    assert law.w(4.0) == pytest.approx(2.0 + 0.8, rel=1e-15)
    assert law.energy(4.0) == pytest.approx(2 / 3 * 8 + 0.1 * 16, rel=1e-15)
    with pytest.raises(TypeError):
        Root(1.0) + 1.0


def test_tabulated_reproduces_power_law_between_samples():
    """PCHIP of ``f = 0.3 p**0.7`` on a uniform grid of step h.

    Tolerance 1: on every interval [x_k, x_k+1] (k >= 1) the error is at most the classical
    bound of the chord, h**2/8 max|f''| (monotone cubic Hermite should not be worse than linear
    interpolation of a smooth concave law). Tolerance 2: away from the p**0.7 singularity at 0
    the Fritsch-Butland derivatives are O(h**2), so the error is O(h**3): halving h must reduce
    it by at least 2**2.8 on [2, 9] (the last interval, whose end slope is the segment slope,
    is O(h**2) and is covered by tolerance 1).
    """
    f = lambda p: 0.3 * p**0.7  # noqa: E731
    f2 = lambda p: 0.3 * 0.7 * 0.3 * p**-1.3  # noqa: E731  |f''|, decreasing
    x = np.linspace(0.0, 10.0, 41)
    law = Tabulated(x, f(x))
    h = x[1] - x[0]
    np.testing.assert_array_equal(law.w(x), f(x))  # passes through the data
    for k in range(1, x.size - 1):
        q = np.linspace(x[k], x[k + 1], 51)
        assert np.max(np.abs(law.w(q) - f(q))) <= h**2 / 8 * f2(x[k]), k
    q = np.linspace(2.0, 9.0, 4001)
    errors = []
    for n in (41, 81):
        xs = np.linspace(0.0, 10.0, n)
        errors.append(np.max(np.abs(Tabulated(xs, f(xs)).w(q) / f(q) - 1)))
    assert errors[0] / errors[1] >= 2**2.8
    assert errors[1] < 1e-6


def test_tabulated_plateau_monotone_and_smallest_inverse():
    law = Tabulated([0.0, 1.0, 2.0, 3.0, 4.0, 5.0], [0.0, 1.0, 1.0, 1.0, 2.0, 2.0])
    p = np.linspace(0.0, 7.0, 700_001)
    w = law.w(p)
    assert np.all(np.diff(w) >= 0.0)
    assert np.all(w[(p >= 1.0) & (p <= 3.0)] == 1.0)  # flat data stay exactly flat
    assert law.inverse(1.0) == 1.0  # smallest pressure reaching the plateau
    assert law.inverse(2.0) == 4.0
    assert law.inverse(2.0 + 1e-9) == np.inf  # zero end slope: rigid beyond the table
    assert law.w(100.0) == 2.0


def test_tabulated_monotone_across_nodes_despite_rounding():
    """Just left of every node the cubic, evaluated in floating point, must not exceed the
    node value (raw Horner evaluation does so at about 3% of nodes of random tables)."""
    rng = np.random.default_rng(7)
    for _ in range(20):
        x = np.concatenate(([0.0], np.cumsum(rng.uniform(0.01, 3.0, 25))))
        y = np.concatenate(([0.0], np.cumsum(rng.choice([0.0, 1e-3, 1.0, 5.0], 25) * rng.uniform(size=25))))
        law = Tabulated(x, y)
        left, right = np.nextafter(x[1:], -np.inf), np.nextafter(x[1:], np.inf)
        assert np.all(law.w(left) <= y[1:]) and np.all(law.w(right) >= y[1:])
        np.testing.assert_array_equal(law.w(x), y)


def test_tabulated_extrapolation_rules():
    law = Tabulated([0.5, 1.0, 2.0], [0.2, 0.5, 0.6])  # extended by (0, 0)
    assert law.w(0.0) == 0.0
    q = np.linspace(0.0, 0.5, 101)
    assert np.all((law.w(q) >= 0.0) & (law.w(q) <= 0.2))
    # beyond the last point: linear with the last segment's slope (0.6 - 0.5) / (2 - 1)
    np.testing.assert_allclose(law.w([3.0, 7.0]), [0.7, 1.1], rtol=1e-15)
    assert law.dw(7.0) == pytest.approx(0.1, rel=1e-15)
    h = 1e-7  # C1 at the last node: the left difference quotient tends to the same slope
    assert (law.w(2.0) - law.w(2.0 - h)) / h == pytest.approx(0.1, rel=1e-5)
    assert law.inverse(1.1) == pytest.approx(7.0, rel=1e-14)
    assert law.energy(7.0) == pytest.approx(float(law.energy(2.0)) + 0.6 * 5 + 0.05 * 25, rel=1e-15)


def test_custom_with_all_callables_uses_them():
    law = Custom(
        lambda p: 0.6 * np.sqrt(p),
        dw=lambda p: 0.3 / np.sqrt(np.maximum(p, 1e-300)),
        energy=lambda p: 0.4 * p**1.5,
        inverse=lambda c: (c / 0.6) ** 2,
        p_scale=2.0,
    )
    p = np.array([0.1, 1.0, 3.0])
    np.testing.assert_allclose(law.energy(p), 0.4 * p**1.5, rtol=1e-15)
    np.testing.assert_allclose(law.inverse(0.6 * np.sqrt(p)), p, rtol=1e-15)
    assert law.inverse(-1.0) == 0.0


def test_custom_numerical_fallbacks_match_closed_forms():
    law = Custom(lambda p: 1.3 * p**0.4, p_scale=0.5)
    p = np.array([1e-3, 0.2, 1.0, 40.0])
    np.testing.assert_allclose(law.dw(p), 0.52 * p**-0.6, rtol=1e-9)
    np.testing.assert_allclose(law.energy(p), 1.3 * p**1.4 / 1.4, rtol=1e-8)
    np.testing.assert_allclose(law.inverse(1.3 * p**0.4), p, rtol=1e-12)
    assert law.dw(0.0) == np.inf
    kinked = Custom(lambda p: np.minimum(p, 0.7))  # documented: ~1e-5 across a kink
    assert kinked.energy(2.0) == pytest.approx(0.245 + 0.7 * 1.3, rel=1e-4)


# ---------------------------------------------------------------------------------------------
# Serialisation
# ---------------------------------------------------------------------------------------------

SERIALISABLE = [name for name in IDS if name != "custom_numeric"]


@pytest.mark.parametrize("name", SERIALISABLE)
def test_to_dict_from_dict_round_trip(name):
    law = law_of(name)
    d = json.loads(json.dumps(law.to_dict()))  # plain JSON values only
    again = from_dict(d)
    assert type(again) is type(law)
    assert again.to_dict() == law.to_dict()
    assert repr(again) == repr(law)
    np.testing.assert_array_equal(again.w(P_SMOOTH), law.w(P_SMOOTH))


def test_to_dict_names_the_law_and_parameters():
    assert Power(1e-3, 0.5).to_dict() == {"law": "power", "lam": 1e-3, "s": 0.5}
    assert ElasticRigid(2.0, 3.0).to_dict() == {"law": "elastic_rigid", "lam": 2.0, "p_cr": 3.0}
    assert repr(Bilinear(1.0, 0.5, 2.0)) == "Bilinear(lam1=1.0, lam2=0.5, p_star=2.0)"
    assert set(LAWS) == {
        "linear", "power", "root", "elastic_rigid", "bilinear", "tabulated", "custom", "series"
    }


def test_custom_serialises_importable_functions():
    law = Custom(np.sqrt, energy="numpy:cbrt")
    d = law.to_dict()
    assert d == {"law": "custom", "w": "numpy:sqrt", "energy": "numpy:cbrt", "p_scale": 1.0}
    again = from_dict(json.loads(json.dumps(d)))
    assert again.w(4.0) == 2.0 and again.energy(8.0) == 2.0
    lam = Custom(lambda p: p)
    assert callable(lam.to_dict()["w"]) and from_dict(lam.to_dict()).w(3.0) == 3.0


# ---------------------------------------------------------------------------------------------
# Refused input: InputError whose message starts with the offending argument or key
# ---------------------------------------------------------------------------------------------

BAD = [
    ("lam", lambda: Linear(0.0)),
    ("lam", lambda: Linear(-1.0)),
    ("lam", lambda: Power(-1.0, 0.5)),
    ("lam", lambda: Power("1", 0.5)),
    ("s", lambda: Power(1.0, 0.0)),
    ("s", lambda: Power(1.0, -0.5)),
    ("lam", lambda: Root(float("nan"))),
    ("lam", lambda: ElasticRigid(0.0, 1.0)),
    ("p_cr", lambda: ElasticRigid(1.0, 0.0)),
    ("p_cr", lambda: ElasticRigid(1.0, -2.0)),
    ("lam1", lambda: Bilinear(0.0, 1.0, 1.0)),
    ("lam2", lambda: Bilinear(1.0, -0.1, 1.0)),
    ("p_star", lambda: Bilinear(1.0, 1.0, 0.0)),
    ("p[2]", lambda: Tabulated([0.0, 1.0, 1.0, 2.0], [0.0, 1.0, 1.5, 2.0])),
    ("p[2]", lambda: Tabulated([0.0, 2.0, 1.0], [0.0, 1.0, 1.5])),
    ("w[2]", lambda: Tabulated([0.0, 1.0, 2.0], [0.0, 1.0, 0.9])),
    ("w", lambda: Tabulated([0.0, 1.0, 2.0], [0.0, np.nan, 2.0])),
    ("p", lambda: Tabulated([0.0, np.inf], [0.0, 1.0])),
    ("w[0]", lambda: Tabulated([0.0, 1.0], [0.1, 1.0])),
    ("w[0]", lambda: Tabulated([0.5, 1.0], [-0.1, 1.0])),
    ("p[0]", lambda: Tabulated([-1.0, 1.0], [0.0, 1.0])),
    ("w", lambda: Tabulated([0.0, 1.0, 2.0], [0.0, 1.0])),
    ("p", lambda: Tabulated([[0.0, 1.0]], [[0.0, 1.0]])),
    ("p", lambda: Tabulated([0.0], [0.0])),
    ("w", lambda: Custom(lambda p: p + 1.0)),
    ("w", lambda: Custom(lambda p: -p)),
    ("w", lambda: Custom(lambda p: np.sin(p))),
    ("w", lambda: Custom(lambda p: float(p))),
    ("w", lambda: Custom(lambda p: np.where(p > 10, np.nan, p))),
    ("w", lambda: Custom(3.0)),
    ("w", lambda: Custom("no_such_module_xyz:f")),
    ("dw", lambda: Custom(np.sqrt, dw="not-a-reference")),
    ("p_scale", lambda: Custom(np.sqrt, p_scale=0.0)),
    ("b", lambda: Series(Linear(1.0), 3.0)),
    ("law", lambda: from_dict({"law": "cubic", "lam": 1.0})),
    ("law", lambda: from_dict({"lam": 1.0})),
    ("layer key", lambda: from_dict({"law": "power", "lam": 1.0, "s": 0.5, "p_cr": 1.0})),
    ("s", lambda: from_dict({"law": "power", "lam": 1.0})),
    ("a.lam", lambda: from_dict({"law": "series", "a": {"law": "root", "lam": -1}, "b": {"law": "root", "lam": 1}})),
    ("b.law", lambda: from_dict({"law": "series", "a": {"law": "root", "lam": 1}, "b": {}})),
    ("layer", lambda: from_dict(["power", 1.0])),
]


@pytest.mark.parametrize("name, make", BAD, ids=[f"{i}-{n}" for i, (n, _) in enumerate(BAD)])
def test_bad_input_raises_input_error_naming_argument(name, make):
    with pytest.raises(InputError) as info:
        make()
    assert str(info.value).startswith(name + " "), str(info.value)
    assert "is not allowed" in str(info.value)


def test_unknown_key_message_names_the_key():
    with pytest.raises(InputError, match="'p_cr'"):
        from_dict({"law": "power", "lam": 1.0, "s": 0.5, "p_cr": 1.0})


def test_all_laws_are_layers():
    for name in IDS:
        assert isinstance(law_of(name), Layer)


def test_root_law_gives_its_formulas_numbers_in_place():
    """The root law evaluates in the new arrays of its clipped input: bit for bit its formulas as written, on an
    array and on a scalar, and a new array each time."""
    law, lam = Root(0.7), 0.7
    p = np.array([-1.0, -0.0, 0.0, 5e-324, 1e-300, 0.3, 2.0, 1e300, np.inf, np.nan])
    q = np.maximum(p, 0.0) + 0.0
    with np.errstate(divide="ignore", over="ignore"):
        expected = {"w": lam * np.sqrt(q), "dw": (0.5 * lam) / np.sqrt(q), "secant": lam / np.sqrt(q),
                    "energy": (2.0 / 3.0 * lam) * (q * np.sqrt(q))}
    for name, values in expected.items():
        got = getattr(law, name)(p)
        assert got.dtype == np.float64 and got.tobytes() == values.tobytes(), name
        assert not np.shares_memory(got, p) and got is not getattr(law, name)(p)
        scalar = getattr(law, name)(0.3)
        assert np.ndim(scalar) == 0 and float(scalar) == values[5], name
