"""The command line and the scenes check the sizes they set (``--n-cols``, ``--synthetic grid=``,
``[gap] grid``, ``[bem] cell_nodes``) against bem's one node limit before anything is made: exit
code 2, one line naming the option or key as written, its value, the nodes, the limit and the
memory they would need."""

import math
import tracemalloc

import numpy as np
import pytest

from bem import checks
from bem.checks import bytes_per_node, max_nodes

from .conftest import cli

pytest.importorskip("SurfaceTopography.Generation")

#: far less than any array of a refused lattice or grid [bytes]
SMALL = 5e7
SYNTHETIC = "hurst=0.8,rms_height=0.5e-6,size=1e-4,seed=1,grid="


def _refused(*argv):
    """``(stderr, peak bytes allocated)`` of ``contactlab argv``, which must exit 2 with one line."""
    tracemalloc.start()
    try:
        code, out, err = cli(*argv)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert code == 2 and out == "", err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    return err, peak


def _states(err, n_nodes, what):
    """The line gives the nodes, the limit, the memory they need and the memory of the machine."""
    assert f"would hold {n_nodes:.3g} nodes (limit {max_nodes(what):.3g} on this machine)" in err
    per_node = bytes_per_node(what)
    assert f"about {n_nodes * per_node / 1e9:.3g} GB of memory at {per_node} bytes a node" in err
    assert f"the machine has {checks.machine_memory() / 1e9:.3g} GB" in err  # conftest pins it


def _cell_nodes(n_cols):
    """Nodes of the square cell with ``n_cols`` nodes along x: rows the even number nearest ``n_cols 2/sqrt(3)``."""
    return n_cols * 2 * round(n_cols / np.sqrt(3))


def _layer_law(tmp_path, *argv):
    return _refused("layer-law", *argv, "--E-star", 115e9, "--no-figures", "--out", tmp_path / "law")


def test_layer_law_n_cols_over_the_limit(tmp_path):
    err, peak = _layer_law(tmp_path, "--synthetic", SYNTHETIC + "64", "--n-cols", 8192)
    assert err.startswith("contactlab: error: --n-cols = 8192 is not allowed: the periodic cell")
    _states(err, _cell_nodes(8192), "the periodic cell")
    assert peak < SMALL and not (tmp_path / "law").exists()


def test_layer_law_synthetic_grid_over_the_limit(tmp_path):
    err, peak = _layer_law(tmp_path, "--synthetic", SYNTHETIC + "8192")
    assert err.startswith("contactlab: error: --synthetic grid = 8192 is not allowed: the surface grid")
    _states(err, 8192 * 8192, "the surface grid")
    # within the limit as a grid, beyond it as the default cell (n_cols = grid nodes along x)
    grid = math.isqrt(max_nodes("the surface grid"))
    assert _cell_nodes(grid) > max_nodes("the periodic cell")
    err, peak_cell = _layer_law(tmp_path, "--synthetic", SYNTHETIC + str(grid))
    assert err.startswith(f"contactlab: error: --synthetic grid = {grid} is not allowed: the periodic cell")
    _states(err, _cell_nodes(grid), "the periodic cell")
    assert max(peak, peak_cell) < SMALL


def test_layer_law_of_a_file_checks_n_cols_before_the_cell_is_made(tmp_path):
    np.save(tmp_path / "heights.npy", np.random.default_rng(1).normal(size=(16, 16)))
    err, peak = _layer_law(tmp_path, tmp_path / "heights.npy", "--size", "1,1", "--scale", 1e-6, "--n-cols", 8192)
    assert err.startswith("contactlab: error: --n-cols = 8192 is not allowed: the periodic cell")
    _states(err, _cell_nodes(8192), "the periodic cell")
    assert peak < SMALL


def test_a_scene_grid_over_the_limit(tmp_path):
    err, peak = _refused("check", "rough_flat", "--set", "gap.grid=8192")
    assert "gap.grid = 8192 is not allowed: the surface grid" in err
    _states(err, 8192 * 8192, "the surface grid")
    assert peak < SMALL


def test_a_scene_cell_over_the_limit_is_refused_before_it_is_made(tmp_path):
    err, peak = _refused("run", "rough_flat", "--set", "gap.grid=64", "--set", "bem.cell_nodes=8192",
                         "--out", tmp_path / "r")
    assert "bem.cell_nodes = 8192 is not allowed: the periodic cell" in err
    _states(err, _cell_nodes(8192), "the periodic cell")
    assert peak < SMALL and not (tmp_path / "r").exists()
