"""CuPy against NumPy: the same solves on a CUDA device (skipped without CuPy or a device)."""

import math

import numpy as np
import pytest

import bem
from bem import layers
from bem.gaps import Paraboloid
from bem.periodic import PeriodicCell, solve_periodic

from .fourier_qp_cases import CASES, compare

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


# the paper's methods on a coarser lattice (step 0.1, C_nn = 0.09): the augmented gap method converges
# only for a layer stiffer than about C_nn (docs/method.md), Linear(0.02) is 0.22 C_nn there
PAPER_KW = dict(KW, step=0.1, nested=False)


@pytest.mark.parametrize("layer, method, kw", [(None, "kalker", KW), (layers.Root(0.05), "newton", KW),
                                               (layers.Linear(0.02), "augmented_gap", PAPER_KW),
                                               (layers.Power(0.1, 2.0), "variable_compliance", PAPER_KW),
                                               (layers.Tabulated(np.linspace(0, 4, 41),
                                                                 0.05 * np.linspace(0, 4, 41) ** 0.5), "newton", KW)],
                         ids=["kalker", "newton_root", "augmented_gap_linear", "variable_compliance_power",
                              "newton_tabulated"])
def test_cuda_solve_equals_the_numpy_solve(layer, method, kw):
    ref = bem.solve(Paraboloid(1.0), layer=layer, method=method, **kw)
    seen = []
    res = bem.solve(Paraboloid(1.0), layer=layer, method=method, device="cuda",
                    callback=lambda k, p: seen.append(isinstance(p, cupy.ndarray)), **kw)
    _same(ref, res)
    assert seen and all(seen)


@pytest.mark.parametrize("layer", [None, layers.Root(0.2)])
def test_cuda_periodic_solve_equals_the_numpy_solve(layer):
    cell = PeriodicCell(1.0 / 64, 64, 64)
    h = 0.05 * (2 - np.cos(2 * math.pi * cell.x) - np.cos(2 * math.pi * cell.y / cell.size[1]))
    # the cell's QP in the Fourier basis on both, solved far enough (KKT 1e-13) for the answers to agree to 1e-10
    kw = dict(step=cell.step, E_star=1.0, mean_pressure=0.02, layer=layer, rtol=1e-13)
    _same(solve_periodic(h, **kw), solve_periodic(h, device="cuda", **kw))


def test_cuda_subsurface_stress_equals_the_numpy_stress():
    res = bem.solve(Paraboloid(1.0), **KW)
    z = np.linspace(0.0, 0.3, 5)
    ref = bem.subsurface_stress(res, z, nu=0.3)
    out = bem.subsurface_stress(res, z, nu=0.3, device="cuda")
    assert isinstance(out.sigma, np.ndarray)
    assert np.abs(out.sigma - ref.sigma).max() <= 1e-10 * np.abs(ref.sigma).max()


@pytest.mark.parametrize("case", ["hardness", "coating"])
def test_cuda_hardness_and_coatings_equal_the_numpy_solve(case):
    extra = (dict(E_star=1.0, hardness=0.5) if case == "hardness"
             else dict(E1=1.0, nu1=0.3, E2=1.0, nu2=0.3, coating1=bem.Coating(0.2, 3.0, 0.3)))
    kw = {k: v for k, v in KW.items() if k != "E_star"} | extra
    _same(bem.solve(Paraboloid(1.0), **kw), bem.solve(Paraboloid(1.0), device="cuda", **kw))
    cell = PeriodicCell(1.0 / 64, 64, 64)
    h = 0.05 * (2 - np.cos(2 * math.pi * cell.x) - np.cos(2 * math.pi * cell.y / cell.size[1]))
    kw = dict(step=cell.step, mean_pressure=0.02, rtol=1e-13) | (dict(E_star=1.0, hardness=0.05) if case == "hardness"
                                                                 else extra)
    _same(solve_periodic(h, **kw), solve_periodic(h, device="cuda", **kw))



@pytest.mark.parametrize("case", CASES)
def test_cuda_fourier_qp_takes_the_numpy_path(monkeypatch, case):
    """The periodic cell's QP in the Fourier basis (bem.periodic.qp) on CuPy: the iteration of NumPy, step by
    step, to the same count, and its answer (tests/bem/fourier_qp_cases.py, as on the strict namespace)."""
    assert isinstance(compare(case, "cuda", cupy.asarray, monkeypatch).p, cupy.ndarray)
