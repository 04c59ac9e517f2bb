"""The hardness bound against a peer code: tamaas' ``KatoSaturated`` (a pressure-saturated Kato solver on a
square grid of point forces), on the same seeded periodic surface; skipped where tamaas is not installed.

The two discretisations differ (pyramid elements on a triangular lattice against point forces on a square
grid), so the contact and plastic fractions agree to the discretisation error, which falls with the
resolution: measured on this surface at 128 columns, 1.1 % (elastic contact), 0.8 % and 0.5 % (contact at
H = 0.1, 0.05 E*), 2.0 % and 0.8 % (plastic); at 256 columns 0.4 %, 0.5 %, 0.3 %, 0.7 %, 0.4 %.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import bem


def _series(lx, ly, seed=5, modes=4):
    """A seeded smooth periodic surface ``z(x, y)`` of a few Fourier modes over ``(lx, ly)``."""
    rng = np.random.default_rng(seed)
    terms = [(m, n, rng.standard_normal() / (m * m + n * n), rng.uniform(0, 2 * math.pi))
             for m in range(1, modes) for n in range(-modes + 1, modes)]

    def z(x, y):
        out = np.zeros(np.broadcast(x, y).shape)
        for m, n, a, phase in terms:
            out += a * np.cos(2 * math.pi * (m * x / lx + n * y / ly) + phase)
        return 0.02 * out

    return z


@pytest.mark.slow
@pytest.mark.parametrize("hardness", [0.1, 0.05])
def test_contact_and_plastic_fractions_agree_with_tamaas(hardness):
    tm = pytest.importorskip("tamaas")
    n, pbar = 128, 0.02
    cell = bem.PeriodicCell(1.0 / n, n, n)
    lx, ly = cell.size
    z = _series(lx, ly)
    h = z(cell.x, cell.y)
    res = bem.solve_periodic(h.max() - h, step=cell.step, E_star=1.0, mean_pressure=pbar, hardness=hardness)
    assert res.status == "converged"
    ny = round(n * ly / lx)
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [lx, ly], [n, ny])
    model.E, model.nu = 1.0, 0.0  # E* = 1
    x, y = np.meshgrid(np.arange(n) * lx / n, np.arange(ny) * ly / ny, indexing="ij")
    surface = z(x, y)
    solver = tm.KatoSaturated(model, surface - surface.max(), 1e-12, hardness)
    solver.max_iter = 20000
    solver.solve(pbar)
    p = np.asarray(model.traction).reshape(-1)
    assert p.mean() == pytest.approx(pbar, rel=1e-9) and p.max() == pytest.approx(hardness, rel=1e-12)
    assert res.contact_fraction == pytest.approx(np.mean(p > 0), rel=0.015)
    assert res.plastic_fraction == pytest.approx(np.mean(p >= hardness * (1 - 1e-9)), rel=0.03)
