"""A periodic gap of a few seeded waves and its cell, a root law and the functional, for the tests of Newton's method
on a cell (tests/bem/test_newton_buffers.py, test_newton_closure_move.py, test_newton_line_search.py)."""

import math

import numpy as np

import bem
from bem import layers
from bem.periodic import PeriodicCell

CELL = PeriodicCell(1.0 / 48, 48, 48)
FORCE = 0.02


def root_law(scale):
    """A root law whose closure at the mean pressure ``FORCE / CELL.area`` is ``scale`` times the elastic ``C_nn``
    times it."""
    return layers.Root(scale * bem.diagonal_coefficient(CELL.step, 1.0) * math.sqrt(FORCE / CELL.area))


def phi(op, layer, h, p, delta):
    """``Phi / a`` of eq. 15 by its definition."""
    return 0.5 * float(np.sum(p * op.matvec(p))) + float(np.sum(p * (h - delta))) + float(np.sum(layer.energy(p)))


def waves(cell, seed=5, modes=8):
    """``modes`` plane waves of amplitude ``0.01 / m`` in random directions, smallest value 0 [length]."""
    rng = np.random.default_rng(seed)
    lx, ly = cell.size
    h = np.zeros(cell.shape)
    for m in range(1, modes + 1):
        kx, ky = 2 * math.pi * rng.integers(-m, m + 1) / lx, 2 * math.pi * m / ly
        h += 0.01 * np.cos(kx * cell.x + ky * cell.y + rng.uniform(0, 2 * math.pi)) / m
    return h - h.min()
