"""bem.solve refuses bad input early and reports an undersized candidate region."""

import re

import numpy as np
import pytest

import bem
from bem.checks import InputError
from bem.gaps import Paraboloid

GOOD = dict(E_star=1.0, force=0.01, step=0.05, extent=0.5)


@pytest.mark.parametrize("change, name", [
    (dict(E_star=-1.0), "E_star"),
    (dict(E_star=float("nan")), "E_star"),
    (dict(force=0.0), "force"),
    (dict(force=None), "approach"),
    (dict(approach=0.1), "approach"),
    (dict(step=0.0), "step"),
    (dict(extent=-1.0), "extent"),
    (dict(method="simplex"), "method"),
    (dict(rtol=-1e-3), "rtol"),
    (dict(layer="soft"), "layer"),
    (dict(E_star=None, E1=2e11, nu1=0.3, E2=2e11), "E_star"),
    (dict(E_star=None, E1=2e11, nu1=0.7, E2=2e11, nu2=0.3), "nu1"),
    (dict(x0=np.zeros(3)), "x0"),
    (dict(x0="abc"), "x0 = 'abc' is not allowed"),
    (dict(rtol=10.0), r"rtol = 10\.0 is not allowed: it must be in \(0, 0\.01\]"),
    (dict(rtol=0.05), "rtol = 0.05 is not allowed"),
    (dict(extent=(0.5, 0.5, 0.5)), r"extent = \(0\.5, 0\.5, 0\.5\) is not allowed: it must be a number or a pair"),
    (dict(E_star=1e308), r"E_star = 1e\+308 is not allowed"),
    (dict(force=1e308), r"force = 1e\+308 is not allowed"),
    (dict(force=None, approach=1e-308), r"approach = 1e-308 is not allowed"),
    (dict(E_star=None, E1=1e308, nu1=0.3, E2=2.0, nu2=0.3), r"E1 = 1e\+308 is not allowed"),
    (dict(step=1e-9), r"step = 1e-09 is not allowed: the candidate region would hold 1\.15e\+18 nodes"),
    (dict(step=1e-300, extent=1e-299), r"^step = 1e-300 is not allowed: it must be in \[1e-60, 1e\+60\]"),
    (dict(step=1e300, extent=1e301), r"^step = 1e\+300 is not allowed: it must be in \[1e-60, 1e\+60\]"),
])
def test_bad_input_is_refused_naming_the_argument(change, name):
    kw = {**GOOD, **change}
    with pytest.raises(InputError, match=name):
        bem.solve(Paraboloid(1.0), **kw)


def test_gap_with_nan_is_refused():
    """The message shows the value and a point of the candidate region where the gap is NaN."""
    rule = (r"^gap\(x, y\) = nan at \(x, y\) = \((\S+), (\S+)\) is not allowed: the gap must be finite over "
            r"the candidate region")
    with pytest.raises(InputError, match=rule) as err:
        bem.solve(lambda x, y: np.where(x > 0.2, np.nan, x * x + y * y), **GOOD)
    x, y = map(float, re.match(rule, str(err.value)).groups())
    assert 0.2 < x <= 0.5 and abs(y) <= 0.5


def test_periodic_gap_with_nan_is_refused_in_the_same_form():
    from bem.periodic import PeriodicCell

    cell = PeriodicCell.from_size(0.05, (1.0, 1.0))
    rule = r"^gap\(x, y\) = nan at \(x, y\) = \((\S+), (\S+)\) is not allowed: the gap must be finite over the cell\.$"
    with pytest.raises(InputError, match=rule) as err:
        bem.solve_periodic(lambda x, y: np.where(x > 0.6, np.nan, 0.01 * np.cos(2 * np.pi * x)), cell=cell,
                           E_star=1.0, mean_pressure=1e-3)
    x, _ = map(float, re.match(rule, str(err.value)).groups())
    assert x >= 0.6  # shown to 6 significant digits


def test_gap_of_the_wrong_shape_is_refused():
    with pytest.raises(InputError, match=r"^gap returned shape \(3,\) which is not allowed: it must return the "
                                         r"shape of x \(\(\d+, \d+\)\)\.$"):
        bem.solve(lambda x, y: np.zeros(3), **GOOD)


def test_contact_reaching_the_border_says_so():
    with pytest.raises(bem.RegionTooSmallError, match="extent"):
        bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=0.05, extent=0.5)


def test_contact_reaching_the_border_names_the_periodic_cell_for_a_rough_patch():
    with pytest.raises(bem.RegionTooSmallError, match="periodic cell: bem.solve_periodic"):
        bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=0.05, extent=0.5)


def test_e1_nu1_e2_nu2_give_the_same_answer_as_e_star():
    a = bem.solve(Paraboloid(1.0), E_star=1.0 / (2 * (1 - 0.3**2) / 2.0), force=0.01, step=0.05, extent=0.5)
    b = bem.solve(Paraboloid(1.0), E1=2.0, nu1=0.3, E2=2.0, nu2=0.3, force=0.01, step=0.05, extent=0.5)
    np.testing.assert_allclose(a.p, b.p, rtol=1e-12)


def test_non_convergence_is_reported_not_hidden():
    res = bem.solve(Paraboloid(1.0), maxiter=2, nested=False, **GOOD)
    assert not res.converged
    assert res.status == "maxiter"
    assert np.all(np.isfinite(res.p))


def test_an_overflowing_radius_is_refused_by_name():
    with pytest.raises(InputError, match=r"R = 1e\+308 is not allowed"):
        Paraboloid(1e308)


def test_the_loosest_tolerance_is_accepted_and_met():
    res = bem.solve(Paraboloid(1.0), rtol=bem.checks.RTOL_MAX, **GOOD)
    assert res.converged and res.kkt_residual <= bem.checks.RTOL_MAX

