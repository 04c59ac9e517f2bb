"""A flat punch with a rounded edge."""

from __future__ import annotations

import numpy as np

from ..checks import check_scale
from .base import AxisymmetricGap

__all__ = ["FlatPunch"]


class FlatPunch(AxisymmetricGap):
    """Flat of radius ``a`` with a rounded edge (axisymmetric).

    ``h(r) = 0`` for ``r <= a`` and ``(r - a)**2 / (2 edge_radius)`` for
    ``r > a``: the flat blends tangentially into a torus of meridian radius
    ``edge_radius`` (parabolic approximation).

    Parameters
    ----------
    a : float
        Radius of the flat [length], ``> 0``.
    edge_radius : float
        Edge (blend) radius [length], ``> 0``.
    """

    type_name = "flat_punch"
    units = {"a": "length", "edge_radius": "length"}

    def __init__(self, a, edge_radius):
        self.a = check_scale("a", a)
        self.edge_radius = check_scale("edge_radius", edge_radius)

    def _profile(self, r):
        d = np.maximum(r - self.a, 0.0)
        return d * d / (2.0 * self.edge_radius)

    def _params(self):
        return {"a": self.a, "edge_radius": self.edge_radius}
