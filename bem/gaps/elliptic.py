"""The elliptic paraboloid gap (two bodies of different curvatures)."""

from __future__ import annotations

import math

import numpy as np

from ..checks import check_scale
from .base import Gap

__all__ = ["EllipticParaboloid"]


class EllipticParaboloid(Gap):
    """Elliptic paraboloid ``h = x**2 / (2 Rx) + y**2 / (2 Ry)``.

    Parameters
    ----------
    Rx, Ry : float
        Effective radii of relative curvature [length] in the x-z and y-z
        planes, ``> 0``. Axisymmetric (with ``h_r``) only when ``Rx == Ry``.
    """

    type_name = "elliptic_paraboloid"
    units = {"Rx": "length", "Ry": "length"}

    def __init__(self, Rx, Ry):
        self.Rx = check_scale("Rx", Rx)
        self.Ry = check_scale("Ry", Ry)

    @property
    def is_axisymmetric(self):
        return self.Rx == self.Ry

    def _evaluate(self, x, y):
        return x * x / (2.0 * self.Rx) + y * y / (2.0 * self.Ry)

    def h_r(self, r):
        if not self.is_axisymmetric:
            return super().h_r(r)
        r = np.asarray(r, dtype=float)
        return r * r / (2.0 * self.Rx)

    def _params(self):
        return {"Rx": self.Rx, "Ry": self.Ry}

    def expected_semi_axes(self, *, E_star, force=None, approach=None, layer=None):
        """Hertz's ellipse (:func:`bem.reference.hertz_elliptic`), widened by the layer as the
        paraboloid of the same mean radius ``sqrt(Rx Ry)`` is."""
        from ..reference import hertz_elliptic
        from .paraboloid import Paraboloid

        hz = hertz_elliptic(self.Rx, self.Ry, E_star, force=force, approach=approach)
        widen = 1.0
        if layer is not None:
            eq = Paraboloid(math.sqrt(self.Rx * self.Ry))
            kw = dict(E_star=E_star, force=force, approach=approach)
            widen = eq.expected_semi_axes(layer=layer, **kw)[0] / eq.expected_semi_axes(**kw)[0]
        return hz.a * widen, hz.b * widen
