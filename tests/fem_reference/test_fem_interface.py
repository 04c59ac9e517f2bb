"""Interface law p(g): the bem.layers law as a penalty; tangent, potential, rigid branch."""

import numpy as np
import pytest

from bem.layers import Bilinear, ElasticRigid, Linear, Power, Root
from fem_reference.interface import InterfaceLaw

K = 1e6
G = np.linspace(-0.02, 0.05, 141)

LAWS = {
    "linear": (Linear(0.01), lambda g: np.maximum(g, 0) / 0.01),
    "power_s0.5": (Power(0.02, 0.5), lambda g: (np.maximum(g, 0) / 0.02) ** 2),
    "power_s2": (Power(1e-4, 2.0), lambda g: np.sqrt(np.maximum(g, 0) / 1e-4)),
    "root": (Root(0.03), lambda g: (np.maximum(g, 0) / 0.03) ** 2),
    "bilinear": (Bilinear(0.01, 0.002, 2.0),
                 lambda g: np.where(g <= 0.02, np.maximum(g, 0) / 0.01, 2.0 + (g - 0.02) / 0.002)),
}


@pytest.mark.parametrize("name", sorted(LAWS))
def test_pressure_is_the_inverse_law(name):
    layer, exact = LAWS[name]
    law = InterfaceLaw(layer, K)
    g = G.copy()
    np.testing.assert_allclose(law.pressure(g), exact(G), rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(g, G)  # input untouched


@pytest.mark.parametrize("name", sorted(LAWS))
def test_potential_derivative_is_pressure_and_tangent_is_its_slope(name):
    layer, exact = LAWS[name]
    law = InterfaceLaw(layer, K)
    g = np.linspace(0.003, 0.045, 29)
    step = 1e-7
    dpsi = (law.potential(g + step) - law.potential(g - step)) / (2 * step)
    np.testing.assert_allclose(dpsi, exact(g), rtol=1e-6)
    dp = (exact(g + step) - exact(g - step)) / (2 * step)
    np.testing.assert_allclose(law.tangent(g), np.minimum(dp, K), rtol=1e-5)
    assert np.all(law.potential(np.array([-1.0, 0.0])) == 0.0)
    assert np.all(law.tangent(np.array([-1.0, 0.0])) == 0.0)


def test_infinite_tangents_are_regularised():
    # power s > 1: dp/dg -> inf at g -> 0+: capped at k_pen
    law = InterfaceLaw(Power(1e-4, 2.0), K)
    t = law.tangent(np.array([1e-300, 1e-20, 1e-2]))
    assert np.all(np.isfinite(t)) and t[0] == K and t[1] == K and t[2] < K
    # root: dw = inf at p = 0 -> dp/dg = 0 there
    law = InterfaceLaw(Root(0.03), K)
    assert law.tangent(np.array([1e-300]))[0] == pytest.approx(0.0, abs=1e-200)


def test_rigid_branch_continued_by_penalty():
    lam, p_cr = 0.01, 2.0
    law = InterfaceLaw(ElasticRigid(lam, p_cr), K)
    g = np.array([0.005, 0.02 - 1e-9, 0.02 + 1e-4, 0.021])
    p = law.pressure(g)
    np.testing.assert_allclose(p[:2], g[:2] / lam, rtol=1e-9)
    np.testing.assert_allclose(p[2:], p_cr + K * (g[2:] - lam * p_cr), rtol=1e-6)
    g_lim, p_lim = law.rigid_limit()
    assert g_lim == pytest.approx(lam * p_cr, rel=1e-12) and p_lim == pytest.approx(p_cr, rel=1e-9)
    np.testing.assert_array_equal(law.tangent(g[2:]), K)
    # the potential stays the integral of p across the kink
    a, b = 0.015, 0.0205
    x, w = np.polynomial.legendre.leggauss(40)
    kink = lam * p_cr
    quad = sum(0.5 * (hi - lo) * np.sum(w * law.pressure(0.5 * (hi - lo) * x + 0.5 * (hi + lo)))
               for lo, hi in ((a, kink), (kink, b)))
    assert law.potential(np.array([b]))[0] - law.potential(np.array([a]))[0] == pytest.approx(quad, rel=1e-9)


def test_penalty_without_layer():
    law = InterfaceLaw(None, K)
    np.testing.assert_array_equal(law.pressure(G), K * np.maximum(G, 0))
    np.testing.assert_array_equal(law.tangent(G), np.where(G > 0, K, 0.0))
    np.testing.assert_allclose(law.potential(G), 0.5 * K * np.maximum(G, 0) ** 2)
