"""The parts of the periodic cell's constrained CG (bem.periodic.qp_parts) against plain references."""

import numpy as np
import pytest

from bem.backend import get_backend
from bem.periodic.qp_parts import LastPreconditionedGap, weighted_square


def test_last_preconditioned_gap_reads_the_kept_values_at_new_nodes():
    """``at`` gives the last kept ``z`` at nodes of the last selection (to single precision) and 0 elsewhere,
    whatever selections came before; ``keep`` copies."""
    shape = (12, 10)
    bk = get_backend("cpu")
    rng = np.random.default_rng(3)
    last = LastPreconditionedGap(bk, shape)
    assert np.array_equal(last.at(np.array([0, 5, 7])), np.zeros(3))
    for _ in range(4):
        nodes = np.flatnonzero(rng.random(shape) < 0.4)
        z = rng.standard_normal(nodes.size)
        kept = z.copy()
        last.keep(nodes, z)
        z[:] = 0.0  # the caller's array is not held
        new = np.flatnonzero(rng.random(shape) < 0.4)
        expected = np.zeros(new.size)
        where = np.isin(new, nodes)
        expected[where] = kept[np.searchsorted(nodes, new[where])]
        got = last.at(new)
        assert got.dtype == np.float64
        np.testing.assert_allclose(got, expected, rtol=1e-7, atol=0)
        assert np.all(got[~where] == 0)


def test_weighted_square_is_the_sum():
    d, t = np.array([1.0, 2.0, 0.5]), np.array([3.0, -1.0, 4.0])
    assert weighted_square(get_backend("cpu"), d, t) == pytest.approx(9.0 + 2.0 + 8.0, rel=1e-15)
