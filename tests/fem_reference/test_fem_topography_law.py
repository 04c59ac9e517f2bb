"""The layer law of a rough surface (bem.rough.layer_from_topography) as the interface of the
dissimilar sphere problem: the FEM reference and the BEM give one macro answer."""

import logging

import numpy as np
import pytest
from .fem_cases import E, E_SOFT, NU, NU_SOFT, P, e_star

import bem
import fem_reference as fr
from bem import rough

pytest.importorskip("SurfaceTopography")

ES = e_star(E, NU, E_SOFT, NU_SOFT)  # MPa


@pytest.fixture(scope="module")
def topography_law():
    """A self-affine cell 0.1 mm across, rms height 1 um (units mm, MPa), 8 pressures up to 0.3 E* h'_rms."""
    surface = rough.self_affine((64, 64), (0.1, 0.1), hurst=0.8, rms_height=1e-3, long_cutoff=0.025,
                                short_cutoff=0.1 / 16, seed=1)
    pressures = np.geomspace(3e-3, 0.3, 8) * ES * surface.stats.rms_slope
    return rough.layer_from_topography(surface, ES, pressures=pressures, n_cols=64)


def test_fem_and_bem_agree_on_the_sphere_with_a_topography_law(gap, topography_law, caplog):
    """Measured (n_contact_elements = 12, BEM step a/25): approach 7.8e-5, p_max 6.1e-4, contact radius 9.4e-4
    apart (relative); the law moves the approach by +24 % and the peak by -12 % from the smooth contact."""
    law = topography_law.law
    with caplog.at_level(logging.WARNING):
        fem = fr.solve(gap, E1=E, nu1=NU, E2=E_SOFT, nu2=NU_SOFT, force=P, layer=law, n_contact_elements=12,
                       domain_factor=30.0)
        assert fem.converged, fem.message
        kw = dict(E1=E, nu1=NU, E2=E_SOFT, nu2=NU_SOFT, force=P, step=fem.edge_radius / 25,
                  extent=1.3 * fem.edge_radius)
        ref = bem.solve(gap, layer=law, **kw)
    assert ref.converged
    assert ref.approach == pytest.approx(fem.approach, rel=0.01)
    assert ref.p_max == pytest.approx(fem.p_max, rel=0.01)
    assert ref.contact_radius == pytest.approx(fem.edge_radius, rel=0.02)
    assert max(fem.p_max, ref.p_max) < topography_law.mean_pressure[-1]
    assert [r for r in caplog.records if r.levelno >= logging.WARNING] == []  # within the table's range
    smooth = bem.solve(gap, **dict(kw, extent=1.5 * fem.edge_radius))
    assert ref.approach > 1.1 * smooth.approach and ref.p_max < 0.95 * smooth.p_max  # the layer takes part


def test_fem_beyond_the_table_warns_with_the_range(gap, topography_law, caplog):
    p, w = topography_law.mean_pressure[:3], topography_law.closure[:3]
    with caplog.at_level(logging.WARNING):
        fem = fr.solve(gap, E1=E, nu1=NU, E2=E_SOFT, nu2=NU_SOFT, force=P, layer=bem.layers.Tabulated(p, w),
                       n_contact_elements=8, domain_factor=30.0)
    assert fem.converged and fem.p_max > p[-1]
    (message,) = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert message.startswith(f"FEM reference: the peak pressure p_max = {fem.p_max:.6g} exceeds the tabulated "
                              f"layer law's range 0 <= p <= {p[-1]:.6g}")
