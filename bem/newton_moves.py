"""Moves of a Newton step (:mod:`bem.newton`): along ``d = q - p`` (:func:`line_search`), onto the bounds of the
pressure and to the model's closure, and the change of the functional.

Damped Newton steps approach a bound of ``p`` geometrically and never reach it: a node that the model
releases (``q = 0``) where ``w`` is concave (:func:`release`), and, with a hardness ``H``
(:mod:`bem.plastic`), a node that the model puts at ``H`` while the line search stops short of it
(:func:`settle_plastic`). Where ``w'`` varies fast (a root law at small pressures) the step along
``d = q - p`` is poor for the nodes the layer dominates, and the move to the pressure whose closure is the
model's (:func:`closure_move`) is better. Each move is tried once per step and kept when ``Phi`` of eq. 15
decreases (:func:`energy_change`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .backend import backend_of, operator_backend
from .brent import brent_root
from .newton_passes import gather
from .plastic import fill_force, in_place

__all__ = ["StepNodes", "StepEnd", "step_nodes", "line_search", "energy_change", "scaled", "release", "settle_plastic",
           "model_closure", "closure_move"]


class StepNodes(NamedTuple):
    """The nodes of a Newton step ``p -> p + t (q - p)`` (:func:`step_nodes`) and what the step reads there (1-D)."""

    sel: object  #: every node with pressure before or after the step (the others stay 0; Backend.select)
    p: object  #: the pressure before the step [pressure]
    q: object  #: the model's answer [pressure]
    u: object  #: ``C p`` [length]
    uq: object  #: ``C q`` [length]
    h: object  #: the gap [length]

    def end(self, t):
        """:class:`StepEnd` of the step ``t`` along ``d = q - p`` (the arrays of ``p``, ``q`` and ``C q`` not held)."""
        return StepEnd(self.sel, self.q > 0, (self.uq - self.u) * t + self.u, self.h)


class StepEnd(NamedTuple):
    """What the closure move reads at a step's nodes after the step (:meth:`StepNodes.end`; 1-D)."""

    sel: object  #: the step's nodes
    keep: object  #: where the model keeps a node in contact (``q > 0``; boolean)
    u: object  #: ``C p`` after the step, ``u + t (C q - u)`` [length]
    h: object  #: the gap [length]


def step_nodes(bk, p, q, u, uq, h, mask=None):
    """:class:`StepNodes` of the step from ``p`` to ``q`` (brick arrays; ``u = C p``, ``uq = C q``; on ``mask``)."""
    moving = (p > 0) | (q > 0)
    sel = bk.select(moving if mask is None else mask & moving)
    arrays = (p, q, u, uq, h)
    return StepNodes(sel, *(gather(sel, *arrays) if bk.is_numpy else (bk.take(x, sel) for x in arrays)))


def line_search(bk, layer, at, delta):
    """Exact minimiser of ``Phi(p + t d)``, ``d = q - p``, on ``[0, 1]`` at the step's nodes ``at``
    (:class:`StepNodes`; ``d = 0`` elsewhere): the root of the slope ``d.grad Phi(p + t d) = a + t b + d.w(p + t d)``,
    ``a = d.(u + h - delta)`` and ``b = d.C d`` summed once; 0 where the slope is not negative at 0, 1 where it is
    negative at 1. Under force control ``sum d = 0``: ``delta`` drops out."""
    xp = bk.xp
    ds = at.q - at.p
    a = bk.dot(ds, at.u + at.h - delta)
    b = bk.dot(ds, at.uq - at.u)

    def slope(t):
        return a + t * b + bk.dot(ds, layer.w(xp.maximum(at.p + t * ds, 0.0)))

    s0, s1 = slope(0.0), slope(1.0)
    if s0 >= 0:
        return 0.0
    if s1 <= 0:
        return 1.0
    return brent_root(slope, 0.0, 1.0, s0, s1, xtol=1e-14, rtol=4 * np.finfo(float).eps)


