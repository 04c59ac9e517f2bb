"""The layer-dominated (rigid-body) limit of the layered contact, in closed form.

When both bodies are rigid the contact condition (paper eq. 14) reduces pointwise to
``w(p) = delta - h``, so ``p = w^{-1}(max(delta - h, 0))``; for a paraboloid on a power
law ``w = lam p**s`` the force-approach law follows by one integral.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import (
    check_callable,
    check_choice,
    check_finite_array,
    check_load,
    check_nonnegative,
    check_positive,
    fail,
)
from .hertz import _ClosedForm

__all__ = ["RigidLayerParaboloid", "rigid_layer_pressure", "rigid_layer_paraboloid", "rigid_layer_force"]


def rigid_layer_pressure(layer, gap_values, approach):
    """Pressure when both bodies are rigid: ``p = w^{-1}(max(delta - h, 0))`` [pressure].

    The contact condition (paper eq. 14) with ``u = 0`` leaves
    ``w(p) = delta - h`` where ``p > 0``.

    Parameters
    ----------
    layer : object
        Any layer with ``inverse(closure)`` (:class:`bem.layers.Layer`).
    gap_values : array_like
        Gap ``h`` [length] at the points of interest, finite.
    approach : float
        Approach ``delta`` [length], ``>= 0``.

    Returns
    -------
    numpy.ndarray
        Pressure, same shape as ``gap_values``.
    """
    inverse = check_callable("layer.inverse", getattr(layer, "inverse", None))
    h = check_finite_array("gap_values", gap_values, min_size=0)
    approach = check_nonnegative("approach", approach)
    return np.asarray(inverse(np.maximum(approach - h, 0.0)), dtype=float)


_FIXED_EXPONENT = {"linear": 1.0, "root": 0.5}


def _power_parameters(law, lam, s):
    """``(lam, s)`` of ``w = lam p**s`` from a law name or a layer object."""
    if isinstance(law, str):
        law = check_choice("law", law, ("linear", "power", "root"))
        lam = check_positive("lam", lam)
        if law == "power":
            return lam, check_positive("s", s)
        fixed = _FIXED_EXPONENT[law]
        if s is not None and s != fixed:
            fail("s", s, f"left out (or {fixed}) for law={law!r}")
        return lam, fixed
    if lam is not None or s is not None:
        fail("(lam, s)", (lam, s), "left out when law is a layer object (they are read from it)")
    lam = check_positive("law.lam", getattr(law, "lam", None))
    s = getattr(law, "s", None)
    if s is None:
        s = 1.0 if getattr(law, "is_linear", False) else 0.5 if type(law).__name__ == "Root" else None
    if s is None:
        fail("law", law, "a Linear, Power or Root layer, or 'linear', 'power', 'root' with lam (and s)")
    s = check_positive("law.s", s)
    p = np.array([0.5, 2.0])
    if not np.allclose(law.w(p), lam * p**s, rtol=1e-12, atol=0.0):
        fail("law", law, f"a power law w = lam * p**s with lam = {lam}, s = {s}")
    return lam, s


@dataclass(frozen=True)
class RigidLayerParaboloid(_ClosedForm):
    """Rigid paraboloid ``h = r**2/(2R)`` pressed into a power-law layer ``w = lam p**s``.

    Attributes
    ----------
    R, lam, s : float
        Radius [length], compliance [length / pressure**s], exponent [-].
    force, approach : float
        Total force [force] and approach ``delta`` [length].
    contact_radius : float
        ``sqrt(2 R delta)`` [length].
    p_max : float
        ``(delta / lam)**(1/s)`` [pressure], at the centre.
    """

    R: float
    lam: float
    s: float
    force: float
    approach: float
    contact_radius: float
    p_max: float

    def pressure(self, x, y=0.0):
        """``((delta - r**2/(2R)) / lam)**(1/s)`` inside, 0 outside [pressure], ``r = hypot(x, y)``."""
        r = np.hypot(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        closure = np.maximum(self.approach - r * r / (2.0 * self.R), 0.0)
        return (closure / self.lam) ** (1.0 / self.s)


def rigid_layer_paraboloid(law, R, *, force=None, approach=None, lam=None, s=None):
    """Layer-dominated limit for a paraboloid: closed-form force-approach law.

    With ``p = ((delta - h)/lam)**(1/s)`` and ``h = r**2/(2R)``, the
    substitution ``u = delta - r**2/(2R)`` (``r dr = -R du``) gives::

        P = 2 pi integral_0^rc p r dr = 2 pi R integral_0^delta (u/lam)**(1/s) du
          = 2 pi R delta**(1/s + 1) / (lam**(1/s) (1/s + 1))

    i.e. ``P = pi R delta**2 / lam`` (linear, ``s = 1``) and
    ``P = 2 pi R delta**3 / (3 lam**2)`` (root, ``s = 1/2``); force control
    inverts it, ``delta = (P lam**(1/s) (1/s + 1) / (2 pi R))**(s/(1 + s))``.

    Parameters
    ----------
    law : str or layer object
        ``"linear"``, ``"power"`` or ``"root"`` with ``lam`` (and ``s`` for
        ``"power"``); or a ``bem.layers`` ``Linear``/``Power``/``Root`` object,
        whose ``lam`` (and ``s``; 1 for linear, 1/2 for root) are read and
        checked against its ``w``.
    R : float
        Radius [length], ``> 0``.
    force, approach : float, keyword-only
        Exactly one, ``> 0``.
    lam, s : float, keyword-only
        Layer parameters when ``law`` is a name.

    Returns
    -------
    RigidLayerParaboloid
    """
    lam, s = _power_parameters(law, lam, s)
    R = check_positive("R", R)
    force, approach = check_load(force, approach)
    k = 1.0 / s + 1.0
    scale = 2.0 * math.pi * R / (lam ** (1.0 / s) * k)  # P = scale * delta**k
    delta = approach if approach is not None else (force / scale) ** (1.0 / k)
    return RigidLayerParaboloid(R=R, lam=lam, s=s, force=scale * delta**k, approach=delta,
                                contact_radius=math.sqrt(2.0 * R * delta), p_max=(delta / lam) ** (1.0 / s))


def rigid_layer_force(law, R, approach, *, lam=None, s=None):
    """Force [force] of the layer-dominated paraboloid at ``approach`` [length].

    Shorthand for ``rigid_layer_paraboloid(law, R, approach=approach, ...).force``.
    """
    return rigid_layer_paraboloid(law, R, approach=approach, lam=lam, s=s).force
