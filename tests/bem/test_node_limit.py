"""One memory guard for both solvers: the candidate region of ``bem.solve`` and the periodic cell of
``bem.solve_periodic`` (and the lattice and grid of a rough surface) hold at most
``bem.checks.MAX_NODES`` nodes, refused before anything is built by a message that names the
argument, its value, the nodes, the limit and the memory they would need."""

import tracemalloc

import numpy as np
import pytest

import bem
from bem import checks
from bem.periodic import PeriodicCell
from bem.rough import to_lattice

#: more than a refusal's own allocations, far less than any array of the refused lattice [bytes]
SMALL = 1e6


def _refused(call):
    """``(message, peak bytes allocated)`` of ``call()``, which must raise :class:`bem.InputError`."""
    tracemalloc.start()
    try:
        with pytest.raises(bem.InputError) as info:
            call()
        return str(info.value), tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def _states(message, n_nodes):
    """The message gives the nodes, the limit and the memory of ``n_nodes`` nodes at 0.4 kB each."""
    assert f"would hold {n_nodes:.3g} nodes" in message
    assert f"limit {checks.MAX_NODES:.3g}" in message
    assert f"about {n_nodes * 400 / 1e9:.3g} GB of memory" in message


def test_a_periodic_gap_array_over_the_limit_is_refused_before_the_solve():
    gap = np.broadcast_to(0.0, (5000, 4000))  # 2e7 nodes that occupy no memory
    message, peak = _refused(lambda: bem.solve_periodic(gap, step=1.0, E_star=1.0, mean_pressure=1.0))
    assert message.startswith("gap = '<array of shape (5000, 4000)>' is not allowed: the periodic cell")
    _states(message, 5000 * 4000)
    assert peak < SMALL


def test_a_periodic_cell_over_the_limit_is_refused_when_it_is_made():
    message, peak = _refused(lambda: PeriodicCell(1e-6, 20000, 20000))
    assert message.startswith("(n_cols, n_rows) = (20000, 20000) is not allowed")
    _states(message, 20000 * 20000)
    message, peak_size = _refused(lambda: PeriodicCell.from_size(1e-9, 1.0))
    assert message.startswith("step = 1e-09 is not allowed")
    assert max(peak, peak_size) < SMALL
    assert PeriodicCell(1.0, 4000, 4000).n_nodes == checks.MAX_NODES  # the limit itself is allowed
    with pytest.raises(bem.InputError, match="would hold 1.6e"):
        PeriodicCell(1.0, 4000, 4002)


def test_both_solvers_obey_the_one_limit(monkeypatch):
    """With the limit lowered, both solvers refuse what exceeds it and solve what does not."""
    monkeypatch.setattr(checks, "MAX_NODES", 1000)
    step, extent = 0.1, 1.5  # 31 x 35 = 1085 nodes in the bounded lattice
    assert bem.lattice.node_count(step, extent) > 1000 >= bem.lattice.node_count(step, 1.3)
    kw = dict(E_star=1.0, step=step, force=1.0)
    with pytest.raises(bem.InputError, match=r"step = 0.1 is not allowed: the candidate region would hold "
                                             r"1.08e\+03 nodes \(limit 1e\+03"):
        bem.solve(bem.gaps.Paraboloid(1.0), extent=extent, **kw)
    assert bem.solve(bem.gaps.Paraboloid(1.0), extent=1.3, **kw).converged
    with pytest.raises(bem.InputError, match=r"would hold 1.02e\+03 nodes \(limit 1e\+03"):
        bem.solve_periodic(np.zeros((32, 32)), step=1.0, E_star=1.0, mean_pressure=1.0)
    x = np.arange(30)
    gap = 0.01 * (1 - np.cos(2 * np.pi * x / 30))[None, :] + np.zeros((30, 1))
    assert bem.solve_periodic(gap, step=1.0, E_star=1.0, mean_pressure=1e-4).converged


def test_the_lattice_of_a_rough_surface_is_checked_before_it_is_made():
    heights = np.zeros((8, 8))
    message, peak = _refused(lambda: to_lattice(heights, (1.0, 1.0), 8192))
    assert message.startswith("n_cols = 8192 is not allowed: the periodic cell")
    n_rows = 2 * round(8192 / np.sqrt(3))  # the even number of rows nearest Ly / (c sqrt(3)/2)
    _states(message, 8192 * n_rows)
    assert peak < SMALL


def test_a_synthetic_grid_over_the_limit_is_refused_before_it_is_made():
    pytest.importorskip("SurfaceTopography.Generation")  # imported here: an import under tracemalloc is slow
    message, peak = _refused(lambda: bem.rough.self_affine((8192, 8192), (1.0, 1.0), hurst=0.8, rms_height=1.0,
                                                           seed=1))
    assert message.startswith("grid = (8192, 8192) is not allowed: the surface grid")
    _states(message, 8192 * 8192)
    assert peak < SMALL
