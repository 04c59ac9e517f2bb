"""The pieces of the two-scale check (:mod:`validation.studies.two_scale`).

- :class:`TiledRoughness`: the gap of a sphere carrying a periodic rough surface, exact at the
  nodes of the half-space lattice (the roughness cell is a cell of the same triangular lattice);
- :func:`windowed`: the pressure averaged over square windows of a given width;
- :func:`nominal_radius`: the radius of the circle about the apex that holds a share of the force;
- :func:`greenwood_tripp_law`: the layer law of Greenwood and Tripp's rough sphere from the
  surface's spectral moments.
"""

from __future__ import annotations

import math

import numpy as np

from bem.checks import InputError

__all__ = ["TiledRoughness", "windowed", "nominal_radius", "spectral_moments", "greenwood_tripp_law",
           "gw_pressure"]

_SQRT3 = math.sqrt(3.0)


class TiledRoughness:
    """Gap ``h = r^2/(2R) + max z - z(x, y)`` of a sphere carrying the tiled roughness cell ``cell``.

    ``cell`` is a :class:`bem.rough.LatticeHeights` of step ``c``; node ``(q, j)`` of the
    half-space lattice of the same step (:class:`bem.lattice.Lattice`, ``x = c (q + (j mod 2)/2)``,
    ``y = c sqrt(3)/2 j``) is node ``(q mod n_cols, j mod n_rows)`` of the cell (``n_rows`` is
    even), so the heights at the nodes are the cell's, exactly; the nodes of the coarser lattices
    of nested iteration (steps ``2c, 4c, ...``) are nodes of the finest. ``max z`` is the cell's
    highest node, so ``h >= 0`` and the approach is measured from the position at which the flat
    touches the plane of the highest summit at the apex (docs/rough.md, "When the layer model
    holds"). A point off the lattice is refused.

    Parameters
    ----------
    cell : bem.rough.LatticeHeights
        The roughness cell (heights outwards, summits positive) [length].
    R : float
        Sphere radius [length].
    """

    def __init__(self, cell, R):
        self.cell, self.R = cell, float(R)
        self.offset = cell.heights.max() - cell.heights  # max z - z, >= 0

    def indices(self, x, y):
        """Cell indices ``(row, col)`` of lattice points ``(x, y)``; refuses points off the lattice."""
        c = self.cell.step
        j = np.rint(np.asarray(y) / (c * _SQRT3 / 2)).astype(np.int64)
        q = np.rint(np.asarray(x) / c - 0.5 * np.mod(j, 2)).astype(np.int64)
        off = np.hypot(x - c * (q + 0.5 * np.mod(j, 2)), y - c * _SQRT3 / 2 * j)
        if off.size and off.max() > 1e-6 * c:
            raise InputError(f"x, y = a point {off.max():.3g} away from the lattice of step {c!r} is not allowed: "
                             "the tiled roughness is known at the lattice nodes only.")
        return np.mod(j, self.cell.n_rows), np.mod(q, self.cell.n_cols)

    def roughness(self, x, y):
        """``max z - z`` at the lattice points ``(x, y)`` [length]."""
        r, q = self.indices(x, y)
        return self.offset[r, q]

    def __call__(self, x, y):
        return (np.asarray(x) ** 2 + np.asarray(y) ** 2) / (2 * self.R) + self.roughness(x, y)


def windowed(x, y, p, width, mask=None):
    """The mean of ``p`` over the nodes in square windows of side ``width`` centred at ``(i, j) width``.

    Every node carries the same area, so the mean of the nodal pressures is the window's mean
    pressure. Returns ``(ix, iy, mean, count)``: the windows' integer indices and their means
    [pressure] (only windows holding nodes), vectorised with ``np.bincount``.
    """
    x, y, p = (np.asarray(a, dtype=float).ravel() for a in (x, y, p))
    if mask is not None:
        keep = np.asarray(mask).ravel()
        x, y, p = x[keep], y[keep], p[keep]
    ix = np.floor(x / width + 0.5).astype(np.int64)
    iy = np.floor(y / width + 0.5).astype(np.int64)
    x0, y0 = ix.min(), iy.min()
    nx = ix.max() - x0 + 1
    flat = (iy - y0) * nx + (ix - x0)
    count = np.bincount(flat)
    total = np.bincount(flat, weights=p)
    used = np.flatnonzero(count)
    return used % nx + x0, used // nx + y0, total[used] / count[used], count[used]


def nominal_radius(x, y, p, share=0.99):
    """Radius of the circle about the origin that holds ``share`` of the force of the nodal ``p`` [length]."""
    r = np.hypot(np.asarray(x).ravel(), np.asarray(y).ravel())
    p = np.asarray(p, dtype=float).ravel()
    order = np.argsort(r)
    cum = np.cumsum(p[order])
    k = int(np.searchsorted(cum, share * cum[-1]))
    return float(r[order][min(k, r.size - 1)])


