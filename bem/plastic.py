"""The hardness bound of Kalker's QP: an elastic-perfectly-plastic surface, ``0 <= p <= H``.

With a hardness ``H`` [pressure] the nodal pressure is bounded at every node. The bounded QP
``min 1/2 p.(C + lam) p + p.(h - delta)`` over ``0 <= p <= H`` (and ``a sum p = P`` under force
control) has the KKT conditions, with ``g = C p + w(p) + h - delta`` the deformed gap,

* ``g >= 0`` where ``p = 0`` (open),
* ``g = 0`` where ``0 < p < H`` (elastic contact),
* ``g <= 0`` where ``p = H`` (plastic: the surface yields, and the overlap ``-g`` is the plastic
  deformation).

The nodes at ``p = H`` are the plastic set; the constrained conjugate gradients move the elastic
contact nodes only and project their step onto ``[0, H]`` (:mod:`bem.cg_rules`). Under force
control the approach is the multiplier of the elastic contact, the mean of ``C p + w(p) + h``
over it; where every contact node is plastic (a fully plastic contact, ``A = P / H``) it is
undetermined in the interval of :func:`plastic_approach`, and its lower end is returned.
The rules here are shared by every step of the constrained CG, Newton's method and the KKT
residual (:mod:`bem.kkt`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["plastic_approach", "fill_force", "plastic_start", "carry_force", "clip", "clipped_start", "in_place",
           "leaving_pressure", "note_fully_plastic", "fully_plastic_note"]

#: Rounds of :func:`fill_force` (each caps at least one more node at ``H``).
_FILL_ROUNDS = 64


def clip(xp, p, hardness):
    """``p`` clipped at 0 and, with a hardness, at ``H`` (``hardness`` None: at 0 only)."""
    p = xp.maximum(p, 0.0)
    return p if hardness is None else xp.minimum(p, hardness)


def in_place(bk, x):
    """Whether a solver on the backend ``bk`` can hold its iterate in ``x``: NumPy, and ``x`` a writeable,
    C-contiguous float64 NumPy array."""
    return (bk.is_numpy and isinstance(x, np.ndarray) and x.dtype == np.float64 and x.flags.c_contiguous
            and x.flags.writeable)


def clipped_start(bk, x0, mask, hardness=None, overwrite_x0=False):
    """A start ``x0`` clipped at 0 (and at ``hardness``), 0 off ``mask``: ``x0`` itself, clipped in place, where
    ``overwrite_x0`` and :func:`in_place` allow it; else a new array (``x0`` not modified)."""
    if not (overwrite_x0 and in_place(bk, x0)):
        return bk.xp.where(mask, clip(bk.xp, bk.asarray(x0), hardness), 0.0)
    p = np.maximum(x0, 0.0, out=x0)
    if hardness is not None:
        np.minimum(p, hardness, out=p)
    p[~mask] = 0.0
    return p


def plastic_approach(lowest_open, highest_plastic):
    """The approach of a contact without elastic nodes, and the interval that allows it.

    With every contact node plastic the conditions ``g <= 0`` there and ``g >= 0`` at the open
    nodes hold for every approach ``delta`` in ``[lo, hi]``, ``lo = max_plastic (C p + w + h)``,
    ``hi = min_open (C p + w + h)``; the pressure does not depend on it. Returns
    ``(delta, (lo, hi))`` with ``delta = lo`` (the smallest approach that closes every plastic
    node), or the midpoint where ``lo > hi`` (an iterate that is not yet a solution: the midpoint
    makes the largest violation smallest). ``hi`` is ``inf`` where no node is open.
    """
    lo, hi = float(highest_plastic), float(lowest_open)
    return (lo if lo <= hi else 0.5 * (lo + hi)), (lo, hi)


def fill_force(xp, p, target, hardness):
    """``p`` (values in ``[0, H]``) with the nodes below ``H`` scaled to carry ``sum p = target``.

    One factor ``s >= 0`` scales every node below ``H``; nodes that it would lift above ``H`` are
    capped there and the factor of the others found again (a water filling, at most one round
    per capped node). Where the nodes at ``H`` alone carry more than ``target`` (a step that
    clipped many nodes at 0 and others at ``H``), every node is scaled down by one factor instead,
    and the plastic ones leave ``H``. Returns ``(p, s, capped)``: the scaled pressure, the factor
    of the nodes that stayed below ``H`` and whether a node was capped or left ``H``; ``None``
    where the nodes below ``H`` cannot carry the rest of ``target`` (they carry nothing while it is
    positive, or all of them reach ``H``).
    """
    fixed = p >= hardness  # the nodes at H (the values are at most H)
    n_fixed, total, capped = int(xp.count_nonzero(fixed)), float(xp.sum(p)), False
    for _ in range(_FILL_ROUNDS):
        need = target - hardness * n_fixed
        if need < -1e-13 * target:  # too many nodes at H: all of them scaled down
            return p * (target / total), 1.0, True
        rest = total - hardness * n_fixed
        if not rest > 1e-10 * total:  # little or nothing below H: its sum without cancellation
            rest = float(xp.sum(xp.where(fixed, 0.0, p)))
            if not rest > 0:
                return (p, 1.0, capped) if abs(need) <= 1e-13 * target else None
        s = max(need / rest, 0.0)
        if s <= 1.0:  # no node rises to H
            return xp.where(fixed, p, p * s), s, capped
        q = xp.minimum(p * s, hardness)
        top = q >= hardness
        n_top = int(xp.count_nonzero(top))
        if n_top == n_fixed:
            return q, s, capped
        capped, fixed, n_fixed = True, top, n_top
        p = xp.where(top, hardness, p)
        total = float(xp.sum(p))
    return xp.where(fixed, p, xp.minimum(p * s, hardness)), s, capped


def note_fully_plastic(record, bracket, fully_plastic):
    """Say in a converged constrained CG's ``record`` (:class:`bem.cg_rules.Record`) that its contact is fully
    plastic and the approach ``bracket[0]`` one of the interval ``bracket`` (:func:`plastic_approach`)."""
    if fully_plastic and bracket is not None and record.converged:
        record.message += fully_plastic_note(bracket)
        record.history["approach_bracket"] = list(bracket)


def fully_plastic_note(bracket):
    """The words a converged solve adds to its message where every contact node is plastic."""
    return (f"; fully plastic: every contact node at the hardness, the approach is any value in "
            f"[{bracket[0]:.6g}, {bracket[1]:.6g}], the lower end returned")


def leaving_pressure(xp, hardness, lowered):
    """Pressure of a plastic node whose gap opens (``p = H``, ``g > 0``): ``H`` lowered by the pressure
    an entering node would take at ``-g`` (:func:`bem.cg_rules.entering_pressure`), not below 0."""
    return xp.maximum(hardness - lowered, 0.0)


def plastic_start(xp, h, target, hardness, mask):
    """``H`` on the nodes of ``mask`` in the order of their gap ``h``, smallest first, until they carry
    ``target = P / a`` (the rest of it shared by the nodes at the next gap value): the rigid-plastic
    pressure (brick array); ``None`` where the nodes of ``mask`` cannot carry ``target`` below ``H``."""
    hm = xp.where(mask, h, xp.inf)
    values = xp.sort(xp.reshape(hm, (-1,)))
    k = int(target // hardness)
    if k >= int(xp.count_nonzero(mask)):
        return None
    level = float(values[k])
    full = hm < level
    tie = hm == level
    rest = target - hardness * int(xp.count_nonzero(full))
    share = xp.astype(tie, h.dtype) * (rest / int(xp.count_nonzero(tie)))
    return xp.minimum(xp.where(full, hardness, share), hardness)


def carry_force(xp, p, target, hardness, mask, h=None):
    """``p`` (``>= 0``) scaled to carry ``sum p = target``, capped at ``H`` and filled up by
    :func:`bem.plastic.fill_force`; where its support cannot carry ``target``, ``p`` joined (the larger value
    at each node) by the rigid-plastic pressure of the gap ``h`` (:func:`plastic_start`) and scaled down to
    ``target``, or without ``h`` the uniform ``target / n`` on the ``n`` nodes of ``mask`` (capped at ``H``:
    the caller checks that they can). Values within round-off (a relative ``1e-12``) of ``H`` are set to
    ``H``: a start that the force fills to the bound is plastic there."""
    starts = [p]
    if h is not None and (rigid := plastic_start(xp, h, target, hardness, mask)) is not None:
        starts.append(xp.maximum(xp.minimum(p * (target / max(float(xp.sum(p)), 1e-300)), hardness), rigid))
    for start in (*starts, xp.astype(mask, p.dtype)):
        total = float(xp.sum(start))
        if total > 0:
            filled = fill_force(xp, xp.minimum(start * (target / total), hardness), target, hardness)
            if filled is not None:
                return _snap(xp, filled[0], hardness)
    return _snap(xp, xp.minimum(xp.astype(mask, p.dtype) * (target / float(xp.sum(xp.astype(mask, p.dtype)))),
                                hardness), hardness)


def _snap(xp, p, hardness):
    """``p`` with the values within a relative ``1e-12`` of ``H`` set to ``H``."""
    return xp.where(p >= hardness * (1.0 - 1e-12), hardness, p)
