"""Optimality (KKT) residual of the discrete contact problem (eq. 7-8, 14).

At a minimiser of the functional of eq. 15 over ``p >= 0`` the deformed gap
``g_n = (C p)_n + w(p_n) + h_n - delta`` satisfies

* ``p_n >= 0`` (primal feasibility),
* ``g_n = 0`` where ``p_n > 0`` (stationarity on the contact set),
* ``g_n >= 0`` where ``p_n = 0`` (dual feasibility),
* ``sqrt(3)/2 c^2 sum p_n = P`` under force control (eq. 9).

With a hardness ``H`` (:mod:`bem.plastic`) also ``p_n <= H``, and at the plastic nodes
(``p_n = H``) ``g_n <= 0`` instead of ``g_n = 0``.

:func:`kkt_residual` measures each violation relative to its natural scale and
returns the largest; every solver reports it for its final state.
"""

from __future__ import annotations

import math

from .backend import backend_of, operator_backend
from .extremes import residual_extremes
from .plastic import plastic_approach

__all__ = ["kkt_residual", "layered_state"]


def kkt_residual(p, gap, *, displacement_scale, force=None, node_area=None, hardness=None):
    """Largest relative violation of the optimality conditions.

    Parameters
    ----------
    p : ndarray
        Nodal pressures [pressure] of the candidate nodes.
    gap : ndarray
        Deformed gap ``(C p + w(p) + h - delta)`` at the same nodes [length].
    displacement_scale : float
        Scale of the gap [length]: the largest elastic displacement plus layer closure
        ``max |C p + w(p)|``.
    force : float, optional
        Target force [force] under force control; then the force balance
        ``|a sum p - P| / P`` (``a`` = ``node_area``) is included.
    node_area : float, optional
        Quadrature weight ``sqrt(3)/2 c^2`` [length^2]; needed with ``force``.
    hardness : float, optional
        The bound ``H`` [pressure] of ``p`` (:mod:`bem.plastic`): the contact nodes with ``p >= H``
        are plastic, measured by ``max_{p>=H} g_+ / s`` and ``max (p - H)_+ / H``.

    Returns
    -------
    float
        ``max( max(-p)_+ / p_max, max_{p>0} |g| / s, max_{p=0} (-g)_+ / s, force balance )``
        with ``s`` = ``displacement_scale`` (``max |g|`` when that is 0, e.g.
        for ``p = 0``); 0 for an exact solution. ``inf`` if anything is not finite.
    """
    bk = backend_of(p)
    xp = bk.xp
    p = bk.asarray(p)
    gap = bk.asarray(gap)
    with bk.errstate(over="ignore", invalid="ignore"):  # a sum is finite only where every term is, or overflows
        p_sum, gap_sum = float(xp.sum(p)), float(xp.sum(gap))
    if not (math.isfinite(p_sum) and math.isfinite(gap_sum)) and not (
            bool(xp.all(xp.isfinite(p))) and bool(xp.all(xp.isfinite(gap)))):
        return float("inf")
    s = float(displacement_scale)
    if s <= 0:  # no deformation at all: measure the gap against itself
        s = bk.max0(xp.abs(gap)) or 1.0
    if hardness is None:  # four extremes: on NumPy in one pass (bem.extremes: compiled on large arrays)
        p_min, p_max, g_contact, g_open = residual_extremes(p, gap) if bk.is_numpy else _extremes(bk, p, gap)
        p_max = max(p_max, 0.0)
        parts = [max(0.0, -p_min) / p_max if p_max > 0 else 0.0, g_contact / s, max(0.0, -g_open) / s]
    else:
        p_max, contact, plastic = bk.max0(p), p > 0, p >= hardness
        parts = [
            max(0.0, -bk.min0(p)) / p_max if p_max > 0 else 0.0,
            max(0.0, p_max - hardness) / hardness,
            bk.max0(xp.abs(gap[contact & ~plastic])) / s,
            max(0.0, -bk.min0(gap[~contact])) / s,
            max(0.0, bk.max0(gap[plastic])) / s,
        ]
    if force is not None:
        parts.append(abs(node_area * p_sum - force) / force)
    return max(parts)


def _extremes(bk, p, gap):
    """:func:`bem.extremes.residual_extremes` in the backend's namespace (0 for an empty selection's extreme, which the
    residual reads as none)."""
    contact = p > 0
    return bk.min0(p), bk.max0(p), bk.max0(bk.xp.abs(gap[contact])), bk.min0(gap[~contact])


