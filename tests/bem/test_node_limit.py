"""One memory guard for both solvers: the candidate region of ``bem.solve`` and the periodic cell of
``bem.solve_periodic`` (and the lattice and grid of a rough surface) hold at most the nodes whose
memory (``bem.checks.BYTES_PER_NODE`` each) fits in the machine's (``bem.checks.machine_memory``,
pinned by the suite's conftest), refused before anything is built by a message that names the
argument, its value, the nodes, the limit, the memory they would need and the memory the machine has."""

import os
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


def _states(message, n_nodes, what):
    """The message gives the nodes, the limit, the memory of ``n_nodes`` nodes and the machine's."""
    per_node = checks.bytes_per_node(what)
    limit = checks.machine_memory() // per_node
    assert f"would hold {n_nodes:.3g} nodes (limit {limit:.3g} on this machine)" in message
    assert f"about {n_nodes * per_node / 1e9:.3g} GB of memory at {per_node} bytes a node" in message
    assert f"the machine has {checks.machine_memory() / 1e9:.3g} GB" in message


def _memory(monkeypatch, nodes, what):
    """Let the machine have the memory of exactly ``nodes`` nodes of ``what``."""
    monkeypatch.setattr(checks, "machine_memory", lambda: nodes * checks.bytes_per_node(what))


def test_the_limit_is_the_memory_of_the_machine_over_the_bytes_per_node(monkeypatch):
    assert checks.machine_memory() == 16_000_000 * checks.BYTES_PER_NODE["candidate region"]  # conftest
    for key, per_node in checks.BYTES_PER_NODE.items():
        assert checks.max_nodes(f"the {key}") == checks.machine_memory() // per_node
    assert checks.bytes_per_node("the mirrored periodic cell") == checks.BYTES_PER_NODE["periodic cell"]
    _memory(monkeypatch, 2_000_000, "the candidate region")  # twice the memory, twice the nodes
    assert checks.max_nodes() == 2_000_000
    assert checks.check_node_count("step", 0.1, 2_000_000) == 2_000_000
    message, _ = _refused(lambda: checks.check_node_count("step", 0.1, 2_000_001))
    assert message.startswith("step = 0.1 is not allowed: the candidate region would hold 2e+06 nodes")
    _states(message, 2_000_001, "the candidate region")
    assert message.endswith("Make the lattice coarser or the candidate region smaller.")


def test_the_memory_read_is_the_machine_s_at_most(monkeypatch):
    monkeypatch.undo()  # the machine's own reading, not the suite's pinned one
    memory = checks.machine_memory()
    assert 0 < memory <= os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")


def test_a_periodic_gap_array_over_the_limit_is_refused_before_the_solve():
    gap = np.broadcast_to(0.0, (6000, 4000))  # 2.4e7 nodes that occupy no memory
    message, peak = _refused(lambda: bem.solve_periodic(gap, step=1.0, E_star=1.0, mean_pressure=1.0))
    assert message.startswith("gap = '<array of shape (6000, 4000)>' is not allowed: the periodic cell")
    _states(message, 6000 * 4000, "the periodic cell")
    assert peak < SMALL


def test_a_periodic_cell_over_the_limit_is_refused_when_it_is_made(monkeypatch):
    message, peak = _refused(lambda: PeriodicCell(1e-6, 20000, 20000))
    assert message.startswith("(n_cols, n_rows) = (20000, 20000) is not allowed")
    _states(message, 20000 * 20000, "the periodic cell")
    message, peak_size = _refused(lambda: PeriodicCell.from_size(1e-9, 1.0))
    assert message.startswith("step = 1e-09 is not allowed")
    assert max(peak, peak_size) < SMALL
    _memory(monkeypatch, 4000 * 4000, "the periodic cell")
    assert PeriodicCell(1.0, 4000, 4000).n_nodes == checks.max_nodes("the periodic cell")  # the limit is allowed
    with pytest.raises(bem.InputError, match="would hold 1.6e"):
        PeriodicCell(1.0, 4000, 4002)


def test_both_solvers_obey_the_one_limit(monkeypatch):
    """With the memory lowered, both solvers refuse what exceeds it and solve what does not."""
    _memory(monkeypatch, 1000, "the candidate region")
    step, extent = 0.1, 1.5  # 31 x 35 = 1085 nodes in the bounded lattice
    assert bem.lattice.node_count(step, extent) > 1000 >= bem.lattice.node_count(step, 1.3)
    kw = dict(E_star=1.0, step=step, force=1.0)
    with pytest.raises(bem.InputError, match=r"step = 0.1 is not allowed: the candidate region would hold "
                                             r"1.08e\+03 nodes \(limit 1e\+03"):
        bem.solve(bem.gaps.Paraboloid(1.0), extent=extent, **kw)
    assert bem.solve(bem.gaps.Paraboloid(1.0), extent=1.3, **kw).converged
    _memory(monkeypatch, 1000, "the periodic cell")
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
    _states(message, 8192 * n_rows, "the periodic cell")
    assert peak < SMALL


def test_a_synthetic_grid_over_the_limit_is_refused_before_it_is_made():
    pytest.importorskip("SurfaceTopography.Generation")  # imported here: an import under tracemalloc is slow
    message, peak = _refused(lambda: bem.rough.self_affine((8192, 8192), (1.0, 1.0), hurst=0.8, rms_height=1.0,
                                                           seed=1))
    assert message.startswith("grid = (8192, 8192) is not allowed: the surface grid")
    _states(message, 8192 * 8192, "the surface grid")
    assert peak < SMALL
