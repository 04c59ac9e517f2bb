"""Linear Winkler layer (eq. 13: C + lam I) against an independent dense solve."""

import numpy as np
import pytest
from scipy.optimize import nnls

import bem
from bem.gaps import Paraboloid
from bem.layers import Linear

R, E_STAR = 1.0, 1.0


def _dense_reference(res, lam, approach):
    """Solve min 1/2 p.(C + lam I) p + p.(h - delta), p >= 0 by Lawson-Hanson NNLS.

    With A = L L^T (Cholesky) the QP is min |L^T p + L^-1 (h - delta)|^2 over p >= 0.
    """
    op = bem.InfluenceOperator(res.lattice, E_STAR)
    A = op.dense() + lam * np.eye(res.p.size)
    b = Paraboloid(R)(res.x, res.y) - approach
    L = np.linalg.cholesky(A)
    p, _ = nnls(L.T, -np.linalg.solve(L, b), maxiter=50 * res.p.size)
    return p


@pytest.mark.parametrize("lam_factor", [0.1, 10.0])
def test_winkler_layer_matches_dense_nnls(lam_factor):
    step = 0.05
    lam = lam_factor * bem.diagonal_coefficient(step, E_STAR)
    res = bem.solve(Paraboloid(R), E_star=E_STAR, force=0.02, step=step, extent=0.6, layer=Linear(lam),
                    method="kalker", rtol=1e-12)
    assert res.converged and res.p.size < 700
    ref = _dense_reference(res, lam, res.approach)
    assert np.abs(res.p - ref).max() <= 1e-8 * ref.max()
    assert res.lattice.node_area * ref.sum() == pytest.approx(0.02, rel=1e-8)


def test_layer_lowers_peak_and_widens_contact():
    kw = dict(E_star=E_STAR, force=0.02, step=0.03, extent=0.6)
    smooth = bem.solve(Paraboloid(R), **kw)
    soft = bem.solve(Paraboloid(R), layer=Linear(0.2), **kw)
    assert soft.p_max < smooth.p_max
    assert soft.contact_area > smooth.contact_area
    np.testing.assert_allclose(soft.closure, 0.2 * soft.p)
    assert np.abs(soft.gap[soft.p > 0]).max() < 1e-9 * np.abs(soft.displacement + soft.closure).max()
