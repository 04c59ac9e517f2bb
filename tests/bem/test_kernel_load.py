"""The loads of the compiled kernels (bem.extremes.load, bem.newton_passes.load, bem.periodic.passes.load,
bem.periodic.step_passes.load) cover every signature a solve calls, so that a clock started after them
(benchmarks/cases.py) counts no load."""

import sys
import threading

import numpy as np
import pytest

import bem
from bem import extremes, newton_passes
from bem.periodic import passes, step_passes

numba = pytest.importorskip("numba", reason="the compiled kernels need numba (contactlab[fast])")


@pytest.fixture
def loads(monkeypatch):
    """The kernels a call compiles or loads from numba's cache (their names), recorded from here on."""
    from numba.core.dispatcher import Dispatcher

    names, lock, original = [], threading.Lock(), Dispatcher._compile_for_args

    def recorded(self, *args, **kwargs):
        with lock:
            names.append(self.py_func.__name__)
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Dispatcher, "_compile_for_args", recorded)
    return names


@pytest.mark.parametrize("root", [False, True])
def test_after_the_loads_a_large_cells_solve_loads_no_kernel(loads, root):
    """A cell of ``MIN_NODES`` nodes (the compiled passes, the block products with the cell's read-only symbols, the
    step's passes, the prolongation, the KKT residual's extremes and with a root layer Newton's passes), smooth and with
    a root layer: the loads made every signature it calls."""
    assert passes.load() and step_passes.load() and extremes.load() and newton_passes.load()
    loads.clear()
    n = 512
    assert n * n >= passes.MIN_NODES and n * n >= extremes.MIN_NODES
    cell = bem.periodic.PeriodicCell(1.0 / n, n, n)
    x, y, ly = cell.x, cell.y, cell.size[1]
    h = 0.02 * (np.cos(2 * np.pi * 3 * x) * np.cos(2 * np.pi * 2 * y / ly) + np.sin(2 * np.pi * 7 * x)) ** 2
    layer = bem.layers.Root(1e-3) if root else None
    res = bem.solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=0.01, rtol=1e-8, layer=layer)
    assert res.converged and 0.05 < np.mean(res.p > 0) < 0.9
    assert loads == []


def test_the_extremes_load_without_numba(monkeypatch):
    assert extremes.load() is True
    monkeypatch.setitem(sys.modules, "numba", None)  # an import of numba fails
    assert extremes._compile() is None
    monkeypatch.setattr(extremes, "_COMPILED", [])
    assert extremes.load() is False
    assert extremes._COMPILED == [None]
