"""Rollers with a crown along their axis (Lundberg's logarithmic crown, a circular crown, none)."""

from __future__ import annotations

import math

import numpy as np

from ..checks import check_choice, check_positive, check_scale, fail
from .base import Gap

__all__ = ["CrownedRoller", "lundberg_coefficient"]


def lundberg_coefficient(force, length, E_star):
    """Lundberg's logarithmic-crown coefficient ``A = P / (pi l E*)`` [length].

    A line load of intensity ``q = P / l`` on ``|x| < l/2`` lowers the surface
    on the axis by ``(q / (pi E*)) ln(1 - (2x/l)**2)`` relative to the centre
    (far-field of the Boussinesq kernel, paper eq. 3); the crown
    ``-A ln(1 - (2x/l)**2)`` compensates it, so the design load ``P`` is
    carried without edge peaks (G. Lundberg, Forsch. Ing.-Wes. 10 (1939)
    201-211; with ``E' = 2 E*`` this is the usual ``2P / (pi l E')``).

    Parameters
    ----------
    force : float
        Design load ``P`` [force], ``> 0``.
    length : float
        Effective roller length ``l`` [length], ``> 0``.
    E_star : float
        Johnson's effective modulus [pressure], ``> 0``.
    """
    force = check_positive("design_force", force)
    length = check_positive("length", length)
    E_star = check_positive("E_star", E_star)
    return force / (math.pi * length * E_star)


class CrownedRoller(Gap):
    """Roller with its axis along x: ``h = y**2 / (2 R) + h_x(x)``.

    Axial crown ``h_x``:

    - ``"log"`` (Lundberg): ``h_x = -A ln(1 - (2x/l)**2)``, with ``A`` given
      directly or from a design load, ``A = design_force / (pi l E_star)``
      (:func:`lundberg_coefficient`);
    - ``"circular"``: ``h_x = x**2 / (2 crown_radius)``;
    - ``"none"``: a straight roller, ``h_x = 0``.

    The roller ends at ``|x| = l/2``. There, and beyond, the gap is the finite
    value ``end_gap = 1e3 * l`` (the gap is also capped at it inside), so the
    field stays finite; ``domain`` says where the shape is real, and a
    candidate region must lie strictly inside ``|x| < l/2``.

    Parameters
    ----------
    length : float
        Roller length ``l`` [length], ``> 0``.
    R : float
        Effective transverse radius [length], ``> 0``.
    crown : {"log", "circular", "none"}
    A : float, keyword-only
        Log-crown coefficient [length], ``> 0`` (``"log"`` only; give either
        ``A`` or ``design_force`` with ``E_star``).
    design_force, E_star : float, keyword-only
        Design load [force] and effective modulus [pressure] for ``A``.
    crown_radius : float, keyword-only
        Crown radius [length], ``> 0`` (``"circular"`` only).
    """

    type_name = "crowned_roller"
    units = {"length": "length", "R": "length", "A": "length", "crown_radius": "length",
             "design_force": "force", "E_star": "pressure"}
    CROWN_KEYS = {"log": ("A", "design_force", "E_star"), "circular": ("crown_radius",), "none": ()}

    def __init__(self, length, R, crown="log", *, A=None, crown_radius=None,
                 design_force=None, E_star=None):
        self.length = check_scale("length", length)
        self.R = check_scale("R", R)
        self.crown = check_choice("crown", crown, tuple(self.CROWN_KEYS))
        given = {"A": A, "crown_radius": crown_radius, "design_force": design_force, "E_star": E_star}
        for name, value in given.items():
            if value is not None and name not in self.CROWN_KEYS[self.crown]:
                fail(name, value, f'left out for crown="{self.crown}"')
        self.A = self.crown_radius = None
        if self.crown == "log":
            if (A is None) == (design_force is None):
                fail("(A, design_force)", (A, design_force), 'exactly one given for crown="log"')
            if A is not None:
                if E_star is not None:
                    fail("E_star", E_star, "left out when A is given (it only sets A from design_force)")
                self.A = check_positive("A", A)
            elif E_star is None:
                fail("E_star", E_star, "given with design_force (A = design_force / (pi length E_star))")
            else:
                self.A = lundberg_coefficient(design_force, self.length, E_star)
        elif self.crown == "circular":
            self.crown_radius = check_scale("crown_radius", crown_radius)
        self.end_gap = 1e3 * self.length
        self.domain = ((-self.length / 2, self.length / 2), (-math.inf, math.inf))

    def _evaluate(self, x, y):
        u2 = (2.0 * x / self.length) ** 2
        inside = u2 < 1.0
        if self.crown == "log":
            hx = -self.A * np.log1p(-np.where(inside, u2, 0.0))
        elif self.crown == "circular":
            hx = x * x / (2.0 * self.crown_radius)
        else:
            hx = np.zeros_like(x)
        h = np.minimum(y * y / (2.0 * self.R) + hx, self.end_gap)
        return np.where(inside, h, self.end_gap)

    def _params(self):
        extra = {"A": self.A, "crown_radius": self.crown_radius}
        return {"length": self.length, "R": self.R, "crown": self.crown,
                **{k: v for k, v in extra.items() if v is not None}}

    def expected_semi_axes(self, *, E_star, force=None, approach=None, layer=None):
        """``ax = l/2``; ``ay`` the Hertz line-contact half-width ``b = sqrt(4 P R / (pi l E*))``
        (Johnson 1985, ISBN 978-0-521-34796-9, sec. 4.3, load per length ``P/l``), or
        ``sqrt(R delta)`` under approach control (heuristic)."""
        if force is not None:
            return self.length / 2, math.sqrt(4.0 * force * self.R / (math.pi * self.length * E_star))
        return self.length / 2, math.sqrt(self.R * approach)
