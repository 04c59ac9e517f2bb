"""Brent's root finder of the line searches (bem.brent) against SciPy's brentq and exact roots."""

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
def test_brent_root_takes_scipys_iterates_to_the_root(name):
    f = FUNCTIONS[name]
    calls = []

    def counted(t):
        calls.append(t)
        return f(t)

    root = brent_root(counted, 0.0, 1.0, f(0.0), f(1.0), xtol=1e-14, rtol=EPS)
    ours = list(calls)
    calls.clear()
    reference = brentq(counted, 0.0, 1.0, xtol=1e-14, rtol=EPS)
    assert abs(root - ROOT) <= 1e-13
    assert root == reference
    assert ours == calls[2:]  # the same points, less the two end points the caller passes


def test_brent_root_returns_an_end_point_that_is_a_root():
    assert brent_root(math.sin, 0.0, 1.0, 0.0, math.sin(1.0), xtol=1e-14, rtol=EPS) == 0.0


def test_brent_root_refuses_a_bracket_without_a_sign_change():
    with pytest.raises(ValueError, match="opposite signs"):
        brent_root(math.exp, 0.0, 1.0, 1.0, math.e, xtol=1e-14, rtol=EPS)
