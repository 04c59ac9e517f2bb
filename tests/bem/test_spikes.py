"""Spikes of a height map (bem.rough.find_spikes, remove_spikes): planted spikes on a seeded surface,
normal heights without any, the particles of a real AFM scan, and the harmonic fill."""


import numpy as np
import pytest

from bem import InputError
from bem.rough import SPIKE_THRESHOLD, find_spikes, remove_spikes

from ..instrument_data import unpacked

SPOT = unpacked("spot_1-1000nm.ibw")


def _field(seed=3, n=128):
    """Smooth correlated normal heights of unit rms (a Gaussian filter of white noise)."""
    from scipy import ndimage

    z = ndimage.gaussian_filter(np.random.default_rng(seed).standard_normal((n, n)), 2.0, mode="wrap")
    return z / z.std()


def _plant(z):
    """Three spikes: one point up 40 sigma, a 3 x 3 particle up 25 sigma with 8 sigma flanks, one point down 30."""
    z = z.copy()
    z[20, 30] += 40.0
    z[70:73, 80:83] += 25.0
    z[69, 80:83] += 8.0  # a flank above threshold/2 that joins the particle
    z[100, 10] -= 30.0
    planted = np.zeros(z.shape, dtype=bool)
    planted[20, 30] = planted[100, 10] = True
    planted[69:73, 80:83] = True
    return z, planted


def test_normal_heights_have_no_spike():
    spikes = find_spikes(_field())
    assert spikes.count == 0 and not spikes.mask.any()
    assert spikes.robust_sigma == pytest.approx(1.0, rel=0.1)  # the MAD's sigma of unit-rms normal heights


def test_planted_spikes_are_found_with_their_flanks_and_nothing_else():
    z, planted = _plant(_field())
    spikes = find_spikes(z)
    assert np.array_equal(spikes.mask, planted)
    assert (spikes.n_high, spikes.n_low, spikes.n_spikes_high, spikes.n_spikes_low) == (13, 1, 2, 1)
    assert spikes.robust_sigma == pytest.approx(1.0, rel=0.1)  # the spikes do not move the robust statistic
    assert spikes.top == pytest.approx((z.max() - z.mean()) / z.std())
    assert "14 of 16384 points" in spikes.describe()


def test_threshold_is_the_rule():
    z, _ = _plant(_field())
    assert find_spikes(z, threshold=50.0).count == 0  # the highest score is about 41
    assert find_spikes(z, threshold=35.0).count == 1  # only the 40-sigma point


def test_removal_fills_the_spikes_from_their_neighbours_and_keeps_every_other_point():
    base = _field()
    z, planted = _plant(base)
    spikes = find_spikes(z)
    filled = remove_spikes(z, spikes, (1.0, 1.0), periodic=True)
    assert np.array_equal(filled[~planted], z[~planted])
    assert np.abs(filled[planted] - base[planted]).max() < 1.0  # back within one sigma of the smooth field
    assert find_spikes(filled).count == 0
    assert z[20, 30] == base[20, 30] + 40.0  # the input is not modified


def test_bad_arguments_are_named():
    z, _ = _plant(_field())
    with pytest.raises(InputError, match="threshold = -1"):
        find_spikes(z, threshold=-1)
    with pytest.raises(InputError, match="spikes.mask.shape"):
        remove_spikes(z[:64], find_spikes(z), (1.0, 1.0))
    with pytest.raises(InputError, match="heights"):
        find_spikes(np.ones(5))


def test_the_particles_of_a_real_afm_scan():
    """SurfaceTopography's spot_1-1000nm.ibw: particles up to 22 rms heights above the mean plane."""
    pytest.importorskip("SurfaceTopography")
    from bem.rough import read_surface

    surface = read_surface(SPOT)  # the plane of least rms height taken off
    spikes = find_spikes(surface.heights)
    assert spikes.top == pytest.approx(21.8, abs=0.1)
    assert spikes.top_score > 6 * SPIKE_THRESHOLD - 1  # 60 robust standard deviations above the median
    assert spikes.n_spikes_high >= 3 and spikes.n_high < 0.02 * spikes.mask.size
    filled = remove_spikes(surface.heights, spikes, surface.size)
    top = (filled.max() - filled.mean()) / filled.std()
    assert top < 7.0  # 6.4 rms heights once the spikes are filled
    assert find_spikes(filled).count == 0
