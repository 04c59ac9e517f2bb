"""Gap shapes: closed forms, symmetry, validation, round trips, table accuracy."""

import math

import numpy as np
import pytest

from bem.checks import InputError
from bem.gaps import (
    Callable,
    CrownedRoller,
    EllipticParaboloid,
    FlatPunch,
    Paraboloid,
    Table,
    gap_from_dict,
    lundberg_coefficient,
)

RNG = np.random.default_rng(20240607)
PTS = RNG.uniform(-0.9, 0.9, size=(2, 400))


def _smooth(x, y):
    return 1.0 + 0.5 * np.cos(2.0 * x) * np.sin(3.0 * y) + 0.2 * x * y


def _table(n, method="cubic", f=_smooth):
    x = np.linspace(-1.0, 1.0, n)
    y = np.linspace(-1.0, 1.0, n + 3)
    return Table(x, y, f(*np.meshgrid(x, y, indexing="ij")), method=method)


def _shapes():
    return [
        Paraboloid(0.7),
        EllipticParaboloid(0.5, 2.0),
        CrownedRoller(2.0, 0.3, "log", A=0.01),
        CrownedRoller(2.0, 0.3, "circular", crown_radius=5.0),
        CrownedRoller(2.0, 0.3, "none"),
        FlatPunch(0.2, 0.5),
        Callable(np.hypot),
        _table(12, f=lambda x, y: x * x + 3 * y * y),
    ]


# ---------------------------------------------------------------- closed forms

def test_paraboloid_closed_form():
    g = Paraboloid(2.0)
    np.testing.assert_allclose(g([0.0, 1.0, 3.0], [0.0, 1.0, 4.0]), [0.0, 0.5, 6.25], rtol=1e-15)
    np.testing.assert_allclose(g.h_r([0.0, 5.0]), [0.0, 6.25], rtol=1e-15)


def test_elliptic_paraboloid_closed_form():
    g = EllipticParaboloid(1.0, 4.0)
    np.testing.assert_allclose(g([2.0, 0.0, 2.0], [0.0, 4.0, 4.0]), [2.0, 2.0, 4.0], rtol=1e-15)
    assert not g.is_axisymmetric
    with pytest.raises(TypeError, match="not axisymmetric"):
        g.h_r(1.0)
    round_ = EllipticParaboloid(3.0, 3.0)
    assert round_.is_axisymmetric
    np.testing.assert_allclose(round_.h_r(3.0), 1.5, rtol=1e-15)


def test_roller_log_crown_closed_form():
    g = CrownedRoller(10.0, 2.0, "log", A=0.01)
    # x = 3: 1 - (2*3/10)^2 = 0.64; y = 1: y^2/(2R) = 0.25
    np.testing.assert_allclose(g(3.0, 1.0), 0.25 - 0.01 * math.log(0.64), rtol=1e-14)
    np.testing.assert_allclose(g(0.0, 0.0), 0.0, atol=0)
    assert g.domain == ((-5.0, 5.0), (-math.inf, math.inf))


def test_roller_circular_and_straight_closed_form():
    g = CrownedRoller(10.0, 2.0, "circular", crown_radius=100.0)
    np.testing.assert_allclose(g(3.0, 1.0), 0.25 + 9.0 / 200.0, rtol=1e-15)
    s = CrownedRoller(10.0, 2.0, "none")
    np.testing.assert_allclose(s([-4.9, 0.0, 4.9], 1.0), [0.25, 0.25, 0.25], rtol=1e-15)


@pytest.mark.parametrize("crown, kw", [("log", {"A": 0.01}), ("circular", {"crown_radius": 1.0}),
                                       ("none", {})])
