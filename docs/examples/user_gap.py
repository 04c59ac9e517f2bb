"""A gap of your own: a ball with a machined waviness, given as a Python function h(x, y).

Any vectorised function of the coordinates [m] returning the initial gap [m] (finite, >= 0,
zero where the bodies first touch) can be used with :class:`bem.gaps.Callable`. Such a gap has
no estimate of the contact size, so the lattice step and the candidate region are given
explicitly. In a scene file the same gap is ``[gap] type = "callable"``,
``function = "module:name"`` (docs/scenes.md). Run::

    python docs/examples/user_gap.py
"""

from __future__ import annotations

import numpy as np

import bem
from bem.gaps import Callable
from bem.reference import hertz_sphere

R = 0.01             # m, ball radius (on a flat)
WAVE_LENGTH = 1e-4   # m, period of the waviness along x
WAVE_DEPTH = 0.5e-6  # m, peak-to-valley depth of the waviness


def wavy_ball(x, y):
    """Initial gap [m] at ``(x, y)`` [m]: the ball's paraboloid plus a waviness along x."""
    return (x**2 + y**2) / (2 * R) + 0.5 * WAVE_DEPTH * (1 - np.cos(2 * np.pi * x / WAVE_LENGTH))


def main():
    """Solve the wavy ball and the smooth one; return both results and the peak ratio."""
    E, nu, P = 210e9, 0.3, 100.0                   # Pa, -, N: steel on steel, 100 N
    E_star = bem.effective_modulus(E, nu, E, nu)   # Pa
    a = hertz_sphere(R, E_star, force=P).contact_radius         # m, the smooth ball's contact radius
    options = dict(E_star=E_star, force=P, step=a / 40, extent=1.6 * a)
    wavy = bem.solve(Callable(wavy_ball, scale=a), **options)
    smooth = bem.solve(Callable(lambda x, y: (x**2 + y**2) / (2 * R), scale=a), **options)
    ratio = wavy.p_max / smooth.p_max
    print(f"smooth ball: p_max {smooth.p_max / 1e9:.3f} GPa, contact area {smooth.contact_area * 1e12:.0f} um^2")
    print(f"wavy ball:   p_max {wavy.p_max / 1e9:.3f} GPa, contact area {wavy.contact_area * 1e12:.0f} um^2 "
          f"(peak x{ratio:.2f}); converged {wavy.converged}")
    return {"wavy": wavy, "smooth": smooth, "peak_ratio": ratio}


if __name__ == "__main__":
    main()
