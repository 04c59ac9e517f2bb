"""A priori contact radius (mesh sizing) against closed forms."""

import math

import numpy as np
import pytest
from tests.fem_reference.fem_cases import E, NU, P, R, e_star, hertz

import bem.reference as fr
from bem.checks import InputError
from bem.gaps import Paraboloid
from bem.layers import Linear

ES = e_star(E, NU, E, NU)


def test_hertz_radius_force_and_approach():
    a, _, delta = hertz(P, R, ES)
    gap = Paraboloid(R)
    assert fr.hertz_radius(gap, E_star=ES, force=P) == pytest.approx(a, rel=1e-10)
    assert fr.hertz_radius(gap, E_star=ES, approach=delta) == pytest.approx(a, rel=1e-10)
    # a non-paraboloidal gap: h = c r^4 -> 8 E* a c a^4 = 3 P
    c = 2.0
    quartic = lambda x, y: c * (x * x + y * y) ** 2  # noqa: E731
    assert fr.hertz_radius(quartic, E_star=ES, force=P) == pytest.approx((3 * P / (8 * ES * c)) ** 0.2, rel=1e-10)


def test_layer_radius_winkler_closed_form():
    """Rigid paraboloid on a Winkler layer: P = pi a^4 / (4 R lam)."""
    lam = 1e-4
    a_L = fr.layer_radius(Paraboloid(R), Linear(lam), force=P)
    assert a_L == pytest.approx((4 * R * lam * P / math.pi) ** 0.25, rel=1e-8)
    assert fr.layer_radius(Paraboloid(R), Linear(lam), approach=0.01) == pytest.approx(math.sqrt(2 * R * 0.01))


def test_estimate_combines_bodies_and_layer():
    lam, gap = 1e-4, Paraboloid(R)
    a_H = hertz(P, R, ES)[0]
    a_L = (4 * R * lam * P / math.pi) ** 0.25
    est = fr.estimate_contact_radius(gap, E_star=ES, force=P, layer=Linear(lam))
    assert est == pytest.approx((a_H**3 + a_L**3) ** (1 / 3), rel=1e-8)
    assert est > max(a_H, a_L)
    assert fr.estimate_contact_radius(gap, E_star=ES, force=P) == pytest.approx(a_H, rel=1e-10)


def test_flat_gap_cannot_be_estimated():
    with pytest.raises(InputError, match="a_est"):
        fr.estimate_contact_radius(lambda x, y: np.zeros_like(x), E_star=ES, force=P)
    with pytest.raises(InputError, match="force"):
        fr.estimate_contact_radius(Paraboloid(R), E_star=ES, force=P, approach=0.1)
