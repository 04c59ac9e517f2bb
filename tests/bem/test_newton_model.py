"""The compliance of Newton's model (bem.newton_model.tangent) against its definition written out here, in double and
in single precision, with the contact given by the caller or found."""

import numpy as np
import pytest

from bem.backend import backend_of
from bem.newton_model import tangent

LAM = 0.3
FLOAT32_MAX = float(np.finfo(np.float32).max)


class _Law:
    """``w = LAM sqrt(p)``, with ``w'`` infinite above ``p = 2`` (where the model takes a secant instead)."""

    def w(self, p):
        return LAM * np.sqrt(np.maximum(p, 0.0))

    def dw(self, p):
        with np.errstate(divide="ignore"):
            return np.where(p > 2.0, np.inf, 0.5 * LAM / np.sqrt(np.maximum(p, 0.0)))

    def inverse(self, c):
        return (np.maximum(c, 0.0) / LAM) ** 2


def _secant(gap, p_ref):
    """``w(r) / r`` at ``r = w^-1(-g)`` (``p_ref`` where ``r`` is not positive and finite, at most ``1e6 p_ref``)."""
    r = (np.maximum(-gap, 0.0) / LAM) ** 2
    r = np.where((r > 0) & np.isfinite(r), np.minimum(r, 1e6 * p_ref), p_ref)
    return LAM * np.sqrt(r) / r


def _case(seed, n=4000):
    rng = np.random.default_rng(seed)
    p = np.maximum(rng.standard_normal(n), 0.0) * 2.0  # some above 2: w' infinite there
    gap = rng.standard_normal(n) * 0.1  # open and shut nodes among those without pressure
    return p, gap


def _by_definition(p, gap, p_ref):
    D = np.full(p.shape, _secant(np.zeros(1), p_ref)[0])
    on, shut = p > 0, (p <= 0) & ~(gap >= 0)
    with np.errstate(divide="ignore"):
        d = 0.5 * LAM / np.sqrt(p[on])
    d = np.where(p[on] > 2.0, _secant(gap[on], p_ref), d)
    D[on], D[shut] = d, _secant(gap[shut], p_ref)
    return D


@pytest.mark.parametrize("seed", [0, 1])
def test_the_tangent_is_its_definition_in_double_and_single_precision(seed):
    p, gap = _case(seed)
    given = p.copy(), gap.copy()
    bk, p_ref = backend_of(p), float(np.mean(p[p > 0]))
    expected = _by_definition(p, gap, p_ref)
    assert (p > 2).any() and ((p <= 0) & (gap < 0)).any() and ((p <= 0) & (gap >= 0)).any()
    double = tangent(bk, _Law(), p, gap, p_ref)
    assert double.dtype == np.float64 and np.array_equal(double, expected)
    single = tangent(bk, _Law(), p, gap, p_ref, single_below=FLOAT32_MAX)
    assert single.dtype == np.float32 and single.tobytes() == expected.astype(np.float32).tobytes()
    nodes = np.flatnonzero(p > 0)
    found = tangent(bk, _Law(), p, gap, p_ref, single_below=FLOAT32_MAX, positive=p > 0, on=(nodes, p[nodes]))
    assert found.tobytes() == single.tobytes()
    assert np.array_equal(p, given[0]) and np.array_equal(gap, given[1])


def test_an_entry_at_the_bound_keeps_double_precision():
    p, gap = _case(2)
    bk, p_ref = backend_of(p), float(np.mean(p[p > 0]))
    expected = _by_definition(p, gap, p_ref)
    bound = float(np.max(expected))  # the largest entry is not below it
    kept = tangent(bk, _Law(), p, gap, p_ref, single_below=bound)
    assert kept.dtype == np.float64 and np.array_equal(kept, expected)
    assert tangent(bk, _Law(), p, gap, p_ref, single_below=np.nextafter(bound, np.inf)).dtype == np.float32
    for part in (p > 2, (p <= 0) & (gap < 0), (p <= 0) & (gap >= 0)):  # the largest entry in each part in turn
        top = float(np.max(expected[part]))
        assert tangent(bk, _Law(), p, gap, p_ref, single_below=top).dtype == np.float64


def test_the_open_nodes_value_counts_where_it_is_the_largest():
    """With a small ``p_ref`` the secant at the open nodes is the largest entry: at that bound, double precision; and
    with no open node it is not an entry."""
    p, gap = _case(3)
    p = np.where(p > 0, p + 0.5, 0.0)  # w', and below, the secants at shut nodes and where w' is infinite moderate
    gap = np.where(p > 2, -1.0, np.where(gap < 0, gap - 0.01, gap))
    bk, p_ref = backend_of(p), 1e-4
    expected = _by_definition(p, gap, p_ref)
    fill = _secant(np.zeros(1), p_ref)[0]
    assert fill == np.max(expected)
    assert tangent(bk, _Law(), p, gap, p_ref, single_below=fill).dtype == np.float64
    shut = np.where((p <= 0) & (gap >= 0), -1.0, gap)  # every node without pressure shut
    assert tangent(bk, _Law(), p, shut, p_ref, single_below=fill).dtype == np.float32
