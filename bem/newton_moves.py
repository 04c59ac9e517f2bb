"""Moves of a Newton step (:mod:`bem.newton`) onto the bounds of the pressure, and the change of the functional.

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

import numpy as np

from .backend import backend_of, operator_backend
from .plastic import fill_force, in_place

__all__ = ["energy_change", "scaled", "release", "settle_plastic", "model_closure", "closure_move"]


def energy_change(bk, layer, p, delta_p, u, c_dp, h, delta, mask):
    """``(Phi(p + dp) - Phi(p)) / a`` of eq. 15, free of cancellation.

    ``u = C p``, ``c_dp = C dp``. The layer term uses the Taylor expansion where the move
    is tiny against the pressure, so that changes far below the round-off of ``Phi``
    itself are still measured with their sign.
    """
    xp = bk.xp
    # the nodes that move or carry pressure: every other node adds exactly 0
    sel = bk.select(mask & ((delta_p != 0) | (p > 0)))
    dp, pp = bk.take(delta_p, sel), bk.take(p, sel)
    lin = bk.dot(dp, bk.take(u, sel) + bk.take(h, sel) - delta) + 0.5 * bk.dot(dp, bk.take(c_dp, sel))
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


def model_closure(bk, layer, p, q, D, t, sel):
    """``w(p) + t D (q - p)`` [length] at the selected nodes (1-D, double precision): the closure of a Newton step's
    model (compliance ``D`` per node) at ``p + t (q - p)``."""
    ps = bk.take(p, sel)
    return bk.asarray(layer.w(ps)) + bk.xp.astype(bk.take(D, sel), bk.float64) * (t * (bk.take(q, sel) - ps))


def closure_move(op, layer, h, p, u, closure, kept, delta, *, force):
    """Move to the pressure ``w^-1(closure)`` at the nodes of ``kept`` (a selection, :meth:`bem.backend.Backend.select`),
    0 elsewhere, if that lowers ``Phi``.

    ``closure`` is the model's at those nodes (:func:`model_closure`; 1-D) at the step's pressure ``p`` (``u = C p``). The model
    linearises ``w`` about the last pressure; at a node the layer dominates (``w'`` large against ``C_nn``) its
    closure is right where its pressure is not: for a root law ``w = lam sqrt(p)`` and a node that carries its
    load by the layer alone, ``w^-1`` of the model's closure is the answer in one step, where the full step along
    ``d`` from below the answer ``p*`` leaves ``1 - p_new / p* = (1 - sqrt(p / p*))^2``. The nodes off ``kept``
    (those the model releases) go to 0, a node where ``w^-1`` is not finite (a rigid branch) keeps ``p``; under
    force control the move is scaled to the force. ``w^-1`` is evaluated at the nodes of ``kept`` only. It costs
    one product with ``C``. Returns ``(p, u, moved)``; on NumPy ``p`` and ``u`` are updated in place.
    """
    bk, mask = operator_backend(op)
    xp = bk.xp
    with bk.errstate(over="ignore", invalid="ignore"):
        reach = bk.asarray(layer.inverse(xp.maximum(closure, 0.0)))
    closure = None
    trial = bk.spread(p.shape, kept, xp.where(xp.isfinite(reach), reach, bk.take(p, kept)))
    if force is not None:
        total = float(xp.sum(trial))
        if not (total > 0 and math.isfinite(total)):
            return p, u, False
        trial *= force / op.lattice.node_area / total
    trial -= p  # the move dp: under force control sum dp = 0, and Phi does not depend on delta
    c_dp = op.matvec(trial)
    if not energy_change(bk, layer, p, trial, u, c_dp, h, delta, mask) < 0:
        return p, u, False
    if not (in_place(bk, p) and in_place(bk, u)):
        return xp.maximum(p + trial, 0.0), u + c_dp, True
    p += trial
    np.maximum(p, 0.0, out=p)  # p + (w^-1 - p) rounds below 0 only where w^-1 is below 1e-16 p
    u += c_dp
    return p, u, True
