"""The periodic cell of a surface as measured (bem.rough.patch_cell): detrending that keeps a periodic surface
bit for bit or removes a planted plane or paraboloid, the mirrored cell without a seam, spikes, one warning."""

import logging

import numpy as np
import pytest

from bem import InputError, rough

from ..instrument_data import unpacked

pytest.importorskip("SurfaceTopography")

SIZE = (1.0, 0.5)


@pytest.fixture(scope="module")
def periodic():
    return rough.self_affine((64, 32), SIZE, hurst=0.8, rms_height=0.01, long_cutoff=0.25, short_cutoff=1 / 16,
                             seed=4)


def _xy(shape):
    x = np.arange(shape[0])[:, None] * SIZE[0] / shape[0] * np.ones((1, shape[1]))
    y = np.arange(shape[1])[None, :] * SIZE[1] / shape[1] * np.ones((shape[0], 1))
    return x, y


def _fit(z, degree):
    """Least-squares coefficients of z on 1, x, y (and x^2, x y, y^2 for degree 2)."""
    x, y = _xy(z.shape)
    cols = [np.ones(z.size), x.ravel(), y.ravel()]
    if degree == 2:
        cols += [x.ravel() ** 2, (x * y).ravel(), y.ravel() ** 2]
    return np.linalg.lstsq(np.stack(cols, axis=1), z.ravel(), rcond=None)[0]


def _patch(z):
    return rough.from_heights(z, SIZE, periodic=False, source="patch")


def test_detrend_none_keeps_a_periodic_surface_bit_for_bit(periodic):
    for detrend in ("none", "auto"):
        cell = rough.patch_cell(periodic, detrend=detrend)
        assert np.array_equal(cell.surface.heights, periodic.heights)
        assert (cell.detrend, cell.cell, cell.surface.stats.periodic) == ("none", "periodic", True)
    with pytest.raises(InputError, match="detrend = 'height' is not allowed: .*periodic surface"):
        rough.patch_cell(periodic, detrend="height")


def test_height_removes_a_planted_plane(periodic):
    z0 = np.array(periodic.heights)
    x, y = _xy(z0.shape)
    cell = rough.patch_cell(_patch(z0 + 0.3 * x - 0.2 * y + 5.0), detrend="height")
    reference = rough.patch_cell(_patch(z0), detrend="height")
    np.testing.assert_allclose(cell.surface.heights, reference.surface.heights, rtol=0, atol=1e-12)
    np.testing.assert_allclose(_fit(np.asarray(cell.surface.heights), 1), 0.0, atol=1e-12)  # no plane left
    assert cell.detrend == "height" and cell.record()["detrend"] == "height"


def test_curvature_removes_a_planted_paraboloid_that_height_leaves(periodic):
    z0 = np.array(periodic.heights)
    x, y = _xy(z0.shape)
    form = 2.0 * (x - 0.3) ** 2 + 1.5 * (y - 0.2) ** 2 + 0.1 * x
    cell = rough.patch_cell(_patch(z0 + form), detrend="curvature")
    np.testing.assert_allclose(_fit(np.asarray(cell.surface.heights), 2), 0.0, atol=1e-11)
    reference = rough.patch_cell(_patch(z0), detrend="curvature")
    np.testing.assert_allclose(cell.surface.heights, reference.surface.heights, rtol=0, atol=1e-11)
    plane_only = rough.patch_cell(_patch(z0 + form), detrend="height")
    assert _fit(np.asarray(plane_only.surface.heights), 2)[3] == pytest.approx(2.0, rel=0.05)  # x^2 left


@pytest.fixture(scope="module")
def crop():
    """A patch cut from a larger periodic surface: its repetition has a seam."""
    big = rough.self_affine((128, 64), (2 * SIZE[0], 2 * SIZE[1]), hurst=0.8, rms_height=0.01, long_cutoff=0.25,
                            short_cutoff=1 / 16, seed=5)
    return _patch(np.array(big.heights)[:64, :32])


