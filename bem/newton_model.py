"""The per-node compliance ``D`` of the quadratic model of a Newton step (:mod:`bem.newton`).

``D = w'(p)`` where it is finite; where it is not (root and power laws with ``s < 1`` at
``p = 0``) or at a node without pressure, the secant of ``w`` up to the pressure the layer alone
would carry there; raised to the majorant of ``W`` where the model underestimates it on a move.
"""

from __future__ import annotations

from .backend import operator_backend

__all__ = ["tangent", "secant", "majorant"]


def tangent(bk, layer, p, gap, p_ref):
    """Per-node model compliance ``D``: ``w'(p)`` where finite, else a secant (each on its nodes only)."""
    xp = bk.xp
    pos = p > 0
    contact, shut = bk.select(pos), bk.select(~pos & ~(gap >= 0))  # shut: no pressure, a closed gap (or NaN)
    with bk.errstate(divide="ignore", invalid="ignore", over="ignore"):
        # an open gap: the secant at the closure 0, one value
        out = xp.full_like(p, float(secant(bk, layer, xp.zeros(1, dtype=p.dtype), p_ref)[0]))
        d = bk.asarray(layer.dw(bk.take(p, contact)))
        finite = xp.isfinite(d)
        bk.put(out, contact, d)
        bk.put(out, shut, secant(bk, layer, bk.take(gap, shut), p_ref))
        if not bool(xp.all(finite)):
            bad = bk.subset(contact, ~finite)
            bk.put(out, bad, secant(bk, layer, bk.take(gap, bad), p_ref))
    return out


def secant(bk, layer, gap, p_ref):
    """``w(r) / r`` at ``r = w^-1(-g)``, the pressure at which the layer alone closes the gap ``g``.

    ``p_ref`` [pressure] stands for ``r`` where there is none.
    """
    xp = bk.xp
    reach = bk.asarray(layer.inverse(xp.maximum(-gap, 0.0)))
    reach = xp.where((reach > 0) & xp.isfinite(reach), xp.minimum(reach, 1e6 * p_ref), p_ref)
    return bk.asarray(layer.w(reach)) / reach


def majorant(op, layer, p, q, D, mask):
    """``D`` raised where the quadratic model underestimates ``W`` on the move ``p -> q``.

    The curvature that makes the model exact at ``q``,
    ``D_maj = 2 [W(q) - W(p) - w(p) (q - p)] / (q - p)^2``, replaces ``D`` where it is
    larger. For a concave law (``s < 1``) the tangent at ``p`` is too soft for a pressure
    that falls towards 0, and a secant is too soft for a node entering the contact: the
    model then drives such nodes to or from almost zero, where ``w'`` is huge, and the
    step finds no descent. The raised ``D`` majorises ``W`` on the move.
    """
    # a move much smaller than the pressure itself loses the curvature to cancellation in
    # W(q) - W(p) - w(p)(q - p); the tangent is exact to O(step^3) there and is kept
    bk, _ = operator_backend(op)
    xp = bk.xp
    moves = mask & (xp.abs(q - p) > 1e-6 * xp.maximum(xp.abs(p), xp.abs(q)))
    qq, pp = xp.maximum(q[moves], 0.0), p[moves]
    step = qq - pp
    with bk.errstate(divide="ignore", invalid="ignore", over="ignore"):
        d_maj = 2.0 * (layer.energy(qq) - layer.energy(pp) - layer.w(pp) * step) / (step * step)
    out = bk.copy(D)
    raise_ = xp.isfinite(d_maj) & (d_maj > D[moves])
    return bk.put(out, bk.subset(bk.select(moves), raise_), d_maj[raise_])