def test_roller_ends_give_large_finite_gap(crown, kw):
    g = CrownedRoller(10.0, 2.0, crown, **kw)
    x = np.array([-7.0, -5.0, 5.0, 4.999999999, 1e9])
    h = g(x, 0.3)
    assert np.all(np.isfinite(h))
    np.testing.assert_array_equal(h[[0, 1, 2, 4]], 1e3 * 10.0)
    assert h[3] <= 1e4
    # non-decreasing in |x| along the axis (the cap keeps the log branch monotone)
    xs = np.linspace(0.0, 6.0, 2001)
    assert np.all(np.diff(g(xs, 0.0)) >= 0)


def test_lundberg_crown_compensates_a_line_load():
    """A uniform line load q = P/l on |x| < l/2 displaces the axis by
    u(x) = q/(pi E*) [asinh((l/2 - x)/y) + asinh((l/2 + x)/y)] at small y (Boussinesq);
    u(0) - u(x) must equal the Lundberg crown -A ln(1 - (2x/l)^2)."""
    P, l, E_star, y = 3.0e4, 0.02, 1.15e11, 1e-9
    A = lundberg_coefficient(P, l, E_star)
    x = np.array([0.0025, 0.005, 0.008, 0.0095])
    u = lambda x: P / l / (math.pi * E_star) * (np.arcsinh((l / 2 - x) / y) + np.arcsinh((l / 2 + x) / y))
    g = CrownedRoller(l, 0.01, "log", design_force=P, E_star=E_star)
    np.testing.assert_allclose(g(x, 0.0), u(0.0) - u(x), rtol=1e-9)
    assert g.A == A


def test_flat_punch_closed_form():
    g = FlatPunch(1.0, 0.5)
    np.testing.assert_allclose(g([0.0, 0.6, 0.0, 1.3], [0.0, 0.8, 1.0, 0.0]), [0.0, 0.0, 0.0, 0.09], rtol=1e-13)
    np.testing.assert_allclose(g.h_r([0.5, 2.0]), [0.0, 1.0], rtol=1e-15)


# ---------------------------------------------------------------- generic properties

