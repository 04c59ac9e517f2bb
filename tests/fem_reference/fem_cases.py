"""Closed forms and constants shared by the FEM reference tests (written out independently)."""

import math

import numpy as np

E, NU = 200e3, 0.3          # MPa
E_SOFT, NU_SOFT = 70e3, 0.2  # a dissimilar lower body
R = 10.0                    # mm
P = 100.0                   # N


def e_star(E1, nu1, E2, nu2):
    """Johnson's effective modulus, written out here (independent of the code under test)."""
    return 1.0 / ((1 - nu1**2) / E1 + (1 - nu2**2) / E2)


def hertz(force, radius, Es):
    """Hertz sphere-on-flat: contact radius, peak pressure, approach (Johnson 1985, sec. 4.2)."""
    a = (3.0 * force * radius / (4.0 * Es)) ** (1.0 / 3.0)
    p0 = 3.0 * force / (2.0 * math.pi * a * a)
    return a, p0, a * a / radius


def hertz_pressure(r, a, p0):
    return p0 * np.sqrt(np.clip(1.0 - (np.asarray(r) / a) ** 2, 0.0, None))
