"""Spikes of a height map: points far from the bulk of the heights, found by a robust statistic.

Measured topographies carry points that the surface does not have: particles, tip and
optical artefacts (bat wings, drop-outs), scan-line streaks. A few of them decide the first
touch and the first stage of a contact, and so the layer law of the surface. They are found
against the median ``z_med`` and the median absolute deviation of the heights, which a few
outliers do not move (Hampel 1974, DOI 10.1080/01621459.1974.10482962):

    sigma_r = 1.4826 median(|z - z_med|),    s = (z - z_med) / sigma_r,

``sigma_r`` the standard deviation of normally distributed heights (the factor is
``1/Phi^-1(3/4)``). A spike is a connected region (8 neighbours) of points on one side,
``s > threshold/2`` (or ``s < -threshold/2``), that holds at least one point beyond
``threshold``: the core beyond the threshold and the flanks that rise to it, so that taking a
spike out leaves no ring. With the default :data:`SPIKE_THRESHOLD` = 10, normally distributed
heights have no spike (``P(|s| > 10) ~ 1.5e-23``, against ``|s| ~ 5.5`` for the largest of 4
million points).

:func:`remove_spikes` marks the points of the spikes missing and fills them with the harmonic
interpolation of their neighbours (SurfaceTopography's ``interpolate_undefined_data``, the
discrete Laplace equation with the other points as boundary values): a spike of several points
has no local median other than itself, so the fill comes from around it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..checks import check_finite_array, check_positive, fail

__all__ = ["Spikes", "find_spikes", "remove_spikes", "SPIKE_THRESHOLD", "MAD_TO_SIGMA"]

#: spikes lie beyond this many robust standard deviations ``sigma_r`` of the median (module docstring)
SPIKE_THRESHOLD = 10.0
#: ``1/Phi^-1(3/4)``: the median absolute deviation of normal heights times this is their standard deviation
MAD_TO_SIGMA = 1.482602218505602


@dataclass(frozen=True)
class Spikes:
    """The spikes of a height map (:func:`find_spikes`).

    Attributes
    ----------
    mask : ndarray of bool
        The points of the spikes, the shape of the heights.
    threshold : float
        In robust standard deviations [-].
    median : float
        ``z_med`` [length].
    robust_sigma : float
        ``sigma_r = 1.4826 median(|z - z_med|)`` [length].
    rms_height : float
        rms of ``z - mean z`` with the spikes [length].
    n_high, n_low : int
        Points in spikes above and below the median.
    n_spikes_high, n_spikes_low : int
        Spikes (connected regions) above and below the median.
    top : float
        The highest point above the mean, in rms heights [-]: ``(max z - mean z)/rms_height``.
    top_score : float
        The highest point in robust standard deviations, ``(max z - z_med)/sigma_r`` [-].
    """

    mask: np.ndarray
    threshold: float
    median: float
    robust_sigma: float
    rms_height: float
    n_high: int
    n_low: int
    n_spikes_high: int
    n_spikes_low: int
    top: float
    top_score: float

    @property
    def count(self):
        """Points in spikes, both sides."""
        return self.n_high + self.n_low

    @property
    def fraction(self):
        """Share of the points in spikes [-]."""
        return self.count / self.mask.size

    def describe(self, unit="m"):
        """One line for people: counts, the statistic and the highest point."""
        return (f"{self.count} of {self.mask.size} points ({100 * self.fraction:.3g} %) are spikes beyond "
                f"{self.threshold:g} robust standard deviations sigma_r = 1.4826 MAD = {self.robust_sigma:.4g} {unit} "
                f"of the median: {self.n_high} points in {self.n_spikes_high} spikes above, {self.n_low} points in "
                f"{self.n_spikes_low} below; the highest point stands {self.top:.3g} rms heights "
                f"({self.rms_height:.4g} {unit}) above the mean, {self.top_score:.3g} sigma_r above the median")

    def as_dict(self):
        """The numbers as plain JSON values (without the mask)."""
        return dict(threshold=self.threshold, median=self.median, robust_sigma=self.robust_sigma,
                    rms_height=self.rms_height, n_high=self.n_high, n_low=self.n_low,
                    n_spikes_high=self.n_spikes_high, n_spikes_low=self.n_spikes_low, top=self.top,
                    top_score=self.top_score)


def _regions(score, threshold):
    """Points of the connected regions beyond ``threshold/2`` that reach beyond ``threshold``, and their count."""
    from scipy import ndimage

    labels, n = ndimage.label(score > threshold / 2, structure=np.ones((3, 3), dtype=bool))
    if n == 0:
        return np.zeros(score.shape, dtype=bool), 0
    keep = np.zeros(n + 1, dtype=bool)
    keep[np.unique(labels[score > threshold])] = True
    keep[0] = False
    return keep[labels], int(keep.sum())


def find_spikes(heights, *, threshold=SPIKE_THRESHOLD):
    """The spikes of a height map (module docstring).

    Parameters
    ----------
    heights : array_like
        ``z[i, j]`` [length], finite, 2-D; detrended, so that a tilt or a form does not widen the
        bulk of the heights. Not modified.
    threshold : float
        Robust standard deviations beyond which a point is a spike's core, ``> 0``
        (default :data:`SPIKE_THRESHOLD`).

    Returns
    -------
    Spikes
        No spikes where ``sigma_r = 0`` (more than half the points at one height).
    """
    z = check_finite_array("heights", heights, ndim=2)
    threshold = check_positive("threshold", threshold)
    med = float(np.median(z))
    sigma = MAD_TO_SIGMA * float(np.median(np.abs(z - med)))
    rms = float(np.std(z))
    top = float((z.max() - z.mean()) / rms) if rms > 0 else 0.0
    if sigma == 0.0:
        return Spikes(np.zeros(z.shape, dtype=bool), threshold, med, 0.0, rms, 0, 0, 0, 0, top, 0.0)
    score = (z - med) / sigma
    high, n_spikes_high = _regions(score, threshold)
    low, n_spikes_low = _regions(-score, threshold)
    return Spikes(high | low, threshold, med, sigma, rms, int(high.sum()), int(low.sum()), n_spikes_high,
                  n_spikes_low, top, float(score.max()))


def remove_spikes(heights, spikes, size, *, periodic=False):
    """The heights with the points of ``spikes`` filled by harmonic interpolation (module docstring).

    Parameters
    ----------
    heights : array_like
        ``z[i, j]`` [length], finite, 2-D. Not modified.
    spikes : Spikes
        From :func:`find_spikes` of the same heights.
    size : (float, float)
        ``(Lx, Ly)`` [length].
    periodic : bool
        The heights are one period (neighbours across the edges), else a patch.

    Returns
    -------
    ndarray
        A new array; equal to ``heights`` outside ``spikes.mask``.
    """
    from .surface import _pair, _surface_topography

    z = check_finite_array("heights", heights, ndim=2)
    if not isinstance(spikes, Spikes):
        fail("spikes", type(spikes).__name__, "a bem.rough.Spikes (find_spikes)")
    if spikes.mask.shape != z.shape:
        fail("spikes.mask.shape", spikes.mask.shape, f"the shape {z.shape} of heights")
    if spikes.fraction > 0.5:
        fail("spikes", f"{spikes.count} of {z.size} points", "at most half the points (the rest fill them)")
    size = _pair("size", size)
    if not spikes.mask.any():
        return np.array(z, dtype=float)
    st = _surface_topography()
    topo = st.Topography(np.ma.masked_array(np.array(z, dtype=float), mask=spikes.mask), size, periodic=periodic)
    filled = np.array(np.ma.getdata(topo.interpolate_undefined_data("harmonic").heights()), dtype=float)
    filled[~spikes.mask] = z[~spikes.mask]
    return filled
