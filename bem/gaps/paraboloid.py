"""Sphere on a flat (or two spheres): the paraboloid gap."""

from __future__ import annotations

from ..checks import check_scale
from .base import AxisymmetricGap

__all__ = ["Paraboloid"]


class Paraboloid(AxisymmetricGap):
    """Sphere on a flat (or two spheres): ``h = (x**2 + y**2) / (2 R)``.

    Parameters
    ----------
    R : float
        Effective radius [length], ``> 0``; for two spheres
        ``1/R = 1/R1 + 1/R2``.
    """

    type_name = "paraboloid"
    units = {"R": "length"}

    def __init__(self, R):
        self.R = check_scale("R", R)

    def _profile(self, r):
        return r * r / (2.0 * self.R)

    def _params(self):
        return {"R": self.R}
