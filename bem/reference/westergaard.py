"""Westergaard's wavy contact: a sinusoidal gap pressed flat, periodic in ``x``, in closed form.

H. M. Westergaard, J. Appl. Mech. 6 (1939) A49-A53; K. L. Johnson, *Contact Mechanics*,
Cambridge University Press, 1985, ISBN 978-0-521-34796-9, section 13.2. The gap
``h(x) = Delta (1 - cos(2 pi x / lambda))`` (uniform in ``y``) closes first at ``x = 0``.
Full contact needs the mean pressure

    p_wfc = pi E* Delta / lambda.

Below it (``pbar < p_wfc``) the contact is ``|x| < a`` (mod ``lambda``) with

    pbar / p_wfc = sin^2(pi a / lambda),
    p(x) = 2 pbar cos(pi x / lambda) / sin^2(pi a / lambda) sqrt(sin^2(pi a / lambda) - sin^2(pi x / lambda)),

and above it the contact is full and ``p(x) = pbar + p_wfc cos(2 pi x / lambda)``: the
pressure of a cosine displacement ``Delta cos(2 pi x / lambda)`` that closes the gap, whose
transform ``2 / (E* |k|)`` gives ``p_wfc``. The two forms meet at ``pbar = p_wfc``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_positive

__all__ = ["Westergaard", "westergaard"]


@dataclass(frozen=True)
class Westergaard:
    """Westergaard's solution for one mean pressure (module docstring); lengths and pressures as given."""

    amplitude: float
    wavelength: float
    E_star: float
    mean_pressure: float
    converged = True
    message = "closed form (Westergaard)"

    @property
    def full_contact_pressure(self):
        """``p_wfc = pi E* Delta / lambda`` [pressure], the mean pressure that closes the gap everywhere."""
        return math.pi * self.E_star * self.amplitude / self.wavelength

    @property
    def contact_half_width(self):
        """``a`` [length], ``lambda / 2`` in full contact."""
        ratio = self.mean_pressure / self.full_contact_pressure
        if ratio >= 1:
            return self.wavelength / 2
        return self.wavelength / math.pi * math.asin(math.sqrt(ratio))

    @property
    def contact_fraction(self):
        """``2 a / lambda``: the fraction of the period in contact."""
        return 2 * self.contact_half_width / self.wavelength

    @property
    def p_max(self):
        """Peak pressure [pressure], at ``x = 0``."""
        return float(self.pressure(0.0))

    def pressure(self, x):
        """``p(x)`` [pressure] at the abscissae ``x`` [length] (periodic)."""
        x = np.asarray(x, dtype=float)
        pbar, p_wfc, lam = self.mean_pressure, self.full_contact_pressure, self.wavelength
        if pbar >= p_wfc:
            return pbar + p_wfc * np.cos(2 * math.pi * x / lam)
        s2a = pbar / p_wfc
        c = np.cos(math.pi * x / lam)
        inside = np.maximum(s2a - np.sin(math.pi * x / lam) ** 2, 0.0)
        return 2 * pbar * np.abs(c) / s2a * np.sqrt(inside)


def westergaard(amplitude, wavelength, E_star, mean_pressure):
    """Westergaard's wavy contact at the mean pressure ``mean_pressure`` [pressure].

    Parameters
    ----------
    amplitude : float
        ``Delta`` [length]: the gap is ``Delta (1 - cos(2 pi x / lambda))``.
    wavelength : float
        ``lambda`` [length].
    E_star : float
        Effective modulus [pressure].
    mean_pressure : float
        ``pbar`` [pressure], > 0.

    Returns
    -------
    Westergaard
    """
    return Westergaard(check_positive("amplitude", amplitude), check_positive("wavelength", wavelength),
                       check_positive("E_star", E_star), check_positive("mean_pressure", mean_pressure))