def spectral_moments(heights, size):
    """Profile moments ``(m0, m2, m4)`` of a periodic height grid ``z[i, j]`` over ``size`` [length^2, -, 1/length^2].

    ``m2`` and ``m4`` are the variances of the first and second derivative along a line,
    averaged over x and y (isotropic surface), from the grid's Fourier series.
    """
    z = np.asarray(heights, dtype=float)
    z = z - z.mean()
    nx, ny = z.shape
    kx = 2 * np.pi * np.fft.fftfreq(nx, size[0] / nx)[:, None]
    ky = 2 * np.pi * np.fft.fftfreq(ny, size[1] / ny)[None, :]
    power = np.abs(np.fft.fft2(z)) ** 2 / z.size**2
    m0 = power.sum()
    m2 = 0.5 * (power * (kx**2 + ky**2)).sum()
    m4 = 0.5 * (power * (kx**4 + ky**4)).sum()
    return float(m0), float(m2), float(m4)


def _f32(t):
    """Greenwood and Williamson's ``F_3/2(t) = (2 pi)^(-1/2) int_t^inf (s - t)^(3/2) exp(-s^2/2) ds``."""
    s = np.linspace(-10.0, 10.0, 8001)  # the standard normal beyond |s| = 10 is negligible
    t = np.atleast_1d(np.asarray(t, dtype=float))
    f = np.clip(s[None, :] - t[:, None], 0.0, None) ** 1.5 * np.exp(-0.5 * s[None, :] ** 2)
    return np.trapezoid(f, s, axis=1) / math.sqrt(2 * math.pi)


def gw_pressure(d, moments, E_star):
    """Greenwood-Williamson nominal pressure at the mean-plane separation ``d`` [pressure].

    ``p = 4/3 eta E* beta^(1/2) sigma_s^(3/2) F_3/2((d - y_s)/sigma_s)`` with the summit density
    ``eta = m4/(6 pi sqrt(3) m2)``, summit radius ``beta = 0.375 sqrt(pi/m4)``, summit-height
    deviation ``sigma_s = sigma sqrt(1 - 0.8968/alpha)`` and mean summit height
    ``y_s = 4 sigma/sqrt(pi alpha)``, ``alpha = m0 m4/m2^2`` (McCool, Wear 107, 37, 1986,
    DOI 10.1016/0043-1648(86)90045-1, after Nayak 1971).
    """
    m0, m2, m4 = moments
    alpha = m0 * m4 / m2**2
    sigma = math.sqrt(m0)
    sigma_s = sigma * math.sqrt(max(1.0 - 0.8968 / alpha, 1e-6))
    y_s = 4 * sigma / math.sqrt(math.pi * alpha)
    eta = m4 / (6 * math.pi * _SQRT3 * m2)
    beta = 0.375 * math.sqrt(math.pi / m4)
    return 4 / 3 * eta * E_star * math.sqrt(beta) * sigma_s**1.5 * _f32((np.asarray(d) - y_s) / sigma_s)


def greenwood_tripp_law(moments, E_star, first_touch_gap, p_max, n=60):
    """Greenwood and Tripp's rough-sphere model as a :class:`bem.layers.Tabulated` law.

    Greenwood & Tripp (1967, DOI 10.1115/1.3616614) solve the smooth sphere whose local
    mean-plane separation ``d`` and nominal pressure follow Greenwood and Williamson's
    ``p(d)`` (:func:`gw_pressure`). On the layer model's zero (the flat touching the plane
    ``first_touch_gap = max z - mean z`` above the mean plane) the closure is
    ``w = first_touch_gap - d``, tabulated from ``d = first_touch_gap`` (``w = 0``) until
    ``p >= p_max`` [pressure]. The asperities' mutual elastic interaction and the volume of the
    deformed asperities are left out, as in the model.
    """
    from bem.layers import Tabulated

    h0 = float(first_touch_gap)
    d = h0 - np.linspace(0.0, 1.0, 4001) ** 1.5 * 12 * h0
    p = gw_pressure(d, moments, E_star)
    stop = int(np.searchsorted(p, p_max)) + 1
    if stop >= p.size:
        raise InputError(f"p_max = {p_max!r} is not allowed: beyond the Greenwood-Williamson table "
                         f"({float(p[-1]):.3g} at a separation of {float(d[-1]):.3g}).")
    pick = np.unique(np.r_[np.rint(np.geomspace(1, stop, n)).astype(int), 0])
    pick = pick[p[pick] > 0]
    pick = pick[np.r_[True, np.diff(p[pick]) > 0]]
    return Tabulated(np.r_[0.0, p[pick]], np.r_[0.0, h0 - d[pick]])
