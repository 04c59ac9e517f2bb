"""Newton's method on the condensed problem, against direct solutions of small systems."""

import numpy as np
import pytest

from bem.layers import Linear, Root
from fem_reference.interface import InterfaceLaw
from fem_reference.newton import solve_interface


@pytest.fixture
def system():
    rng = np.random.default_rng(7)
    n = 30
    r = np.linspace(0.0, 1.0, n)
    M = rng.normal(size=(n, n))
    C = 0.02 * (M @ M.T) / n + 0.05 * np.eye(n)  # SPD compliance
    A = 0.01 + 0.02 * rng.random(n)
    h = 0.5 * r**2
    return C, A, h


def test_linear_layer_matches_direct_solution(system):
    """Linear law and known active set: (I + C A / lam) g = delta - h is one linear solve."""
    C, A, h = system
    lam, delta = 0.3, 0.2
    law = InterfaceLaw(Linear(lam), 1e8)
    C0, A0, h0 = C.copy(), A.copy(), h.copy()
    sol = solve_interface(C, A, h, law, approach=delta, rtol=1e-12)
    assert sol.converged and sol.status == "converged"
    np.testing.assert_array_equal(C, C0)
    np.testing.assert_array_equal(A, A0)
    np.testing.assert_array_equal(h, h0)
    act = sol.g > 0
    assert 3 < act.sum() < h.size - 3
    # direct solve on the active set (inactive nodes carry no force)
    Ca = C[np.ix_(act, act)]
    g_act = np.linalg.solve(np.eye(act.sum()) + Ca * (A[act] / lam)[None, :], delta - h[act])
    np.testing.assert_allclose(sol.g[act], g_act, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(sol.p[act], g_act / lam, rtol=1e-10)
    # complementarity: open nodes really are open
    d = C @ (A * sol.p)
    assert np.all((delta - h - d)[~act] <= 1e-12)


def test_force_and_approach_control_agree(system):
    C, A, h = system
    law = InterfaceLaw(Root(0.5), 1e8)
    by_delta = solve_interface(C, A, h, law, approach=0.25, rtol=1e-12)
    P = float(np.sum(A * by_delta.p))
    by_force = solve_interface(C, A, h, law, force=P, delta0=0.1, rtol=1e-12)
    assert by_delta.converged and by_force.converged
    assert by_force.delta == pytest.approx(0.25, rel=1e-9)
    np.testing.assert_allclose(by_force.p, by_delta.p, rtol=1e-8, atol=1e-10 * by_delta.p.max())


def test_not_converged_is_reported_with_a_finite_state(system):
    C, A, h = system
    sol = solve_interface(C, A, h, InterfaceLaw(Root(0.5), 1e8), force=0.05, delta0=0.9, maxiter=1,
                          rtol=1e-14)
    assert not sol.converged and sol.status == "maxiter"
    assert np.all(np.isfinite(sol.p)) and np.isfinite(sol.delta)
    assert len(sol.history["residual"]) == 2


def test_indefinite_compliance_is_reported(system):
    C, A, h = system
    bad = C - 10.0 * np.eye(h.size)
    sol = solve_interface(bad, A, h, InterfaceLaw(Linear(0.3), 1e8), approach=0.2)
    assert not sol.converged and sol.status == "singular"
    assert np.all(np.isfinite(sol.p))