@pytest.mark.parametrize("g", _shapes(), ids=lambda g: type(g).__name__)
def test_symmetry_nonnegative_and_origin(g):
    x, y = PTS
    h = g(x, y)
    assert h.shape == x.shape and h.dtype == float
    assert np.all(h >= 0.0)
    np.testing.assert_allclose(g(-x, y), h, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(g(x, -y), h, rtol=1e-9, atol=1e-12)
    assert abs(float(g(0.0, 0.0))) < 1e-12
    if g.is_axisymmetric:
        np.testing.assert_allclose(g(y, x), h, rtol=1e-13)
        np.testing.assert_allclose(g.h_r(np.hypot(x, y)), h, rtol=1e-13)


@pytest.mark.parametrize("g", _shapes(), ids=lambda g: type(g).__name__)
def test_broadcasting_and_inputs_unmodified(g):
    x = np.linspace(-0.5, 0.5, 4)[:, None]
    y = np.linspace(-0.4, 0.4, 3)[None, :]
    x0, y0 = x.copy(), y.copy()
    h = g(x, y)
    assert h.shape == (4, 3)
    np.testing.assert_array_equal(x, x0)
    np.testing.assert_array_equal(y, y0)
    assert x.flags.writeable and y.flags.writeable
    np.testing.assert_allclose(h[2, 1], g(float(x[2, 0]), float(y[0, 1])), rtol=1e-14)


def test_callable_gets_copies_not_the_callers_arrays():
    def greedy(x, y):
        x *= 0.0  # a careless user function modifying its arguments in place
        return np.hypot(x, y)

    g = Callable(greedy)
    x, y = np.array([1.0, 2.0]), np.array([0.0, 0.0])
    g(x, y)
    np.testing.assert_array_equal(x, [1.0, 2.0])


@pytest.mark.parametrize("g", _shapes(), ids=lambda g: type(g).__name__)
def test_dict_round_trip(g):
    d = g.to_dict()
    assert isinstance(d["type"], str)
    g2 = gap_from_dict(d)
    assert type(g2) is type(g)
    np.testing.assert_allclose(g2(*PTS), g(*PTS), rtol=1e-15)


def test_roller_dict_from_design_load_stores_A():
    g = CrownedRoller(0.02, 0.01, "log", design_force=3.0e4, E_star=1.15e11)
    d = g.to_dict()
    assert d == {"type": "crowned_roller", "length": 0.02, "R": 0.01, "crown": "log",
                 "A": 3.0e4 / (math.pi * 0.02 * 1.15e11)}


# ---------------------------------------------------------------- validation

@pytest.mark.parametrize("build, name", [
    (lambda: Paraboloid(-1.0), "R"),
    (lambda: Paraboloid(0.0), "R"),
    (lambda: Paraboloid(float("nan")), "R"),
    (lambda: EllipticParaboloid(1.0, -2.0), "Ry"),
    (lambda: EllipticParaboloid("a", 2.0), "Rx"),
    (lambda: CrownedRoller(-1.0, 1.0, "none"), "length"),
    (lambda: CrownedRoller(1.0, 0.0, "none"), "R"),
    (lambda: CrownedRoller(1.0, 1.0, "parabolic"), "crown"),
    (lambda: CrownedRoller(1.0, 1.0, "log"), "A, design_force"),
    (lambda: CrownedRoller(1.0, 1.0, "log", A=1.0, design_force=2.0), "A, design_force"),
    (lambda: CrownedRoller(1.0, 1.0, "log", A=-1.0), "A"),
    (lambda: CrownedRoller(1.0, 1.0, "log", design_force=2.0), "E_star"),
    (lambda: CrownedRoller(1.0, 1.0, "log", A=1.0, E_star=2.0), "E_star"),
    (lambda: CrownedRoller(1.0, 1.0, "log", design_force=2.0, E_star=-1.0), "E_star"),
    (lambda: CrownedRoller(1.0, 1.0, "circular"), "crown_radius"),
    (lambda: CrownedRoller(1.0, 1.0, "circular", crown_radius=1.0, A=1.0), "A"),
    (lambda: CrownedRoller(1.0, 1.0, "none", crown_radius=1.0), "crown_radius"),
    (lambda: FlatPunch(0.0, 1.0), "a"),
    (lambda: FlatPunch(1.0, -1.0), "edge_radius"),
    (lambda: Callable(3.0), "function"),
    (lambda: Callable(np.hypot, scale=0.0), "scale"),
    (lambda: Table([0, 1, 2], [0, 1, 2, 3], np.ones((3, 4))), "x"),
    (lambda: Table([0, 1, 2, 3], [0, 1, 1, 3], np.ones((4, 4))), "y[2]"),
    (lambda: Table([0, 1, 2, 3], [0, 1, 2, 3], np.ones((4, 5))), "h.shape"),
    (lambda: Table([0, 1, 2, 3], [0, 1, 2, 3], np.ones((4, 4)), method="spline"), "method"),
])
def test_bad_parameters_are_named(build, name):
    with pytest.raises(InputError, match="is not allowed") as info:
        build()
    assert name in str(info.value)


def test_callable_output_is_checked():
    with pytest.raises(InputError, match="one value per point"):
        Callable(lambda x, y: 1.0)
    with pytest.raises(InputError, match=r"f\(x, y\) = -1.0 at \(x, y\) = \(-1.0, -1.0\)"):
        Callable(lambda x, y: x)
    g = Callable(lambda x, y: np.where(x > 5.0, np.nan, 0.0))
    with pytest.raises(InputError, match=r"nan at \(x, y\) = \(6.0, 0.0\)"):
        g([0.0, 6.0], 0.0)


def test_callable_serialisation():
    with pytest.raises(InputError, match="module-level function"):
        Callable(lambda x, y: x * x).to_dict()
    g = gap_from_dict({"type": "callable", "function": "numpy:hypot"})
    np.testing.assert_allclose(g(3.0, 4.0), 5.0, rtol=1e-15)
    with pytest.raises(InputError, match="function = 'numpy:no_such'"):
        gap_from_dict({"type": "callable", "function": "numpy:no_such"})


def test_gap_from_dict_names_bad_keys():
    with pytest.raises(InputError, match=r"gap\['type'\] = 'sphere'"):
        gap_from_dict({"type": "sphere", "R": 1.0})
    with pytest.raises(InputError, match="gap key 'Rr'"):
        gap_from_dict({"type": "paraboloid", "Rr": 1.0})
    with pytest.raises(InputError, match=r"gap\['R'\]"):
        gap_from_dict({"type": "paraboloid"})
    with pytest.raises(InputError, match="R = -1.0"):
        gap_from_dict({"type": "paraboloid", "R": -1.0})
    with pytest.raises(InputError, match="gap = "):
        gap_from_dict([("type", "paraboloid")])


# ---------------------------------------------------------------- table

def test_table_reproduces_smooth_function_to_fourth_order():
    """Cubic splines: error <= 2e-6 on a 41-point grid (step 0.05) and falls
    like step**4 (measured ratio ~20 when the step halves)."""
    x, y = PTS
    errors = [np.abs(_table(n)(x, y) - _smooth(x, y)).max() for n in (41, 81)]
    assert errors[0] < 2e-6
    assert errors[0] / errors[1] > 12.0


def test_table_cubic_is_exact_for_a_quadratic_and_linear_for_bilinear():
    # not-a-knot cubic splines reproduce cubics: checks that the spline system is solved tightly
    x, y = PTS
    par = Paraboloid(0.7)
    np.testing.assert_allclose(_table(9, f=par)(x, y), par(x, y), rtol=0, atol=1e-12)
    bil = lambda x, y: 2.0 + x + 0.5 * y + 0.25 * x * y
    np.testing.assert_allclose(_table(5, "linear", f=bil)(x, y), bil(x, y), rtol=1e-14)


def test_table_refuses_points_outside_and_accepts_edges():
    t = _table(11)
    np.testing.assert_allclose(t([-1.0, 1.0], [1.0, -1.0]), _smooth(np.array([-1.0, 1.0]), np.array([1.0, -1.0])),
                               rtol=1e-12)
    t(1.0 + 1e-14, 0.0)  # round-off at the edge counts as on it
    with pytest.raises(InputError, match=r"point \(x, y\) = \(0.5, 1.25\)"):
        t([0.0, 0.5], [0.0, 1.25])
    with pytest.raises(InputError, match=r"point \(x, y\) = \(-1.5, 0.0\)"):
        t(-1.5, 0.0)
    with pytest.raises(InputError, match="inside the gap table"):
        t(np.nan, 0.0)


def test_table_refuses_nan_and_negative_entries_naming_them():
    h = np.ones((4, 5))
    h[2, 3] = np.nan
    with pytest.raises(InputError, match=r"entry \(2, 3\).*at x = 2.0, y = 3.0"):
        Table(np.arange(4.0), np.arange(5.0), h)
    h[2, 3] = -0.5
    with pytest.raises(InputError, match=r"h\[2, 3\] \(at x = 2.0, y = 3.0\) = -0.5"):
        Table(np.arange(4.0), np.arange(5.0), h)


def test_table_copies_its_data_and_clips_undershoot():
    x = np.linspace(-1.0, 1.0, 9)
    h = np.zeros((9, 9))
    h[4, 4] = 1.0  # a spike: the cubic spline rings below zero next to it
    h0, x0 = h.copy(), x.copy()
    t = Table(x, x, h)
    h[:] = 5.0
    np.testing.assert_array_equal(x, x0)
    np.testing.assert_array_equal(t.h, h0)
    xs = np.linspace(-1.0, 1.0, 201)
    values = t(xs, 0.0)
    assert values.min() == 0.0 and values.max() > 0.9
    assert t.domain == ((-1.0, 1.0), (-1.0, 1.0))
