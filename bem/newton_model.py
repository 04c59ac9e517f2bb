"""The per-node compliance ``D`` of the quadratic model of a Newton step (:mod:`bem.newton`).

``D = w'(p)`` where it is finite; where it is not (root and power laws with ``s < 1`` at
``p = 0``) or at a node without pressure, the secant of ``w`` up to the pressure the layer alone
would carry there; raised to the majorant of ``W`` where the model underestimates it on a move.
"""

from __future__ import annotations

from .backend import operator_backend

__all__ = ["tangent", "secant", "majorant"]


def tangent(bk, layer, p, gap, p_ref, *, single_below=None, positive=None, on=None):
    """Per-node model compliance ``D``: ``w'(p)`` where finite, else a secant (each on its nodes only).

    ``single_below``: ``D`` in single precision where every entry is below it (NaN is not), made so at once (no
    double-precision array of the lattice); double precision otherwise and by default. ``positive``: ``p > 0``, and
    ``on``: its node selection and ``p`` there, where the caller has them."""
    xp = bk.xp
    pos = p > 0 if positive is None else positive
    contact = bk.select(pos) if on is None else on[0]
    shut = bk.select(~pos & ~(gap >= 0))  # no pressure, a closed gap (or NaN)
    with bk.errstate(divide="ignore", invalid="ignore", over="ignore"):
        fill = float(secant(bk, layer, xp.zeros(1, dtype=p.dtype), p_ref)[0])  # an open gap: the secant at closure 0
        d = bk.asarray(layer.dw(bk.take(p, contact) if on is None else on[1]))
        finite = xp.isfinite(d)
        on_shut = secant(bk, layer, bk.take(gap, shut), p_ref)
        bad = None if bool(xp.all(finite)) else bk.subset(contact, ~finite)
        on_bad = None if bad is None else secant(bk, layer, bk.take(gap, bad), p_ref)
    single = False
    if single_below is not None:  # the largest entry of D: over the parts it is made of
        parts = [d if bad is None else xp.where(finite, d, 0.0), on_shut] + ([] if bad is None else [on_bad])
        largest = [bk.max0(x) for x in parts] + ([fill] if p.size > bk.count(contact) + bk.count(shut) else [])
        single = all(x < single_below for x in largest)
    out = xp.full(p.shape, fill, dtype=xp.float32 if single else p.dtype)
    for sel, values in [(contact, d), (shut, on_shut)] + ([] if bad is None else [(bad, on_bad)]):
        bk.put(out, sel, values if bk.is_numpy else xp.astype(values, out.dtype))  # (NumPy rounds in the put)
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
