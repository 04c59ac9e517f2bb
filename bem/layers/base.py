"""The interface-layer protocol shared by every solver (BEM and FEM).

A layer is a normal compliance law ``w(p)``: the extra closure (length) of the
interface under the compressive pressure ``p >= 0`` (docs/method.md section 1).
Every law satisfies ``w(0) = 0`` and is non-decreasing; its energy density
``W(p) = integral_0^p w(s) ds`` enters Kalker's generalised functional (eq. 15
of the paper).

All methods are vectorised: they take and return NumPy arrays (or scalars) and
never modify their input.
"""

from __future__ import annotations

import abc

import numpy as np

__all__ = ["Layer"]


class Layer(abc.ABC):
    """Abstract normal-compliance law ``w(p)``.

    Subclasses implement :meth:`w`, :meth:`dw`, :meth:`energy` and
    :meth:`inverse`; :meth:`secant` has a default.

    Attributes
    ----------
    is_linear : bool
        True when ``w(p) = lam * p`` (the Kalker QP then solves it exactly).
    array_api : bool
        True when the methods take and return arrays of any array API namespace (device
        arrays stay on their device); other laws compute on NumPy arrays, and the solvers
        copy their arguments to the host and back (:func:`bem.layers.device.device_layer`).
    """

    is_linear: bool = False
    array_api: bool = False

    @abc.abstractmethod
    def w(self, p):
        """Closure ``w(p)`` [length] for pressure ``p >= 0`` [pressure]."""

    @abc.abstractmethod
    def dw(self, p):
        """Tangent compliance ``w'(p)`` [length/pressure]; may be ``inf`` at ``p = 0``."""

    @abc.abstractmethod
    def energy(self, p):
        """Energy density ``W(p) = integral_0^p w`` [pressure * length]."""

    @abc.abstractmethod
    def inverse(self, closure):
        """Pressure ``p >= 0`` with ``w(p) = closure`` for ``closure >= 0``.

        Returns 0 for ``closure <= 0`` and ``inf`` where the law cannot close
        that far (a rigid branch, e.g. elastic-rigid beyond ``lam * p_cr``).
        """

    def secant(self, p):
        """Secant compliance ``w(p) / p`` [length/pressure], ``w'(0)`` at ``p = 0``."""
        from ..backend import anp

        if not hasattr(p, "shape") or isinstance(p, (np.ndarray, np.generic)):
            p = np.asarray(p, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            out = anp.where(p > 0, self.w(p) / anp.where(p > 0, p, 1.0), self.dw(anp.zeros_like(p)))
        return out
