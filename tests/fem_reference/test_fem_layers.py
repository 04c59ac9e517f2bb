"""Layered interface: the layer-dominated limit p = w^{-1}(delta - h) and nonlinear laws."""

import numpy as np
import pytest
from .fem_cases import E, E_SOFT, NU, NU_SOFT, P, R, e_star

import fem_reference as fr
from bem.layers import Bilinear, ElasticRigid, Linear, Power

ES = e_star(E, NU, E_SOFT, NU_SOFT)
A_REF = 0.4  # mm, contact radius of the layer-dominated cases
DELTA = A_REF**2 / (2 * R)  # h(A_REF) = delta: rigid bodies on the layer touch out to A_REF


@pytest.mark.parametrize("kind", ["linear", "power_s0.5"])
def test_layer_dominated_limit(gap, kind):
    """Very soft layer: elastic displacement ~1e-3 of the layer closure, so p(r) = w^{-1}(delta - h(r))."""
    soft = 1e3 * A_REF / ES  # secant compliance of the layer, >> a / E*
    p_ref = DELTA / soft
    layer = Linear(soft) if kind == "linear" else Power(DELTA / p_ref**0.5, 0.5)
    inverse = (lambda g: g / soft) if kind == "linear" else (lambda g: (g / DELTA) ** 2 * p_ref)
    res = fr.solve(gap, E1=E, nu1=NU, E2=E_SOFT, nu2=NU_SOFT, approach=DELTA, layer=layer,
                   n_contact_elements=8, domain_factor=30.0)
    assert res.converged, res.message
    expected = inverse(np.clip(DELTA - res.r**2 / (2 * R), 0, None))
    np.testing.assert_allclose(res.p, expected, atol=5e-3 * expected.max())
    assert res.edge_radius == pytest.approx(A_REF, rel=5e-3)
    # force of the rigid-body solution: 2 pi int r w^{-1}(delta - r^2/2R) dr (closed forms)
    exact_force = np.pi * R * DELTA**2 / soft if kind == "linear" else 2 * np.pi * R * DELTA * p_ref / 3
    assert res.force == pytest.approx(exact_force, rel=5e-3)
    assert res.force_reaction == pytest.approx(res.force, rel=1e-8)


@pytest.mark.parametrize("name", ["power_s2", "elastic_rigid", "bilinear"])
def test_nonlinear_laws_satisfy_the_contact_conditions(gap, name):
    """Force control converges; in contact the overlap is w(p), outside the surfaces are open."""
    lam = 0.3 / ES  # compliance comparable to the bodies' (a ~ 0.2 mm)
    p_ref = 600.0  # about the peak pressure with this layer (the Hertz peak is 834 MPa)
    layer = {"power_s2": Power(lam / p_ref, 2.0), "elastic_rigid": ElasticRigid(lam, 0.6 * p_ref),
             "bilinear": Bilinear(lam, 0.1 * lam, 0.5 * p_ref)}[name]
    res = fr.solve(gap, E1=E, nu1=NU, E2=E_SOFT, nu2=NU_SOFT, force=P, layer=layer, n_contact_elements=8,
                   domain_factor=30.0)
    assert res.converged, res.message
    assert res.force == pytest.approx(P, rel=1e-8)
    assert np.all(np.isfinite(res.p)) and np.all(res.p >= 0)
    on = (res.p > 0) & (res.r > 0)
    w = np.asarray(layer.w(res.p[on]))
    if name == "elastic_rigid":
        rigid = res.p[on] > 0.6 * p_ref
        assert rigid.any() and res.p_max > 0.6 * p_ref
        # the rigid branch is only entered by the penalty's small overshoot
        assert res.penalty["max_penetration"] < 1e-3 * res.approach
        np.testing.assert_allclose(res.overlap[on][~rigid], w[~rigid], rtol=1e-6, atol=1e-9 * res.approach)
    else:
        np.testing.assert_allclose(res.overlap[on], w, rtol=1e-6, atol=1e-9 * res.approach)
    assert np.all(res.overlap[(res.p == 0) & (res.r > 0)] <= 0)
    assert 0.15 < res.edge_radius < 0.5
