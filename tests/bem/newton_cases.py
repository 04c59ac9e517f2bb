"""A periodic gap of a few seeded waves and its cell, for the tests of Newton's method on a cell
(tests/bem/test_newton_buffers.py, tests/bem/test_newton_closure_move.py)."""

import math

import numpy as np

from bem.periodic import PeriodicCell

CELL = PeriodicCell(1.0 / 48, 48, 48)


def waves(cell, seed=5, modes=8):
    """``modes`` plane waves of amplitude ``0.01 / m`` in random directions, smallest value 0 [length]."""
    rng = np.random.default_rng(seed)
    lx, ly = cell.size
    h = np.zeros(cell.shape)
    for m in range(1, modes + 1):
        kx, ky = 2 * math.pi * rng.integers(-m, m + 1) / lx, 2 * math.pi * m / ly
        h += 0.01 * np.cos(kx * cell.x + ky * cell.y + rng.uniform(0, 2 * math.pi)) / m
    return h - h.min()
