"""A coating's bond in the FEM reference: one-sided stress recovery (fem_reference.fields.one_sided_stresses)
on a strain linear in depth (exact in the quadratic space), where each material's stress is Hooke's law of
its own constants, and the mesh
refinement around a bond deeper than the contact radius (fem_reference.mesh)."""

import numpy as np
import pytest

from bem.coating import Coating
from fem_reference.fields import nodal_stresses, one_sided_stresses
from fem_reference.mesh import build_mesh
from fem_reference.model import AxiModel, lame

E, NU = 1.0, 0.3


def _hooke(E, nu, e_rr, e_zz):
    lam, mu = lame(E, nu)
    tr = lam * (2 * e_rr + e_zz)
    return {"sigma_rr": tr + 2 * mu * e_rr, "sigma_tt": tr + 2 * mu * e_rr, "sigma_zz": tr + 2 * mu * e_zz,
            "sigma_rz": 0.0}


def test_each_side_of_the_bond_keeps_its_own_materials_stress():
    t, coating = 0.5, Coating(0.5, 10.0 * E, 0.4)
    model = AxiModel(build_mesh(1.0, n_contact_elements=4, domain_factor=12.0, coating_thickness=(None, t)),
                     E1=E, nu1=NU, E2=E, nu2=NU, coating2=coating)
    r, z = model.scalar_basis.doflocs
    e_rr, e_zz = 1e-3, -2e-3 + 1e-3 * z  # u_z = -2e-3 z + 5e-4 z^2: the strain varies from node to node
    u = np.zeros(model.n_dofs)
    u[0::2], u[1::2] = e_rr * r, -2e-3 * z + 5e-4 * z**2
    lower, coated = model.amesh.body == 1, model.amesh.coated
    bond = np.isclose(z, -t, rtol=0, atol=1e-12)
    assert bond.sum() > 10 and np.any(bond & (r == 0.0))  # the axis point of the bond included (hoop limit)
    for elements, material in ((lower & coated, (coating.E, coating.nu)), (lower & ~coated, (E, NU))):
        s = one_sided_stresses(model, u, elements)
        nodes = np.unique(model.scalar_basis.element_dofs[:, elements])
        assert np.array_equal(np.nonzero(s["nodes"])[0], nodes) and np.all(s["nodes"][bond])
        assert np.all(np.isnan(s["sigma_zz"][~s["nodes"]]))
        for name, value in _hooke(*material, e_rr, e_zz).items():
            np.testing.assert_allclose(s[name][nodes], (value + 0 * z)[nodes], rtol=0, atol=1e-12)
    # the continuous projection takes neither material's value at the bond
    projected = nodal_stresses(model, u)["sigma_rr"][bond]
    rr = [_hooke(*m, e_rr, e_zz)["sigma_rr"][bond] for m in ((coating.E, coating.nu), (E, NU))]
    assert np.all(np.abs(projected - rr[0]) > 0.05 * np.abs(rr[0]))
    assert np.all(np.abs(projected - rr[1]) > 0.05 * np.abs(rr[0]))


def _bond_facets_between(mesh, t, r0, r1):
    """Lengths of the mesh facets lying on the bond z = -t whose midpoints have r0 <= r <= r1."""
    x, f = mesh.mesh.p, mesh.mesh.facets
    on_bond = np.isclose(x[1, f[0]], -t, rtol=0, atol=1e-12) & np.isclose(x[1, f[1]], -t, rtol=0, atol=1e-12)
    mid_r = 0.5 * (x[0, f[0]] + x[0, f[1]])
    chosen = on_bond & (mid_r >= r0) & (mid_r <= r1)
    return np.hypot(*(x[:, f[0]] - x[:, f[1]]))[chosen]


@pytest.mark.parametrize("n", [8, 16])
def test_a_deep_bond_is_meshed_at_the_contact_zones_resolution_scaled_by_its_depth(n):
    t = 4.0  # four contact radii deep: outside the contact's fine zone (sizes 0.7 to 0.8 there by its grading)
    mesh = build_mesh(1.0, n_contact_elements=n, coating_thickness=(None, t))
    h_bond = t / n  # h_fine t / a_est, within fine_radius t / a_est of the bond's point on the axis
    near_axis, off_axis = _bond_facets_between(mesh, t, 0.0, 0.5 * t), _bond_facets_between(mesh, t, t, 1.5 * t)
    assert near_axis.size > 2 and off_axis.size > 2
    assert 0.7 * h_bond < np.median(near_axis) < 1.05 * h_bond and near_axis.max() < 1.1 * h_bond
    # a bond radius away from the axis the size is still h_bond (the refinement is centred on the bond)
    assert off_axis.max() < 1.1 * h_bond
