"""CuPy against NumPy: the same solves on a CUDA device (skipped without CuPy or a device)."""

import math

import numpy as np
import pytest

import bem
from bem import layers
from bem.gaps import Paraboloid
from bem.periodic import PeriodicCell, solve_periodic

cupy = pytest.importorskip("cupy")


def _has_device():
    try:
        return cupy.cuda.runtime.getDeviceCount() > 0
    except cupy.cuda.runtime.CUDARuntimeError:
        return False


pytestmark = pytest.mark.skipif(not _has_device(), reason="no CUDA device")

KW = dict(E_star=1.0, force=1.0, step=0.02, extent=1.2)


def _same(a, b, tol=1e-10):
    assert a.converged and b.converged
    assert isinstance(b.p, np.ndarray)
    assert np.abs(b.p - a.p).max() <= tol * a.p.max()
    assert abs(b.approach - a.approach) <= tol * abs(a.approach)


@pytest.mark.parametrize("layer, method", [(None, "kalker"), (layers.Root(0.05), "newton"),
                                           (layers.Linear(0.02), "augmented_gap"),
                                           (layers.Power(0.1, 2.0), "variable_compliance"),
                                           (layers.Tabulated(np.linspace(0, 4, 41), 0.05 * np.linspace(0, 4, 41) ** 0.5),
                                            "newton")])
def test_cuda_solve_equals_the_numpy_solve(layer, method):
    ref = bem.solve(Paraboloid(1.0), layer=layer, method=method, **KW)
    seen = []
    res = bem.solve(Paraboloid(1.0), layer=layer, method=method, device="cuda",
                    callback=lambda k, p: seen.append(isinstance(p, cupy.ndarray)), **KW)
    _same(ref, res)
    assert seen and all(seen)


@pytest.mark.parametrize("layer", [None, layers.Root(0.2)])
def test_cuda_periodic_solve_equals_the_numpy_solve(layer):
    cell = PeriodicCell(1.0 / 64, 64, 64)
    h = 0.05 * (2 - np.cos(2 * math.pi * cell.x) - np.cos(2 * math.pi * cell.y / cell.size[1]))
    kw = dict(step=cell.step, E_star=1.0, mean_pressure=0.02, layer=layer)
    _same(solve_periodic(h, **kw), solve_periodic(h, device="cuda", **kw))


def test_cuda_subsurface_stress_equals_the_numpy_stress():
    res = bem.solve(Paraboloid(1.0), **KW)
    z = np.linspace(0.0, 0.3, 5)
    ref = bem.subsurface_stress(res, z, nu=0.3)
    out = bem.subsurface_stress(res, z, nu=0.3, device="cuda")
    assert isinstance(out.sigma, np.ndarray)
    assert np.abs(out.sigma - ref.sigma).max() <= 1e-10 * np.abs(ref.sigma).max()
