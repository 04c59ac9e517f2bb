"""Brent's root finder of the line searches (bem.brent) against exact roots and SciPy's brentq."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from bem.brent import brent_root

EPS = 4 * np.finfo(float).eps
ROOT = 0.3141592653589793
FUNCTIONS = {
    "linear": lambda t: 2.0 * (t - ROOT),
    "cubic": lambda t: (t - ROOT) ** 3 + 1e-3 * (t - ROOT),
    "exp": lambda t: math.exp(5 * t) - math.exp(5 * ROOT),
    "kinked": lambda t: math.copysign(abs(t - ROOT) ** 0.3, t - ROOT),
    "sqrt_slope": lambda t: t - ROOT + 0.2 * (math.sqrt(max(0.5 - t, 0.0)) - math.sqrt(0.5 - ROOT)),
}


@pytest.mark.parametrize("name", list(FUNCTIONS))
def test_brent_root_finds_the_root_with_no_more_evaluations_than_scipy(name):
    """The root to the tolerance, every point inside the bracket, and at most one evaluation more than
    SciPy's brentq (an independent implementation of the same method) past the two end points."""
    f = FUNCTIONS[name]
    calls = []

    def counted(t):
        calls.append(t)
        return f(t)

    root = brent_root(counted, 0.0, 1.0, f(0.0), f(1.0), xtol=1e-14, rtol=EPS)
    ours = list(calls)
    calls.clear()
    reference = brentq(counted, 0.0, 1.0, xtol=1e-14, rtol=EPS)
    assert abs(root - ROOT) <= 1e-14 + EPS * ROOT
    assert abs(root - reference) <= 2 * (1e-14 + EPS * ROOT)
    assert all(0.0 < t < 1.0 for t in ours)
    assert len(ours) <= len(calls) - 2 + 1  # one more where round-off leaves the exact secant a unit off


def test_brent_root_returns_an_end_point_that_is_a_root():
    assert brent_root(math.sin, 0.0, 1.0, 0.0, math.sin(1.0), xtol=1e-14, rtol=EPS) == 0.0


def test_brent_root_refuses_a_bracket_without_a_sign_change():
    with pytest.raises(ValueError, match="opposite signs"):
        brent_root(math.exp, 0.0, 1.0, 1.0, math.e, xtol=1e-14, rtol=EPS)
