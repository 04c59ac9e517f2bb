"""Limits of a coated contact in the solver: a thin coating on a rigid base against the paper's Winkler layer.

A sphere (``E1, nu1``, Hertz radius ``a`` on the rigid base) pressed on a rigid base carrying a bonded
coating of thickness ``t``. As ``t / a -> 0`` a compressible coating acts as the linear layer
``w = lam p`` of its oedometric compliance ``lam = t (1 + nu)(1 - 2 nu) / ((1 - nu) E)``
(:func:`bem.coating.oedometric_compliance`); an incompressible one has ``lam = 0`` and is no Winkler
layer: its compliance is of order ``t^3 q^2``, yet its pressure stays finite.
"""

import math

import numpy as np
import pytest

import bem
from bem import layers
from bem.coating import oedometric_compliance
from bem.gaps import Paraboloid
from bem.reference import hertz_sphere

E1, NU1, R, A = 1.0, 0.3, 1.0, 0.3
E_STAR = bem.effective_modulus(E1, NU1, math.inf, 0.3)
FORCE = 4 * E_STAR * A ** 3 / (3 * R)
KW = dict(force=FORCE, step=A / 12, extent=2.5 * A, E1=E1, nu1=NU1, E2=math.inf, nu2=0.3, rtol=1e-10)


def _pair(a_over_t, nu_c, E_c=0.2):
    coating = bem.Coating(A / a_over_t, E_c, nu_c)
    coated = bem.solve(Paraboloid(R), coating2=coating, **KW)
    lam = oedometric_compliance(coating)
    winkler = bem.solve(Paraboloid(R), layer=layers.Linear(lam) if lam > 0 else None, **KW)
    assert coated.converged and winkler.converged
    assert coated.kkt_residual <= 1e-10
    return coated, winkler


def _misfit(coated, winkler):
    return max(abs(coated.p.max() / winkler.p.max() - 1), abs(coated.approach / winkler.approach - 1))


def test_a_thin_compressible_coating_on_a_rigid_base_tends_to_its_oedometric_layer():
    misfit = {r: _misfit(*_pair(r, 0.3)) for r in (5, 20, 40)}
    # measured 1.6e-3, 2.0e-5, 1.1e-5 (p_max and approach)
    assert misfit[40] <= 5e-5
    assert misfit[5] >= 20 * misfit[40]
    # the layer is not negligible: the oedometric layer changes the approach by far more than the misfit
    coated, winkler = _pair(40, 0.3)
    bare = bem.solve(Paraboloid(R), **KW)
    assert abs(winkler.approach / bare.approach - 1) >= 100 * misfit[40]


def test_an_incompressible_coating_is_no_winkler_layer_and_its_pressure_stays_finite():
    coated, bare = _pair(5, 0.5)  # oedometric compliance 0: the Winkler model is the bare rigid base
    assert np.all(np.isfinite(coated.p))
    hertz = hertz_sphere(R, E_STAR, force=FORCE)
    assert coated.p.max() <= 1.05 * hertz.p_max
    # the coating still deforms (its compliance is of order t^3 q^2): measured 2.5 % more approach
    assert coated.approach / bare.approach - 1 >= 1e-2
    thinner, _ = _pair(20, 0.5)
    assert np.all(np.isfinite(thinner.p))
    assert thinner.approach / bare.approach - 1 <= 0.1 * (coated.approach / bare.approach - 1)  # measured 6.2e-4


@pytest.mark.parametrize("nu_c", [0.45, 0.499])
def test_nearly_incompressible_coatings_converge_with_finite_pressure(nu_c):
    coated, _ = _pair(5, nu_c)
    assert np.all(np.isfinite(coated.p)) and coated.p.max() > 0


def test_coatings_a_thousandth_of_a_step_and_a_thousand_regions_thick_give_their_limits():
    """On the half-space region: ``t = c / 1000`` is the substrate with the thin-limit layer
    (:func:`bem.periodic.coated.thin_limit`, the long-wave slope of the compliance), ``t = 1000``
    times the region the coating's own half-space, each to 1e-6 of the peak pressure."""
    from bem.periodic.coated import thin_limit

    step, extent = 0.05, 1.2
    kw = dict(force=1.0, step=step, extent=extent, E1=1.0, nu1=0.3, E2=1.0, nu2=0.3, rtol=1e-12)
    thin = bem.solve(Paraboloid(1.0), coating2=bem.Coating(step / 1000, 0.3, 0.35), **kw)
    limit = bem.solve(Paraboloid(1.0), layer=layers.Linear(thin_limit(thin.bodies)), **kw)
    bare = bem.solve(Paraboloid(1.0), **kw)
    assert np.abs(thin.p - limit.p).max() <= 1e-6 * limit.p.max()  # measured 1.6e-7
    assert np.abs(thin.p - bare.p).max() >= 1e-4 * bare.p.max()  # the coating is seen (2.8e-4)
    thick = bem.solve(Paraboloid(1.0), coating2=bem.Coating(1000 * 2 * extent, 3.0, 0.35), **kw)
    own = bem.solve(Paraboloid(1.0), **dict(kw, E2=3.0, nu2=0.35))
    assert np.all(np.isfinite(thick.p))
    assert np.abs(thick.p - own.p).max() <= 1e-6 * own.p.max()  # measured 2.6e-11