def layered_state(op, h, layer, p, u, *, force=None, approach=None, mask=None, closure=None, hardness=None,
                  overwrite_closure=False, positive=None):
    """Deformed gap, approach and KKT residual of a pressure with a layer.

    Parameters
    ----------
    op : bem.operator.InfluenceOperator
        Supplies the lattice (node area, candidate mask).
    h, p, u : ndarray
        Initial gap [length], pressure [pressure] and elastic displacement ``C p`` [length]
        as brick arrays.
    layer : bem.layers.Layer or None
        Interface law ``w(p)``.
    force, approach : float
        The load: under force control ``delta`` is the mean of
        ``C p + w(p) + h`` over the contact nodes (the multiplier of eq. 9).
    mask : ndarray of bool, optional
        Nodes of the problem (default: the lattice's candidate nodes).
    closure : ndarray, optional
        ``w(p)`` (0 off ``mask``) where the caller has it [length].
    overwrite_closure : bool
        Whether a NumPy ``closure`` may hold ``C p + w(p)`` and the gap (not copied: an array of the lattice fewer).
    positive : ndarray of bool, optional
        ``p > 0`` where the caller has it.
    hardness : float, optional
        The bound ``H`` of ``p`` [pressure]: under force control ``delta`` is the mean over the
        elastic contact (``0 < p < H``), or :func:`bem.plastic.plastic_approach` without one.

    Returns
    -------
    gap : ndarray
        ``C p + w(p) + h - delta`` (0 off ``mask``).
    delta : float
        Approach [length].
    kkt : float
        :func:`kkt_residual` of the state.
    """
    lat = op.lattice
    bk, op_mask = operator_backend(op)
    xp = bk.xp
    mask = op_mask if mask is None else mask
    if closure is None:
        closure, overwrite_closure = xp.zeros_like(p) if layer is None else xp.where(mask, layer.w(p), 0.0), True
    if overwrite_closure and bk.is_numpy:
        total = closure  # w + C p: the same sums as C p + w
        total += u
    else:
        total = u + closure
    if hardness is not None:
        return _bounded_state(bk, lat, h, p, total, force, approach, mask, hardness)
    if bool(xp.all(mask)):  # every node of the lattice (a periodic cell): the same numbers without the masking
        scale = max(bk.max0(total), -bk.min0(total))  # max |C p + w| (a NaN reaches the residual through the gap)
        gap = total  # C p + w + h - delta in total's bytes
        gap += h
        contact = p > 0 if positive is None else positive
        delta = float(approach) if force is None else float(xp.mean(gap[contact])) if bool(xp.any(contact)) else 0.0
        gap -= delta
        return gap, delta, kkt_residual(p, gap, displacement_scale=scale, force=force, node_area=lat.node_area)
    contact = mask & (p > 0 if positive is None else positive)
    if force is not None:
        delta = float(xp.mean(total[contact] + h[contact])) if bool(xp.any(contact)) else 0.0
    else:
        delta = float(approach)
    gap = xp.where(mask, total + h - delta, 0.0)
    kkt = kkt_residual(p[mask], gap[mask], displacement_scale=float(xp.max(xp.abs(total[mask]))),
                       force=force, node_area=lat.node_area)
    return gap, delta, kkt


def _bounded_state(bk, lat, h, p, total, force, approach, mask, hardness):
    """:func:`layered_state` with the hardness bound ``H``."""
    xp = bk.xp
    v = xp.where(mask, total + h, 0.0)
    contact = mask & (p > 0)
    plastic = mask & (p >= hardness)
    if force is None:
        delta = float(approach)
    elif bool(xp.any(contact & ~plastic)):
        delta = float(xp.mean(v[contact & ~plastic]))
    elif bool(xp.any(plastic)):
        open_ = mask & ~contact
        lowest = float(xp.min(v[open_])) if bool(xp.any(open_)) else math.inf
        delta = plastic_approach(lowest, float(xp.max(v[plastic])))[0]
    else:
        delta = 0.0
    gap = xp.where(mask, v - delta, 0.0)
    kkt = kkt_residual(p[mask], gap[mask], displacement_scale=float(xp.max(xp.abs(total[mask]))), force=force,
                       node_area=lat.node_area, hardness=hardness)
    return gap, delta, kkt
