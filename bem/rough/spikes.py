"""Spikes of a height map: points far from the others by a robust statistic (numpy only).

A measured map may hold points that are instrument artefacts (a dust grain, a lost
reflection) standing many rms heights above or below the surface. They are counted by their
distance from the median height in units of the scaled median absolute deviation,

    s = 1.4826 median |z - median z|,          spike:  |z - median z| > mads * s,

``s`` being the standard deviation of normally distributed heights, unmoved by a few
outliers (the rms height itself grows with them). Where more than half of the points share one
height (``s = 0``), ``s`` is the rms deviation from the median instead. :data:`SPIKE_MADS` = 6
flags a point of normally distributed heights with probability ``2e-9`` (less than one point in
a map of 16 million), so a map that is Gaussian flags none; the tall asperities of a skewed
surface lie within it unless they stand out from its bulk by 6 ``s``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..checks import check_finite_array, check_positive

__all__ = ["SPIKE_MADS", "Spikes", "find_spikes"]

#: default threshold of :func:`find_spikes`, in scaled median absolute deviations
SPIKE_MADS = 6.0
#: the scaled MAD is the standard deviation of normally distributed heights
_MAD_TO_SIGMA = 1.4826


@dataclass(frozen=True)
class Spikes:
    """The spikes of a height map (:func:`find_spikes`).

    Attributes
    ----------
    mask : ndarray of bool
        ``True`` at a spike, the shape of the heights (read-only).
    count : int
        Spikes in all; ``above`` of them above the median, ``below`` below it.
    above, below : int
    median : float
        Median height [length].
    scale : float
        The robust scale ``s`` [length] (module docstring).
    mads : float
        The threshold, in units of ``s``.
    largest : float
        Largest ``|z - median| / s`` of the map [-] (0 for a flat map).
    """

    mask: np.ndarray
    count: int
    above: int
    below: int
    median: float
    scale: float
    mads: float
    largest: float

    def as_dict(self):
        """The numbers (not the mask) as plain JSON values."""
        return {"count": self.count, "above": self.above, "below": self.below, "median": self.median,
                "scale": self.scale, "mads": self.mads, "largest": self.largest}


def find_spikes(heights, *, mads=SPIKE_MADS):
    """The points of ``heights`` beyond ``mads`` scaled median absolute deviations (module docstring).

    Parameters
    ----------
    heights : array_like
        A height map [length], finite (e.g. :attr:`bem.rough.RoughSurface.heights`, after
        detrending: a tilt widens the spread). Not modified.
    mads : float
        Threshold in units of the robust scale ``s``, ``> 0`` (default :data:`SPIKE_MADS`).

    Returns
    -------
    Spikes
        The mask, the counts above and below the median, and the statistic.

    Raises
    ------
    bem.InputError
        Heights that are not finite or empty, a threshold that is not positive.
    """
    z = check_finite_array("heights", heights)
    mads = check_positive("mads", mads)
    median = float(np.median(z))
    dev = z - median
    scale = _MAD_TO_SIGMA * float(np.median(np.abs(dev)))
    if scale == 0.0:
        scale = float(np.sqrt(np.mean(dev**2)))
    if scale == 0.0:  # every point at one height
        mask = np.zeros(z.shape, dtype=bool)
        largest = 0.0
    else:
        mask = np.abs(dev) > mads * scale
        largest = float(np.max(np.abs(dev)) / scale)
    mask.flags.writeable = False
    above = int(np.count_nonzero(mask & (dev > 0)))
    return Spikes(mask, int(np.count_nonzero(mask)), above, int(np.count_nonzero(mask)) - above, median, scale,
                  float(mads), largest)
