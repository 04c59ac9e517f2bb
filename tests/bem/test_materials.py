"""Effective modulus E* (Johnson 1985, sec. 4.2)."""

import math

import pytest

from bem.checks import InputError
from bem.materials import compliance, effective_modulus


def test_identical_steel_bodies():
    # 1/E* = 2 (1 - 0.09) / 210e9  ->  E* = 210e9 / 1.82
    assert effective_modulus(210e9, 0.3, 210e9, 0.3) == pytest.approx(1.1538461538461538e11, rel=1e-15)


def test_dissimilar_bodies_and_symmetry():
    # steel on aluminium: 1/E* = 0.91/210e9 + 0.8911/70e9
    expected = 1.0 / (0.91 / 210e9 + (1 - 0.33**2) / 70e9)
    assert effective_modulus(210e9, 0.3, 70e9, 0.33) == pytest.approx(expected, rel=1e-15)
    assert effective_modulus(70e9, 0.33, 210e9, 0.3) == pytest.approx(expected, rel=1e-15)


def test_rigid_counterpart_and_limits_of_nu():
    assert effective_modulus(3e9, 0.4, math.inf, 0.0) == pytest.approx(3e9 / 0.84, rel=1e-15)
    assert effective_modulus(math.inf, 0.2, 3e9, 0.5) == pytest.approx(3e9 / 0.75, rel=1e-15)  # incompressible ok
    assert effective_modulus(1.0, -0.99, 1.0, -0.99) == pytest.approx(1.0 / (2 * (1 - 0.99**2)), rel=1e-12)
    assert compliance(math.inf, 0.3) == 0.0
    assert compliance(2.0, 0.0) == 0.5


@pytest.mark.parametrize("args, name", [
    ((-210e9, 0.3, 210e9, 0.3), "E1 = -210000000000.0"),
    ((210e9, 0.3, 0.0, 0.3), "E2 = 0.0"),
    ((210e9, 0.3, float("nan"), 0.3), "E2 = nan"),
    ((210e9, -1.0, 210e9, 0.3), "nu1 = -1.0"),
    ((210e9, 0.3, 210e9, 0.51), "nu2 = 0.51"),
    ((210e9, True, 210e9, 0.3), "nu1 = True"),
    ((math.inf, 0.3, math.inf, 0.3), "(E1, E2)"),
])
def test_bad_input_is_named(args, name):
    with pytest.raises(InputError, match="is not allowed") as info:
        effective_modulus(*args)
    assert name in str(info.value)
