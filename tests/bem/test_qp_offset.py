"""A QP's gap given as ``h`` and an ``offset`` at some nodes (:func:`bem.kalker.solve_qp`,
:func:`bem.periodic.qp.solve_periodic_qp`; Newton's model gap ``h + w(p) - D p``): the solve of the gap ``h + offset``
made into an array, on both domains, under force and under approach control, with a compliance per node in single or
double precision; its displacement is ``C p``, and the caller's arrays are left as they were."""

import numpy as np
import pytest

import bem
from bem.periodic import PeriodicOperator

from .newton_cases import CELL, waves


def _case(domain):
    """``(op, h, lam, force)``: a compliance per node of a root law's size, varying over the nodes."""
    if domain == "cell":
        op, h, force = PeriodicOperator(CELL, 1.0), waves(CELL), 0.02
    else:
        region = bem.HalfSpaceRegion(step=0.02, extent=0.3)
        lat = region.lattice()
        op, force = bem.InfluenceOperator(lat, 1.0), 0.01
        h = region.nodal_gap(bem.gaps.Paraboloid(1.0), lat)
    lam = op.diagonal * np.random.default_rng(3).uniform(0.1, 8.0, h.shape)  # soft nodes too (above 4 C_nn)
    return op, h, lam, force


def _offset(op, h, force):
    """Nodes of the contact of a rough solution and values of the size of a layer's closure there."""
    start = op.qp(h, force=force, rtol=1e-3)
    at = np.flatnonzero(start.p)
    values = 0.3 * np.abs(h).max() * np.random.default_rng(4).uniform(0.0, 1.0, at.size)
    return start.p, at, values


@pytest.mark.parametrize("domain, start", [("cell", "u0"), ("cell", "cold"), ("cell", "double"), ("half-space", "u0"),
                                           ("half-space", "cold")])
@pytest.mark.parametrize("control", ["force", "approach"])
@pytest.mark.parametrize("precision", [np.float64, np.float32])
def test_a_qp_with_an_offset_solves_the_gap_with_it_added(monkeypatch, domain, control, precision, start):
    """``double`` (the cell's rule; the half-space QP has no single-precision products): the cell's products in double
    precision from the first iteration, so that its steps that change the contact update ``u`` by the product of their
    move and rescale it to the force by up to 70 %, which must leave the offset as it is
    (:data:`bem.periodic.qp.SINGLE_ABOVE` raised)."""
    if start == "double":
        monkeypatch.setattr("bem.periodic.qp.SINGLE_ABOVE", 1e3)
    op, h, lam, force = _case(domain)
    x0, at, values = _offset(op, h, force)
    lam = lam.astype(precision)
    dense = h.copy()
    dense.reshape(-1)[at] += values
    kw = dict(lam=lam, contact=x0 > 0, rtol=1e-11)
    kw.update(force=force) if control == "force" else kw.update(approach=0.6 * float(np.max(-h)) + 0.004)
    if start == "u0":  # as Newton starts its model: its pressure and that pressure's product
        kw.update(u0=op.matvec(x0), confirm=False)
    keep = [a.copy() for a in (h, lam, at, values)]
    ref = op.qp(dense, x0=x0.copy(), **kw)
    res = op.qp(h, x0=x0.copy(), offset=(at, values), **kw)
    assert ref.converged and res.converged
    # the two gaps round differently (h + offset against the sum's array): a few iterations apart, not a factor
    assert abs(res.iterations - ref.iterations) <= 2 + ref.iterations // 10
    assert np.abs(res.p - ref.p).max() <= 1e-9 * ref.p.max()
    assert res.approach == pytest.approx(ref.approach, rel=1e-9, abs=1e-12)
    # the displacement returned is C p, the offset taken out of the iterate's product
    c_p = op.matvec(res.p)
    assert np.abs(res.displacement - c_p).max() <= 1e-9 * np.abs(c_p).max()
    for a, b in zip((h, lam, at, values), keep):
        np.testing.assert_array_equal(a, b)