def test_the_mirrored_cell_has_no_seam_and_keeps_every_height(crop, caplog):
    with caplog.at_level(logging.WARNING, logger="bem.rough"):
        repeated = rough.patch_cell(crop, cell="repeat")
    seam = [r for r in caplog.records if "edge jump" in r.getMessage()]
    assert repeated.surface.stats.edge_jump_large and len(seam) == 1  # one warning, of the cell solved
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="bem.rough"):
        mirrored = rough.patch_cell(crop, cell="mirror")
    assert not [r for r in caplog.records if "edge jump" in r.getMessage()]
    z, zm = np.asarray(repeated.surface.heights), np.asarray(mirrored.surface.heights)
    assert zm.shape == (128, 64) and mirrored.surface.size == (2 * SIZE[0], 2 * SIZE[1])
    assert np.array_equal(zm[:64, :32], z) and np.array_equal(zm[64:, :32], z[::-1, :])
    assert np.array_equal(zm[:64, 32:], z[:, ::-1]) and np.array_equal(zm[64:, 32:], z[::-1, ::-1])
    assert mirrored.surface.stats.edge_jump == 0.0 and not mirrored.surface.stats.edge_jump_large
    assert mirrored.cell == "mirror" and mirrored.record()["edge_jump_large"] is False


def test_spikes_are_reported_and_removed_on_request(crop, caplog):
    z = np.array(crop.heights)
    z[10, 12] += 40 * z.std()
    with caplog.at_level(logging.WARNING, logger="bem.rough"):
        kept = rough.patch_cell(_patch(z))
    (warning,) = [r.getMessage() for r in caplog.records if "spikes" in r.getMessage()]
    assert "1 of 2048 points" in warning and "kept" in warning
    assert kept.record()["spike_points"] == 1 and not kept.spikes_removed
    removed = rough.patch_cell(_patch(z), spikes="remove")
    assert removed.spikes_removed and removed.record()["spikes_removed"] is True
    assert rough.find_spikes(removed.surface.heights).count == 0
    zr = np.asarray(removed.surface.heights)
    assert kept.spikes.top > 25 and (zr.max() - zr.mean()) / zr.std() < 5  # the spike, 30 rms heights, is gone


def test_bad_arguments_are_named(crop, periodic):
    with pytest.raises(InputError, match="cell = 'window' is not allowed"):
        rough.patch_cell(crop, cell="window")
    with pytest.raises(InputError, match="spikes = 'drop' is not allowed"):
        rough.patch_cell(crop, spikes="drop")
    with pytest.raises(InputError, match="spike_threshold = 0.0 is not allowed"):
        rough.patch_cell(crop, spike_threshold=0)
    detrended = rough.from_heights(np.array(crop.heights), SIZE, detrend="height")
    with pytest.raises(InputError, match="surface.stats.detrend = 'height' is not allowed"):
        rough.patch_cell(detrended)


def test_a_measured_patch_on_the_half_space_touches_at_its_highest_point_and_refuses_a_spreading_contact():
    """The non-periodic path (bem.gaps.Measured, kind = "topography"; a scene's type = "measured"): the AFM scan
    spot_1-1000nm.ibw with its spikes, pressed lightly by a flat, carries the load on the particle at its
    highest point; a load that spreads the contact to the border of the region is refused."""
    import bem
    from bem.gaps import Measured

    spot = unpacked("spot_1-1000nm.ibw")
    cell = rough.patch_cell(rough.read_surface(spot, detrend=None))
    z = np.asarray(cell.surface.heights)
    dx = cell.surface.size[0] / z.shape[0]
    x = (np.arange(z.shape[0]) - z.shape[0] / 2) * dx
    extent = 0.4 * cell.surface.size[0]
    gap = Measured(x, x, z, kind="topography", method="linear").region(extent)
    E_star, area = 115e9, (2 * extent) ** 2
    force = 1e-4 * E_star * cell.surface.stats.rms_slope * area  # mean pressure 1e-4 E* h'_rms
    light = bem.solve(gap, E_star=E_star, step=2 * dx, extent=extent, force=force, rtol=1e-8)
    assert light.converged and light.force == pytest.approx(force, rel=1e-8)  # sum of the nodal pressures
    inside = np.abs(x) <= extent
    i, j = np.unravel_index(np.argmax(np.where(inside[:, None] & inside[None, :], z, -np.inf)), z.shape)
    k = int(np.argmax(light.p))
    assert np.hypot(light.x[k] - x[i], light.y[k] - x[j]) <= 3 * dx  # the peak pressure on the highest point
    assert light.contact_area < 1e-3 * area
    with pytest.raises(bem.RegionTooSmallError, match="bem.solve_periodic"):
        bem.solve(gap, E_star=E_star, step=2 * dx, extent=extent, force=100 * force, rtol=1e-8)