def energy_change(bk, layer, p, delta_p, u, c_dp, h, delta, mask):
    """``(Phi(p + dp) - Phi(p)) / a`` of eq. 15, free of cancellation.

    ``u = C p``, ``c_dp = C dp``. The layer term uses the Taylor expansion where the move
    is tiny against the pressure, so that changes far below the round-off of ``Phi``
    itself are still measured with their sign.
    """
    # the nodes that move or carry pressure: every other node adds exactly 0
    sel = bk.select(mask & ((delta_p != 0) | (p > 0)))
    return _change(bk, layer, *(bk.take(x, sel) for x in (p, delta_p, u, h, c_dp)), delta)


def _change(bk, layer, pp, dp, u, h, c_dp, delta):
    """:func:`energy_change` on the nodes that move or carry pressure (1-D arrays there)."""
    xp = bk.xp
    lin = bk.dot(dp, u + h - delta) + 0.5 * bk.dot(dp, c_dp)
    small = xp.abs(dp) < 1e-4 * pp
    with bk.errstate(divide="ignore", invalid="ignore", over="ignore"):
        taylor = layer.w(pp) * dp + 0.5 * bk.asarray(layer.dw(pp)) * dp * dp
        direct = layer.energy(xp.maximum(pp + dp, 0.0)) - layer.energy(pp)
    return lin + float(xp.sum(xp.where(small, taylor, direct)))


def scaled(p, force, node_area, hardness=None):
    """``p`` rescaled to carry ``force`` (force control); ``p`` itself otherwise. With a hardness the nodes below
    it are scaled (:func:`bem.plastic.fill_force`; ``p`` itself where they cannot carry the force)."""
    if force is None:
        return p
    xp = backend_of(p).xp
    if hardness is None:
        return p * (force / node_area / float(xp.sum(p)))
    filled = fill_force(xp, p, force / node_area, hardness)
    return p if filled is None else filled[0]


def release(op, layer, h, p, u, released, delta, *, force, hardness=None):
    """Set to 0 the nodes the model solution releases (``released``: boolean, its pressure 0), if that lowers ``Phi``.

    Where ``w`` is concave (power ``s < 1``) a node that leaves the contact is only
    approached geometrically by damped steps (``p -> (1 - t) p``), where ``w'`` grows
    without bound: it never reaches 0, and its gap stays violated. The projected move
    to 0 is tried once per step and kept when the functional decreases; it costs one
    product with ``C``. Only nodes whose release alone lowers ``Phi``,
    ``p_n (u_n + h_n - delta) + W(p_n) - C_nn p_n^2 / 2 > 0`` (``delta`` the multiplier of
    the current contact under force control), are moved: on the root-layer problem of
    ``benchmarks/side_by_side.py`` releasing every node the model releases raises ``Phi``,
    releasing those that pass this test lowers it and saves a Newton step (the others are
    released by the model of a later step).
    Returns ``(p, u)``.
    """
    bk, mask = operator_backend(op)
    xp = bk.xp
    out = bk.select(mask & released & (p > 0))
    if not bk.count(out):
        return p, u
    if force is not None:
        contact = bk.select((p > 0) if hardness is None else (p > 0) & (p < hardness))
        if not bk.count(contact):  # every contact node plastic: no multiplier to measure the gain by
            return p, u
        pc = bk.take(p, contact)
        delta = float(xp.mean(bk.take(u, contact) + bk.asarray(layer.w(pc)) + bk.take(h, contact)))
    pn = bk.take(p, out)
    with bk.errstate(over="ignore", invalid="ignore"):
        gain = pn * (bk.take(u, out) + bk.take(h, out) - delta) + layer.energy(pn) - 0.5 * op.diagonal * pn * pn
    out = bk.subset(out, gain > 0)
    if not bk.count(out):
        return p, u
    trial = bk.put(bk.copy(p), out, 0.0)
    if force is not None and float(xp.sum(trial)) <= 0:
        return p, u
    trial = scaled(trial, force, op.lattice.node_area, hardness)
    dp = trial - p
    c_dp = op.matvec(dp)
    if energy_change(bk, layer, p, dp, u, c_dp, h, delta, mask) < 0:
        return trial, u + c_dp
    return p, u




