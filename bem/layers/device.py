"""Layer laws on a device: the law itself where it is array API clean, else a host adapter."""

from __future__ import annotations

from ..backend import get_backend
from .base import Layer

__all__ = ["device_layer", "HostLayer"]


def device_layer(layer, device):
    """``layer`` for arrays of ``device``.

    Laws with ``array_api = True`` (the closed forms of :mod:`bem.layers.analytic`) and every law
    on the CPU are returned as they are; other laws (tabulated, custom, series, serial: their
    inverses call SciPy) are wrapped in a :class:`HostLayer`, which copies each argument to the
    host and each result back.
    """
    bk = get_backend(device)
    if layer is None or bk.is_numpy or getattr(layer, "array_api", False):
        return layer
    return HostLayer(layer, bk)


class HostLayer(Layer):
    """A NumPy layer law evaluated on the host for arrays of another device.

    Parameters
    ----------
    layer : bem.layers.Layer
        The law.
    backend : bem.backend.Backend
        The device of the arguments and results.
    """

    array_api = True

    def __init__(self, layer, backend):
        self.layer = layer
        self.backend = backend
        self.is_linear = layer.is_linear

    def __getattr__(self, name):  # lam, p_scale, to_dict, ... of the wrapped law
        return getattr(self.__dict__["layer"], name)

    def _call(self, f, x):
        if not hasattr(x, "shape"):
            return f(x)
        return self.backend.asarray(f(self.backend.to_host(x)))

    def w(self, p):
        return self._call(self.layer.w, p)

    def dw(self, p):
        return self._call(self.layer.dw, p)

    def energy(self, p):
        return self._call(self.layer.energy, p)

    def inverse(self, closure):
        return self._call(self.layer.inverse, closure)

    def secant(self, p):
        return self._call(self.layer.secant, p)
