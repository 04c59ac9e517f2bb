"""FEM reference against the half-space BEM (dissimilar bodies, layered interfaces).

Every layer law is compared: pressure within 2 % of p_max (L2 and peak), contact
radius within 2 %, approach within 1 %.
"""

import numpy as np
import pytest
from .fem_cases import E, E_SOFT, NU, NU_SOFT, P, R, e_star, hertz

import bem
import fem_reference as fr
from bem.layers import Linear, Power, Root

ES = e_star(E, NU, E_SOFT, NU_SOFT)
A_H, P0, _ = hertz(P, R, ES)
LAM = A_H / ES  # a layer compliance comparable to the bodies' own
CASES = {
    "none": None,
    "winkler": Linear(LAM),
    "power_s0.7": Power(LAM * P0**0.3, 0.7),
    "root": Root(LAM * P0**0.5),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_fem_matches_bem(gap, name):
    layer = CASES[name]
    fem = fr.solve(gap, E1=E, nu1=NU, E2=E_SOFT, nu2=NU_SOFT, force=P, layer=layer, n_contact_elements=12,
                   domain_factor=30.0)
    assert fem.converged, fem.message
    ref = bem.solve(gap, E1=E, nu1=NU, E2=E_SOFT, nu2=NU_SOFT, force=P, layer=layer,
                    step=fem.edge_radius / 25, extent=1.3 * fem.edge_radius)
    assert ref.converged
    scale = fem.p_max
    r = np.hypot(ref.x, ref.y)
    p_fem = np.interp(r, fem.r, fem.p)
    zone = (ref.p > 0) | (p_fem > 0)
    l2 = np.sqrt(np.mean((ref.p[zone] - p_fem[zone]) ** 2))
    assert l2 <= 0.02 * scale
    assert abs(ref.p_max - fem.p_max) <= 0.02 * scale
    assert ref.contact_radius == pytest.approx(fem.edge_radius, rel=0.02)
    assert ref.approach == pytest.approx(fem.approach, rel=0.01)
    assert ref.force == pytest.approx(fem.force, rel=1e-6)
