"""The gap of the cell's QP without an array of it (:mod:`bem.periodic.passes`: ``scan``, ``gap_at``): the NumPy
forms, made a part of ``CHUNK`` nodes at a time, give the numbers of the whole-array formulas on ``g = u + h`` bit for
bit, on NumPy and on another array namespace, and leave their inputs as they were; the QP makes an array of the gap
only with a hardness, and its entering test from the mask of ``scan`` is the test on the step's pressure."""

import numpy as np
import pytest

import bem.periodic.passes as passes
from bem.backend import get_backend
from bem.periodic.qp import solve_periodic_qp

from .fourier_qp_cases import cell_qp

SIZES = [1000, passes.CHUNK, 2 * passes.CHUNK + 77]  # one part, exactly one, and parts with a short last one


def _arrays(n, single, seed=3):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n).astype(np.float32 if single else np.float64)
    h = rng.standard_normal(n) * 1e-3
    p = np.where(rng.random(n) < 0.6, 0.0, rng.random(n))
    u[n - 1], h[0] = 10.0, -20.0  # the largest u in the last part, the smallest gap in the first
    return u, h, p


@pytest.mark.parametrize("n", SIZES)
@pytest.mark.parametrize("single", [False, True])
def test_the_numpy_forms_are_the_formulas_on_the_gap_array(n, single):
    k = passes.numpy_kernels()
    u, h, p = _arrays(n, single)
    keep = [x.copy() for x in (u, h, p)]
    g = u + h  # float64, as the gap array of the bounded QP
    out = np.empty(n, dtype=bool)
    assert k.scan(u, h, -0.4, p, out) == (out, float(g.min()), float(u.max()), float(u.min()))
    np.testing.assert_array_equal(out, (g < -0.4) & (p == 0))
    assert out.any() and not out.all()
    idx = np.flatnonzero(p > 0)
    at = k.gap_at(u, h, idx)
    assert at.dtype == np.float64 and np.array_equal(at, g[idx])
    assert k.gap_at(u, h, idx[:0]).shape == (0,)
    for x, y in zip((u, h, p), keep):
        np.testing.assert_array_equal(x, y)
    shape = (1, n)  # brick arrays: the same numbers
    brick = np.empty(shape, dtype=bool)
    assert k.scan(u.reshape(shape), h.reshape(shape), -0.4, p.reshape(shape), brick)[1:] == (
        k.scan(u, h, -0.4, p, out)[1:])
    np.testing.assert_array_equal(brick.reshape(-1), out)



def test_the_entering_mask_is_written_into_a_strided_brick():
    """A 2-D view with no flat view of it (``reshape(-1)`` would copy): the mask is written into it all the same."""
    u, h, p = (x.reshape(300, 250) for x in _arrays(300 * 250, False))
    out = np.zeros((300, 500), dtype=bool)[:, 250:]
    wide = [np.zeros((300, 500)) for _ in range(3)]
    for w, x in zip(wide, (u, h, p)):
        w[:, :250] = x
    got = passes.numpy_kernels().scan(*(w[:, :250] for w in wide[:2]), -0.4, wide[2][:, :250], out)
    assert got[0] is out and out.any() and got[1] == float((u + h).min())
    np.testing.assert_array_equal(out, (u + h < -0.4) & (p == 0))


@pytest.mark.parametrize("where", ["u", "h"])
def test_a_nan_in_the_gap_propagates_as_in_numpy(where):
    """A NaN in ``u`` makes every extreme NaN, a NaN in ``h`` only the gap's minimum, in any part."""
    u, h, _ = _arrays(2 * passes.CHUNK + 77, False)
    (u if where == "u" else h)[passes.CHUNK + 5] = np.nan
    _, low, high, lowest = passes.numpy_kernels().scan(u, h, 0.0, u, np.empty(u.size, dtype=bool))
    assert np.isnan(low) and np.isnan(high) == np.isnan(lowest) == (where == "u")


def test_the_namespace_forms_give_the_same_numbers():
    xp = pytest.importorskip("array_api_strict")
    k, ref = passes.kernels(10, get_backend(xp)), passes.numpy_kernels()
    u, h, p = _arrays(2 * passes.CHUNK + 77, False)
    U, H, P = (xp.asarray(x) for x in (u, h, p))
    got, want = k.scan(U, H, -0.4, P, None), ref.scan(u, h, -0.4, p, np.empty(u.size, dtype=bool))
    assert got[1:] == want[1:]
    np.testing.assert_array_equal(np.asarray(got[0]), want[0])
    idx = np.flatnonzero(p > 0)
    np.testing.assert_array_equal(np.asarray(k.gap_at(U, H, xp.asarray(idx))), ref.gap_at(u, h, idx))


@pytest.mark.parametrize("case", ["smooth", "per_node", "hardness"])
def test_the_qp_makes_an_array_of_the_gap_only_with_a_hardness(monkeypatch, case):
    """Without a hardness the QP reads the gap through ``scan`` and ``gap_at`` (no array of the cell's size for it);
    the bounded QP's sets need ``g`` and make it by ``gap``. Either converges."""
    calls = []
    real = passes.numpy_kernels()

    class Counted:
        def __getattr__(self, name):
            calls.append(name)
            return getattr(real, name)

    monkeypatch.setattr("bem.periodic.qp.kernels", lambda n, bk=None: Counted())
    op, h, kw = cell_qp(case)
    res = solve_periodic_qp(op, h, **kw)
    assert res.converged
    if case == "hardness":
        assert "gap" in calls and "scan" not in calls
    else:
        assert "gap" not in calls and {"scan", "gap_at"} <= set(calls)
