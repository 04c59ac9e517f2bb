"""Spikes of a height map (bem.rough.find_spikes): a robust count that a few outliers do not hide."""

import numpy as np
import pytest

import bem
from bem import rough


def test_planted_spikes_are_found_and_a_gaussian_map_has_none():
    rng = np.random.default_rng(3)
    z = rng.normal(size=(256, 256))
    assert rough.find_spikes(z).count == 0  # 65536 normal points: none beyond 6 s
    spiked = z.copy()
    spiked[10, 20], spiked[100, 5], spiked[7, 7] = 20.0, 18.0, -12.0  # ~20 rms heights above the mean
    spiked[200:, :13] = 15.0  # 1 % of the map: its rms height grows by a third
    s = rough.find_spikes(spiked)
    assert (s.count, s.above, s.below) == (3 + 56 * 13, 2 + 56 * 13, 1)
    assert {(10, 20), (100, 5), (7, 7)} <= set(zip(*np.nonzero(s.mask)))
    # the robust scale is the Gaussian's standard deviation, unmoved by the spikes (the rms is not)
    assert s.scale == pytest.approx(1.0, rel=0.02)
    assert s.largest == pytest.approx((20.0 - s.median) / s.scale)


def test_threshold_counts_points_beyond_it_in_both_directions():
    z = np.zeros((8, 8))
    z[0, :4] = [1.0, -1.0, 1.0, -1.0]  # more than half at 0: the scale is the rms deviation
    z[5, 5] = 10.0
    rms = np.sqrt(np.mean(z**2))
    s = rough.find_spikes(z, mads=9.0 / rms)  # 10 is beyond 9, 1 is not
    assert (s.count, s.above, s.below, s.scale) == (1, 1, 0, pytest.approx(rms))
    assert rough.find_spikes(np.ones((8, 8))).count == 0


@pytest.mark.parametrize("heights, mads, name", [(np.full((4, 4), np.nan), 6.0, "heights"),
                                                  (np.zeros((4, 4)), 0.0, "mads")])
def test_bad_arguments_are_named(heights, mads, name):
    with pytest.raises(bem.InputError, match=f"^{name}"):
        rough.find_spikes(heights, mads=mads)
