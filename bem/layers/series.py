"""Two layers in series: the same pressure acts on both, their closures (compliances) add."""

from __future__ import annotations

import numpy as np

from ..checks import InputError
from ._common import LawBase, as_closure, as_pressure, out
from ._solve import invert
from .base import Layer

__all__ = ["Series"]


class Series(LawBase):
    """``w = w_a(p) + w_b(p)``: layers ``a`` and ``b`` stacked (also written ``a + b``).

    Parameters
    ----------
    a, b : Layer
        The two laws (any :class:`bem.layers.Layer`, a ``Series`` included).

    Notes
    -----
    ``dw``, ``energy`` and ``secant`` add. ``inverse(c)`` is the smallest ``p`` with
    ``w(p) >= c``: the search starts at ``min(a.inverse(c), b.inverse(c))`` (an upper bound,
    as each closure alone is at most ``c``) or, where neither layer alone can close ``c``, at
    the larger ``p_scale`` of the two; then bracketing and a safeguarded Newton iteration
    (:func:`bem.layers._solve.invert`). ``+inf`` where ``w(x0 2**128) < c`` (both layers rigid
    beyond their reach).
    """

    law = "series"
    _required = ("a", "b")

    def __init__(self, a, b):
        for name, layer in (("a", a), ("b", b)):
            if not isinstance(layer, Layer):
                raise InputError(f"{name} = {layer!r} is not allowed: it must be a Layer.")
        self.a, self.b = a, b

    def _params(self):
        return {
            name: layer.to_dict() if hasattr(layer, "to_dict") else layer
            for name, layer in (("a", self.a), ("b", self.b))
        }

    def __repr__(self):
        return f"Series({self.a!r}, {self.b!r})"

    @property
    def p_scale(self):
        return max(getattr(self.a, "p_scale", 1.0), getattr(self.b, "p_scale", 1.0))

    def w(self, p):
        p = as_pressure(p)
        return out(np.asarray(self.a.w(p)) + self.b.w(p))

    def dw(self, p):
        p = as_pressure(p)
        return out(np.asarray(self.a.dw(p)) + self.b.dw(p))

    def energy(self, p):
        p = as_pressure(p)
        return out(np.asarray(self.a.energy(p)) + self.b.energy(p))

    def secant(self, p):
        p = as_pressure(p)
        return out(np.asarray(self.a.secant(p)) + self.b.secant(p))

    def inverse(self, closure):
        c = as_closure(closure)
        res = np.where(c <= 0, 0.0, np.nan)
        todo = c > 0
        ct = c[todo]
        x0 = np.minimum(self.a.inverse(ct), self.b.inverse(ct))
        x0 = np.where(np.isfinite(x0) & (x0 > 0), x0, self.p_scale)
        res[todo] = invert(self.w, self.dw, ct, x0)
        return out(res)
