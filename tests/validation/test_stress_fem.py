"""Subsurface stresses of the BEM against the FEM reference: root layer, dissimilar bodies.

The FEM recovers its stresses from the displacement field of an independent model (axisymmetric
quadratic elements, the layer as a penalty); the BEM's come from its contact pressure alone.
"""

import math

import numpy as np
import pytest

import bem
import fem_reference as fr
from bem.gaps import Paraboloid
from bem.layers import Root
from validation.run.stress import compare_with_fem, fem_body_stresses, peak_fit

from .conftest import e_star, hertz

E1, NU1, E2, NU2 = 200e3, 0.3, 70e3, 0.2  # MPa: steel on aluminium
R, P = 10.0, 100.0  # mm, N
ES = e_star(E1, NU1, E2, NU2)
A_H, P0, _ = hertz(P, R, ES)


@pytest.fixture(scope="module")
def solutions():
    layer = Root(A_H / ES * math.sqrt(P0))  # closes like the bodies themselves near the peak
    fem = fr.solve(Paraboloid(R), E1=E1, nu1=NU1, E2=E2, nu2=NU2, force=P, layer=layer, n_contact_elements=16,
                   domain_factor=30.0)
    assert fem.converged, fem.message
    res = bem.solve(Paraboloid(R), E1=E1, nu1=NU1, E2=E2, nu2=NU2, force=P, layer=layer,
                    step=fem.edge_radius / 25, extent=1.3 * fem.edge_radius)
    assert res.converged
    depths = np.linspace(0.0, 1.5, 31) * A_H
    stresses = {name: bem.subsurface_stress(res, depths, nu=nu) for name, nu in (("body1", NU1), ("body2", NU2))}
    return res, fem, stresses, fem_body_stresses(fem)


@pytest.mark.parametrize("name", ["body1", "body2"])
def test_von_mises_maximum_and_its_depth_within_2_percent(solutions, name):
    res, _, stresses, fem = solutions
    cmp = compare_with_fem(res, stresses[name], fem[name])
    assert abs(cmp["max_von_mises_rel"]) <= 0.02, cmp["max_von_mises_rel"]
    assert abs(cmp["max_tresca_rel"]) <= 0.02, cmp["max_tresca_rel"]
    assert abs(cmp["axis_depth_of_max_rel"]) <= 0.02, cmp["axis_depth_of_max_rel"]
    assert cmp["on_axis"]
    # the BEM maximum lies on the axis, where the FEM's depth is taken
    assert math.hypot(*stresses[name].location_of_max[:2]) <= res.step


@pytest.mark.parametrize("name", ["body1", "body2"])
def test_axis_profiles_agree(solutions, name):
    """The whole von Mises profile on the axis, FEM nodes against the BEM there (within 1 % of its peak)."""
    res, _, stresses, fem = solutions
    f = fem[name]
    axis = (f["r"] <= 1e-12) & (f["depth"] >= 0.05 * A_H) & (f["depth"] <= 2.5 * A_H)
    depth, vm = f["depth"][axis], f["von_mises"][axis]
    bem_vm = bem.subsurface_stress(res, depth, nu=stresses[name].nu, x=[0.0], y=[0.0]).von_mises[:, 0]
    assert np.max(np.abs(bem_vm - vm)) <= 0.01 * bem_vm.max()


def test_peak_fit_recovers_a_parabola_and_falls_back():
    z = np.linspace(0.0, 1.0, 21)
    value, depth = peak_fit(z, 2.0 - 3.0 * (z - 0.437) ** 2)
    assert value == pytest.approx(2.0, abs=1e-12) and depth == pytest.approx(0.437, abs=1e-12)
    assert peak_fit([0.0, 1.0], [1.0, 3.0]) == (3.0, 1.0)
