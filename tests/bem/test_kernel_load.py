"""The loads of the compiled kernels (bem.extremes.load, bem.newton_passes.load, bem.periodic.passes.load,
bem.periodic.step_passes.load) cover every signature a solve calls, so that a clock started after them
(benchmarks/cases.py) counts no load."""

import json
import subprocess
import sys

import pytest

from bem import extremes
from bem.periodic import passes, step_passes

numba = pytest.importorskip("numba", reason="the compiled kernels need numba (contactlab[fast])")


_SOLVE = """
import json, sys, threading
import numpy as np
from numba.core.dispatcher import Dispatcher
import bem
from bem import extremes, newton_passes
from bem.periodic import passes, step_passes

assert passes.load() and step_passes.load() and extremes.load() and newton_passes.load()
names, lock, original = [], threading.Lock(), Dispatcher._compile_for_args

def recorded(self, *args, **kwargs):
    with lock:
        names.append(self.py_func.__name__)
    return original(self, *args, **kwargs)

Dispatcher._compile_for_args = recorded
n = 512
cell = bem.periodic.PeriodicCell(1.0 / n, n, n)
x, y, ly = cell.x, cell.y, cell.size[1]
h = 0.02 * (np.cos(2 * np.pi * 3 * x) * np.cos(2 * np.pi * 2 * y / ly) + np.sin(2 * np.pi * 7 * x)) ** 2
layer = bem.layers.Root(1e-3) if sys.argv[1] == "root" else None
res = bem.solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=0.01, rtol=1e-8, layer=layer)
print(json.dumps([bool(res.converged), float(np.mean(res.p > 0)), names]))
"""


@pytest.mark.parametrize("case", ["smooth", "root"])
def test_after_the_loads_a_large_cells_solve_loads_no_kernel(case):
    """In a fresh process (the compiled kernels' signatures are per process), a cell of ``MIN_NODES`` nodes (the
    compiled passes, the block products with the cell's read-only symbols, the step's passes, the prolongation, the
    KKT residual's extremes and with a root layer Newton's passes), smooth and with a root layer: the loads made every
    signature it calls."""
    assert 512 * 512 >= passes.MIN_NODES and 512 * 512 >= extremes.MIN_NODES
    run = subprocess.run([sys.executable, "-c", _SOLVE, case], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    converged, share, loaded = json.loads(run.stdout.strip().splitlines()[-1])
    assert converged and 0.05 < share < 0.9
    assert loaded == []


def test_the_extremes_load_without_numba(monkeypatch):
    assert extremes.load() is True
    monkeypatch.setitem(sys.modules, "numba", None)  # an import of numba fails
    assert extremes._compile() is None
    monkeypatch.setattr(extremes, "_COMPILED", [])
    assert extremes.load() is False
    assert extremes._COMPILED == [None]
