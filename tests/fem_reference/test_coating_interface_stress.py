"""The tractions at a coating's interface: the Hankel sum of :mod:`bem.coating_fields` under the FEM's own
contact pressure against the FEM's recovered stresses there (a sphere on a coated flat)."""

import numpy as np
import pytest

from bem.coating import Coating
from bem.coating_fields import axisymmetric_stress
from bem.gaps import Paraboloid
from fem_reference import solve
from fem_reference.fields import nodal_stresses

E, NU, R, A = 1.0, 0.3, 1.0, 0.1


@pytest.mark.slow
@pytest.mark.parametrize("ratio", [10.0, 0.1])
def test_interface_tractions_equal_the_fem_under_its_own_pressure(ratio):
    # a/t = 1: the interface at the depth of Hertz's largest shear; stiff and soft coatings
    t = A
    coating = Coating(t, ratio * E, NU)
    force = 4 * (E / (2 * (1 - NU**2))) * A**3 / (3 * R)
    res = solve(Paraboloid(R), E1=E, nu1=NU, E2=E, nu2=NU, coating2=coating, force=force, n_contact_elements=24)
    assert res.converged, res.message
    s = nodal_stresses(res.model, res.displacement_dofs)
    r, z = res.model.scalar_basis.doflocs
    on = np.isclose(z, -t, rtol=0, atol=1e-9 * t) & (r < 1.5 * res.edge_radius)  # body 2 lies below z = 0
    assert on.sum() > 20
    rho = r[on]
    edge = float(res.r[res.p > 0].max()) * 1.02
    ours = axisymmetric_stress(lambda x: np.interp(x, res.r, res.p, right=0.0), edge, rho, [t], coating, E, NU,
                               side="substrate")
    szz, srz = ours["szz"][:, 0], -ours["srz"][:, 0]  # the FEM's z points up: sigma_rz changes sign
    assert np.abs(s["sigma_zz"][on] - szz).max() <= 0.01 * np.abs(szz).max()
    assert np.abs(s["sigma_rz"][on] - srz).max() <= 0.02 * np.abs(srz).max()
