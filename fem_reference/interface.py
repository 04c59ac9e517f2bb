"""The interface traction law of the FEM: the layer law as a penalty, regularised for Newton.

The overlap of an interface node pair is (docs/method.md section 1, eq. 14)::

    g = delta - h(r) - d,     d = u_z^upper - u_z^lower + delta_far   (elastic part)

i.e. the interpenetration of the undeformed surfaces, corrected by the initial gap,
that is left after the elastic deformation: ``g = w(p)`` in contact. The traction is
``p = w^{-1}(g)`` for ``g > 0`` and ``0`` for ``g <= 0`` (``layer.inverse``, imported from
:mod:`bem.layers`, not re-coded). Newton needs ``dp/dg = 1 / w'(p)``:

- where ``w'(p) = inf`` (root / power ``s < 1`` at ``p = 0``) the tangent is 0;
- where ``w'(p) = 0`` or ``1/w'(p)`` exceeds ``k_pen`` (power ``s > 1`` near ``p = 0``) it is
  capped at ``k_pen``: only the Newton matrix changes, not the equations;
- a rigid branch (``inverse = inf`` beyond the overlap ``g_lim`` the law can reach) is
  continued by the penalty ``p = p_lim + k_pen (g - g_lim)``.

Without a layer (smooth bodies) the law is the pure penalty ``p = k_pen max(g, 0)``, i.e.
a Winkler layer of compliance ``1/k_pen``: its error vanishes as ``k_pen -> inf``.

Every law has the convex potential ``Psi(g) = integral_0^g p`` (``Psi = g p - W(p)`` on
the elastic branch, ``W = layer.energy``), which makes the condensed interface problem
the minimisation of a convex functional (:mod:`fem_reference.newton`).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["InterfaceLaw"]

_BISECTIONS = 200


class InterfaceLaw:
    """Traction ``p(g)``, tangent ``dp/dg`` and potential ``Psi(g)`` of the interface.

    Parameters
    ----------
    layer : bem.layers.Layer or None
        Interface law ``w(p)``; ``None`` for smooth bodies (pure penalty).
    k_pen : float
        Penalty stiffness [pressure/length]: the whole law without a layer, the
        continuation of rigid branches and the cap of the tangent.
    """

    def __init__(self, layer, k_pen):
        self.layer = layer
        self.k_pen = float(k_pen)
        self._rigid = None  # (g_lim, p_lim, Psi(g_lim)) once a rigid branch is met

    # -- rigid branch -----------------------------------------------------------------
    def _rigid_limit(self, g_inf):
        """``(g_lim, p_lim, Psi_lim)``: largest overlap with a finite inverse, by bisection."""
        if self._rigid is None:
            lo, hi = 0.0, float(g_inf)
            for _ in range(_BISECTIONS):
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    break
                if math.isfinite(float(self.layer.inverse(mid))):
                    lo = mid
                else:
                    hi = mid
            p_lim = float(self.layer.inverse(lo))
            self._rigid = (lo, p_lim, lo * p_lim - float(self.layer.energy(p_lim)))
        return self._rigid

    def _split(self, g):
        """Pressure on the law's own branch (``inf`` on a rigid branch) and the rigid mask."""
        g = np.asarray(g, dtype=float)
        p = np.asarray(self.layer.inverse(np.maximum(g, 0.0)), dtype=float)
        p = np.where(g > 0, p, 0.0)
        rigid = ~np.isfinite(p)
        if rigid.any():
            self._rigid_limit(float(g[rigid].min()))
        if self._rigid is not None:
            rigid = rigid | (g > self._rigid[0])
        return p, rigid

    # -- public -----------------------------------------------------------------------
    def pressure(self, g):
        """Traction ``p(g) >= 0`` [pressure] at overlaps ``g`` [length]."""
        g = np.asarray(g, dtype=float)
        if self.layer is None:
            return self.k_pen * np.maximum(g, 0.0)
        p, rigid = self._split(g)
        if rigid.any():
            g_lim, p_lim, _ = self._rigid
            p = np.where(rigid, p_lim + self.k_pen * (g - g_lim), p)
        return p

    def tangent(self, g):
        """Regularised ``dp/dg`` [pressure/length] (0 out of contact, at most ``k_pen``)."""
        g = np.asarray(g, dtype=float)
        if self.layer is None:
            return np.where(g > 0, self.k_pen, 0.0)
        p, rigid = self._split(g)
        dw = np.asarray(self.layer.dw(np.where(rigid, 0.0, p)), dtype=float)
        with np.errstate(divide="ignore"):
            t = np.where(dw > 0, 1.0 / np.where(dw > 0, dw, 1.0), np.inf)
        t = np.minimum(t, self.k_pen)
        return np.where(rigid, self.k_pen, np.where(g > 0, t, 0.0))

    def potential(self, g):
        """``Psi(g) = integral_0^g p`` [pressure * length]; convex, 0 for ``g <= 0``."""
        g = np.asarray(g, dtype=float)
        if self.layer is None:
            return 0.5 * self.k_pen * np.maximum(g, 0.0) ** 2
        p, rigid = self._split(g)
        pe = np.where(rigid, 0.0, p)
        psi = np.where(g > 0, g * pe - np.asarray(self.layer.energy(pe), dtype=float), 0.0)
        if rigid.any():
            g_lim, p_lim, psi_lim = self._rigid
            e = g - g_lim
            psi = np.where(rigid, psi_lim + p_lim * e + 0.5 * self.k_pen * e * e, psi)
        return psi

    def rigid_limit(self):
        """``(g_lim, p_lim)`` of a rigid branch met so far, else ``None``."""
        return None if self._rigid is None else self._rigid[:2]