def settle_plastic(op, layer, h, p, u, at_bound, delta, *, force, hardness):
    """Set to ``H`` the nodes the model solution puts at the hardness (``at_bound``: boolean), if that lowers ``Phi``.

    A node just below ``H`` whose model puts it at ``H`` is only approached by damped steps
    (``p -> p + t (H - p)``), and its gap, set by its plastic neighbours, stays violated while the
    line search is held short by the other nodes' inexact moves. The move to ``H`` (the force
    filled by :func:`bem.plastic.fill_force`) costs one product with ``C``. Returns ``(p, u)``.
    """
    bk, mask = operator_backend(op)
    up = bk.select(mask & at_bound & (p < hardness))
    if not bk.count(up):
        return p, u
    trial = scaled(bk.put(bk.copy(p), up, hardness), force, op.lattice.node_area, hardness)
    dp = trial - p  # under force control sum dp = 0: Phi does not depend on delta
    c_dp = op.matvec(dp)
    if energy_change(bk, layer, p, dp, u, c_dp, h, delta, mask) < 0:
        return trial, u + c_dp
    return p, u


def model_closure(bk, layer, at, D, t):
    """``w(p) + t D (q - p)`` [length] at the step's nodes ``at`` (:class:`StepNodes`; 1-D, double precision): the
    closure of a Newton step's model (compliance ``D`` per node, a brick array) at ``p + t (q - p)``."""
    return bk.asarray(layer.w(at.p)) + bk.xp.astype(bk.take(D, at.sel), bk.float64) * (t * (at.q - at.p))


def closure_move(op, layer, p, u, closure, end, delta, *, force):
    """Move to the pressure ``w^-1(closure)`` where the model keeps a node in contact (``q > 0``), 0 elsewhere, if
    that lowers ``Phi``.

    ``p`` (``u = C p``) is the pressure after a step along ``d = q - p``, ``end`` (:class:`StepEnd`) that step's
    nodes (``p`` is 0 off them) and ``u`` there, ``closure`` the model's closure there at that step
    (:func:`model_closure`). The model linearises ``w`` about the last pressure; at a node the layer dominates (``w'``
    large against ``C_nn``) its closure is right where its pressure is not: for a root law ``w = lam sqrt(p)`` and a
    node that carries its load by the layer alone, ``w^-1`` of the model's closure is the answer in one step, where
    the full step along ``d`` from below the answer ``p*`` leaves ``1 - p_new / p* = (1 - sqrt(p / p*))^2``. The nodes
    the model releases go to 0, a node where ``w^-1`` is not finite (a rigid branch) keeps ``p``; under force control
    the move is scaled to the force. It costs one product with ``C``; the change of ``Phi`` is measured at the step's
    nodes, with ``u`` there from ``end``. Returns ``(p, u, moved)``; on NumPy ``p`` and ``u`` are updated in place.
    """
    bk, _ = operator_backend(op)
    xp = bk.xp
    ps = bk.take(p, end.sel)
    with bk.errstate(over="ignore", invalid="ignore"):
        reach = bk.asarray(layer.inverse(xp.maximum(closure, 0.0)))
    trial = xp.where(end.keep, xp.where(xp.isfinite(reach), reach, ps), 0.0)
    reach = closure = None
    if force is not None:
        total = float(xp.sum(trial))
        if not (total > 0 and math.isfinite(total)):
            return p, u, False
        trial *= force / op.lattice.node_area / total
    trial -= ps  # the move dp: under force control sum dp = 0, and Phi does not depend on delta
    c_dp = op.matvec(bk.spread(p.shape, end.sel, trial))
    if not _change(bk, layer, ps, trial, end.u, end.h, bk.take(c_dp, end.sel), delta) < 0:
        return p, u, False
    moved = xp.maximum(ps + trial, 0.0)  # p + (w^-1 - p) rounds below 0 only where w^-1 is below 1e-16 p
    if not (in_place(bk, p) and in_place(bk, u)):
        return bk.put(bk.copy(p), end.sel, moved), u + c_dp, True
    u += c_dp
    return bk.put(p, end.sel, moved), u, True
