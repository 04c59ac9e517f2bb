"""Any user function as the gap, checked on every call."""

from __future__ import annotations

import importlib

import numpy as np

from ..checks import InputError, check_callable, check_positive, fail
from .base import Gap

__all__ = ["Callable"]


def _function_path(f):
    module, qualname = getattr(f, "__module__", None), getattr(f, "__qualname__", "")
    if not module or "<" in qualname or module == "__main__":
        fail("function", f, "a module-level function (importable as 'module:name') to be written to a dict")
    return f"{module}:{qualname}"


def _import_function(path):
    if not isinstance(path, str) or path.count(":") != 1:
        fail("function", path, "a string 'module:name'")
    module, qualname = path.split(":")
    try:
        obj = importlib.import_module(module)
        for part in qualname.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError) as exc:
        fail("function", path, f"importable ({exc})")
    return obj


class Callable(Gap):
    """Any user gap ``h = f(x, y)``, checked on every call.

    ``function`` receives copies of the broadcast coordinate arrays and must
    return one finite value ``>= 0`` per point (same shape). It is tried at
    construction on a 5 x 5 grid over ``[-scale, scale]**2``; ``to_dict``
    needs it importable, as ``"module:name"``.

    Parameters
    ----------
    function : callable or str
        Vectorised ``f(x, y)`` [length], or ``"module:name"`` of one.
    scale : float, keyword-only
        Half-width [length] of the validation sample, ``> 0``.
    """

    type_name = "callable"
    units = {"scale": "length"}

    def __init__(self, function, *, scale=1.0):
        if isinstance(function, str):
            function = _import_function(function)
        self.function = check_callable("function", function)
        self.scale = check_positive("scale", scale)
        s = np.linspace(-self.scale, self.scale, 5)
        self(*np.meshgrid(s, s, indexing="ij"))

    def _evaluate(self, x, y):
        try:
            h = np.asarray(self.function(x.copy(), y.copy()), dtype=float)
        except (TypeError, ValueError) as exc:
            raise InputError(f"function = {self.function!r} failed on an array of points: {exc}") from exc
        if h.shape != x.shape:
            raise InputError(
                f"function returned shape {h.shape} for points of shape {x.shape}, which is not allowed: "
                "it must return one value per point (vectorised)."
            )
        bad = ~(np.isfinite(h) & (h >= 0.0))
        if bad.any():
            i = np.unravel_index(np.argmax(bad), bad.shape)
            raise InputError(
                f"f(x, y) = {float(h[i])!r} at (x, y) = ({float(x[i])!r}, {float(y[i])!r}) is not allowed: "
                "a gap must be finite and >= 0."
            )
        return h

    def _params(self):
        return {"function": _function_path(self.function), "scale": self.scale}

    def __repr__(self):
        return f"Callable({self.function!r}, scale={self.scale!r})"
