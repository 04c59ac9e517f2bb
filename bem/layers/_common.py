"""Shared plumbing of the concrete layer laws: argument handling and serialisation.

Conventions every law follows (docs/method.md section 1):

- pressures ``p`` are compressive; ``p < 0`` is treated as ``p = 0`` (clipped), NaN propagates;
- closures ``c <= 0`` invert to ``p = 0``;
- arrays in, arrays of the same shape out; a scalar in gives a NumPy scalar out;
- inputs are never modified.
"""

from __future__ import annotations

import importlib

import numpy as np

from ..backend import backend_of
from ..checks import InputError, check_callable
from .base import Layer

__all__ = ["LawBase", "as_pressure", "as_closure", "out", "callable_ref", "resolve_callable"]


def _on_host(x):
    return not hasattr(x, "shape") or isinstance(x, (np.ndarray, np.generic))


def as_pressure(p):
    """Return ``max(p, 0)`` as a new float array (``-0.0`` becomes ``+0.0``; NaN stays NaN).

    A float64 array of another namespace (a device array) stays in its namespace.
    """
    x = np.maximum(np.asarray(p, dtype=float), 0.0) if _on_host(p) else backend_of(p).xp.maximum(p, 0.0)
    x += 0.0  # in the new array (a NumPy scalar for a scalar)
    return x


def as_closure(closure):
    """Return ``closure`` as a float array (a new one, never the caller's), in its namespace."""
    if _on_host(closure):
        return np.array(closure, dtype=float)
    return backend_of(closure).copy(closure)


def out(x):
    """Return a NumPy scalar for 0-d results, the array otherwise (device arrays as they are)."""
    if _on_host(x):
        return np.asarray(x)[()]
    return x


class LawBase(Layer):
    """Base of the concrete laws: ``to_dict``, ``repr``, ``a + b`` (series) and ``p_scale``.

    Subclasses set ``law`` (the name in ``to_dict``), ``_required`` and ``_optional`` (the
    constructor keywords ``from_dict`` accepts) and implement :meth:`_params`.
    """

    law: str = ""
    _required: tuple[str, ...] = ()
    _optional: tuple[str, ...] = ()

    def _params(self):
        """Parameters as a dict of plain Python values (the constructor keywords)."""
        raise NotImplementedError

    def to_dict(self):
        """``{"law": name, **parameters}``, rebuilt by :func:`bem.layers.from_dict`."""
        return {"law": self.law, **self._params()}

    def __repr__(self):
        args = ", ".join(f"{k}={v!r}" for k, v in self._params().items())
        return f"{type(self).__name__}({args})"

    @property
    def p_scale(self):
        """A typical pressure of the law [pressure]: starts the numerical inverse searches."""
        return 1.0

    def secant(self, p):
        """Secant compliance ``w(p) / p`` [length/pressure], ``w'(0)`` at ``p <= 0``."""
        p = as_pressure(p)
        return out(np.where(np.isnan(p), np.nan, super().secant(p)))

    def __add__(self, other):
        if not isinstance(other, Layer):
            return NotImplemented
        from .series import Series

        return Series(self, other)

    def __radd__(self, other):
        if not isinstance(other, Layer):
            return NotImplemented
        from .series import Series

        return Series(other, self)


def callable_ref(f):
    """``"module:qualname"`` when ``f`` can be re-imported by that name, else ``f`` itself."""
    module, qualname = getattr(f, "__module__", None), getattr(f, "__qualname__", None)
    if not module or not qualname or "<" in qualname:
        return f
    try:
        if _import(module, qualname) is f:
            return f"{module}:{qualname}"
    except (ImportError, AttributeError):
        pass
    return f


def resolve_callable(name, value):
    """Return a callable from a callable or a ``"module:function"`` string; else InputError."""
    if isinstance(value, str):
        module, sep, qualname = value.partition(":")
        try:
            if not (sep and module and qualname):
                raise ImportError
            value = _import(module, qualname)
        except (ImportError, AttributeError):
            raise InputError(
                f"{name} = {value!r} is not allowed: it must be a callable or an importable "
                "'module:function' reference."
            ) from None
    return check_callable(name, value)


def _import(module, qualname):
    obj = importlib.import_module(module)
    for part in qualname.split("."):
        obj = getattr(obj, part)
    return obj
