"""bem.solve over a domain: one set of checks for a half-space region and a periodic cell, the growth
of a region, and the alias solve_periodic."""

import math
import re

import numpy as np
import pytest

import bem
from bem.gaps import Paraboloid
from bem.region import region_limit

CELL = bem.PeriodicCell(1.0 / 16, 16, 16)


def _cell_gap(x, y):
    return 0.01 * (2 - np.cos(2 * math.pi * x / CELL.size[0]) - np.cos(2 * math.pi * y / CELL.size[1]))


REGION = dict(gap=Paraboloid(1.0), step=0.05, extent=0.5, force=1e-3)
PERIODIC = dict(gap=_cell_gap, domain=CELL, mean_pressure=0.01)


@pytest.mark.parametrize("problem", [REGION, PERIODIC], ids=["region", "cell"])
@pytest.mark.parametrize("bad, match", [
    (dict(rtol=0.5), "^rtol = 0.5 is not allowed: it must be in \\(0, 0.01\\]"),
    (dict(x0="nan"), "^x0 is not allowed to contain NaN or inf"),
    (dict(callback=3), "^callback = 3 is not allowed: it must be callable"),
    (dict(maxiter=0), "^maxiter = 0 is not allowed"),
    (dict(nested="yes"), "^nested = 'yes' is not allowed: it must be True or False"),
    (dict(E_star=-1.0), "^E_star = -1.0 is not allowed: it must be > 0"),
    (dict(method="kalker", layer=bem.layers.Root(0.01)), "^method = 'kalker' is not allowed with layer"),
    (dict(eps_p=1e-3), "^eps_p = 0.001 is not allowed"),
])
def test_both_domains_refuse_the_same_input_with_the_same_message(problem, bad, match):
    kw = dict(E_star=1.0, **problem)
    kw.update(bad)
    if isinstance(kw.get("x0"), str):
        n = CELL.n_nodes if "domain" in kw else bem.Lattice.from_extent(kw["step"], kw["extent"]).n_nodes
        kw["x0"] = np.full(n, np.nan)
    with pytest.raises(bem.InputError, match=match):
        bem.solve(**kw)


def test_mean_pressure_is_refused_on_a_half_space_region():
    with pytest.raises(bem.InputError, match="^mean_pressure = 0.1 is not allowed: it must be given on a periodic"):
        bem.solve(Paraboloid(1.0), E_star=1.0, step=0.05, extent=0.5, mean_pressure=0.1)


def test_solve_periodic_is_bem_solve_on_the_cell():
    alias = bem.solve_periodic(_cell_gap, cell=CELL, E_star=1.0, mean_pressure=0.01)
    direct = bem.solve(_cell_gap, domain=CELL, E_star=1.0, force=0.01 * CELL.area)
    assert isinstance(direct, bem.PeriodicContactResult) and direct.converged
    np.testing.assert_array_equal(alias.p, direct.p)
    assert alias.approach == direct.approach and alias.iterations == direct.iterations


def test_a_growing_region_grows_to_the_solution_of_the_region_it_reached():
    """A region too small for the contact grows by 1.5 until the contact fits; the answer is the one
    on the region it reached, solved directly."""
    kw = dict(E_star=1.0, force=1e-3, method="kalker")
    with pytest.raises(bem.RegionTooSmallError):
        bem.solve(Paraboloid(1.0), step=0.005, extent=0.04, **kw)
    grown = bem.solve(Paraboloid(1.0), domain=bem.HalfSpaceRegion(0.005, 0.04, grow=True), **kw)
    assert grown.converged and len(grown.notes) >= 1 and "extent enlarged" in grown.notes[0]
    ex, ey = grown.domain.extent
    assert ex == pytest.approx(0.04 * 1.5 ** len(grown.notes))
    direct = bem.solve(Paraboloid(1.0), step=0.005, extent=(ex, ey), **kw)
    np.testing.assert_array_equal(grown.p, direct.p)


def test_an_automatic_region_starts_at_the_expected_contact_and_holds_it():
    res = bem.solve(Paraboloid(1.0), domain=bem.HalfSpaceRegion(0.005), E_star=1.0, force=1e-3, method="kalker")
    a = bem.reference.hertz_sphere(1.0, 1.0, force=1e-3).contact_radius
    assert res.converged and res.domain.extent[0] == pytest.approx(1.5 * a, rel=0.05)
    assert res.contact_radius < res.domain.extent[0]


class _Bounded:
    """A paraboloid known only for |x|, |y| < 0.05."""

    domain = ((-0.05, 0.05), (-0.05, 0.05))

    def __call__(self, x, y):
        return (x**2 + y**2) / 2.0


def test_growth_stops_at_the_end_of_the_gaps_domain():
    gap = _Bounded()
    assert region_limit(gap) == pytest.approx((0.05 * (1 - 1e-3),) * 2)
    with pytest.raises(bem.RegionTooSmallError, match="reaches the end of the gap's domain"):
        bem.solve(gap, domain=bem.HalfSpaceRegion(0.002, 0.03, grow=True), E_star=1.0, force=1e-2, method="kalker")


def test_x0_is_refused_with_a_growing_region():
    with pytest.raises(bem.InputError, match="^x0 is not allowed with HalfSpaceRegion"):
        bem.solve(Paraboloid(1.0), domain=bem.HalfSpaceRegion(0.05), E_star=1.0, force=1e-3, x0=np.zeros(3))


def test_the_checks_table_has_a_row_for_every_argument_of_solve():
    """docs/method.md, "Checks of bem.solve": one row per keyword of bem.solve, and no other."""
    import inspect
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "method.md").read_text(encoding="utf-8")
    table = text.split("#### Checks of `bem.solve`", 1)[1].split("\n## ", 1)[0]
    rows = {m.group(1) for m in re.finditer(r"^\| `([^`]+)` \|", table, re.M)}
    assert rows == set(inspect.signature(bem.solve).parameters)


@pytest.mark.parametrize("build", [lambda: bem.HalfSpaceRegion(1e-4, 1.0), lambda: bem.PeriodicCell(1.0, 5000, 5000)],
                         ids=["region", "cell"])
def test_both_domains_refuse_more_nodes_than_the_limit_before_building_them(build):
    with pytest.raises(bem.InputError, match=r"nodes \(limit [0-9.e+]+ on this machine\)"):
        build()
