"""The triangular lattice: geometry, interpolation, coarsening."""

import math

import numpy as np
import pytest

from bem.checks import InputError
from bem.lattice import Lattice


def test_nodes_form_equilateral_triangles():
    lat = Lattice.from_extent(0.2, 1.0)
    x, y = lat.x[lat.mask], lat.y[lat.mask]
    d = np.hypot(x[:, None] - x[None, :], y[:, None] - y[None, :])
    np.fill_diagonal(d, np.inf)
    nearest = d.min(axis=1)
    np.testing.assert_allclose(nearest, 0.2, rtol=1e-12)
    interior = ~lat.border[lat.mask]
    assert np.all(np.sum(np.isclose(d, 0.2, rtol=1e-9), axis=1)[interior] == 6)


def test_region_is_symmetric_and_contains_origin():
    lat = Lattice.from_extent(0.1, (1.0, 0.5))
    x, y = lat.x[lat.mask], lat.y[lat.mask]
    assert np.any((x == 0) & (y == 0))
    assert np.abs(x).max() <= 1.0 + 1e-12 and np.abs(y).max() <= 0.5 + 1e-12
    pts = set(zip(np.round(x, 9), np.round(y, 9)))
    assert all((-a, b) in pts and (a, -b) in pts for a, b in pts)


def test_node_area_is_pyramid_volume():
    assert Lattice.from_extent(0.3, 2.0).node_area == pytest.approx(math.sqrt(3) / 2 * 0.09, rel=1e-15)


def test_interpolation_is_exact_for_linear_fields_and_matches_nodes():
    lat = Lattice.from_extent(0.1, 1.0)
    field = 2.0 - 3.0 * lat.x + 0.5 * lat.y
    rng = np.random.default_rng(3)
    xs, ys = rng.uniform(-0.8, 0.8, (2, 500))
    np.testing.assert_allclose(lat.interpolate(field, xs, ys), 2.0 - 3.0 * xs + 0.5 * ys, atol=1e-12)
    np.testing.assert_allclose(lat.interpolate(field, lat.x, lat.y)[lat.mask & ~lat.border],
                               field[lat.mask & ~lat.border], atol=1e-12)


def test_interpolation_is_zero_outside_and_does_not_modify_inputs():
    lat = Lattice.from_extent(0.1, 1.0)
    field = np.ones(lat.shape)
    xs = np.array([5.0, -7.0])
    keep = (field.copy(), xs.copy())
    assert np.all(lat.interpolate(field, xs, xs) == 0)
    np.testing.assert_array_equal(field, keep[0])
    np.testing.assert_array_equal(xs, keep[1])


def test_coarse_nodes_are_fine_nodes():
    fine = Lattice.from_extent(0.05, 1.0)
    coarse = fine.coarsen()
    assert coarse.step == 0.1
    fine_pts = set(zip(np.round(fine.x[fine.mask], 9), np.round(fine.y[fine.mask], 9)))
    coarse_pts = set(zip(np.round(coarse.x[coarse.mask], 9), np.round(coarse.y[coarse.mask], 9)))
    assert coarse_pts <= fine_pts


@pytest.mark.parametrize("step, extent, name", [(-1.0, 1.0, "step"), (0.1, 0.0, "extent"),
                                                 (0.1, float("nan"), "extent"), (1.0, 1.5, "extent")])
def test_bad_lattice_input_is_refused(step, extent, name):
    with pytest.raises(InputError, match=name):
        Lattice.from_extent(step, extent)


@pytest.mark.parametrize("step, extent", [(0.1, 1.0), (0.05, (1.0, 0.7)), (0.037, (0.61, 0.83)), (0.02, 0.5)])
def test_prolong_is_interpolation_onto_the_fine_nodes(step, extent):
    fine = Lattice.from_extent(step, extent)
    coarse = fine.coarsen()
    values = np.random.default_rng(3).random(coarse.shape) * coarse.mask
    expected = coarse.interpolate(values, fine.x, fine.y) * fine.mask
    np.testing.assert_allclose(coarse.prolong(values, fine), expected, rtol=0, atol=1e-14)
    with pytest.raises(InputError, match="fine"):
        fine.prolong(np.zeros(fine.shape), coarse)
