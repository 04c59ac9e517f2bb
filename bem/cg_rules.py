"""The rules every constrained-CG step of Kalker's QP shares, whatever the operator's basis.

The start (:func:`initial_pressure`), the KKT residual of an iterate (:func:`iterate_residual`),
the stopping rule (:func:`stopping_rule`), the pressure of the nodes that enter the contact
(:func:`entering_pressure`), the exact product every :data:`RECOMPUTE_EVERY` updates, and the
record of the iteration and its outcome (:class:`Record`, :class:`QPSolution`); with a hardness
(:mod:`bem.plastic`) the sets of an iterate (:func:`bounded_sets`) and the projected step with its
entering and leaving nodes (:func:`bounded_move`). The steps are
:func:`bem.kalker.solve_qp` (the general loop, any array namespace) and
:func:`bem.periodic.qp.solve_periodic_qp` (a periodic cell in the Fourier basis, any namespace); each
operator picks its own (``op.qp``).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field
from typing import Callable, NamedTuple

import numpy as np

from .backend import operator_backend
from .newton_passes import with_compliance
from .plastic import carry_force, clipped_start, fill_force, leaving_pressure, plastic_approach, plastic_start

__all__ = ["QPSolution", "Record", "CGStep", "run_constrained_cg", "initial_pressure", "iterate_residual",
           "stopping_rule", "entering_pressure", "elastic_displacement", "is_per_node", "is_stiff",
           "RECOMPUTE_EVERY", "ENTERING_FRACTION", "BACKTRACK_HALVINGS", "RIGID_SHARE", "BoundedSets",
           "bounded_sets", "bounded_move"]

log = logging.getLogger(__name__)

#: An exactly recomputed ``C p`` every so many incremental updates of the constrained CG.
RECOMPUTE_EVERY = 20

#: The share of its nodes that may lie deeper, by their deformed gap, than the lowest open node for the rigid-plastic
#: pressure to be the start of a bounded solve under force control (:func:`initial_pressure`).
RIGID_SHARE = 0.1

#: Halvings of the step of the bounded constrained CG (:func:`bounded_move`) where the projected step leaves the
#: nodes below ``H`` unable to carry the force, before the step up to the first bound: a step that sends hundreds of
#: nodes to both bounds at once is shortened instead of reduced to one node per iteration.
BACKTRACK_HALVINGS = 8

#: The share of its Jacobi estimate ``-g / (C_nn + lam)`` a node takes when it enters the contact in a
#: preconditioned step (:func:`entering_pressure`). Measured finest-level iterations of the periodic step
#: at the shares 0.35 / 0.5 / 0.7 / 1: 57 / 57 / 64 / 72 (256^2 self-affine cell, force control),
#: 51 / 50 / 52 / 61 and 52 / 49 / 52 / 54 (the 672 x 776 cell of tests/bem/test_periodic_robustness.py
#: at 0.03 and 0.04 E*), 44 / 43 / 46 / 45 (benchmarks/periodic_rough.py's cell at 512^2). A compliance
#: per node (Newton's model QP) takes the whole estimate: the root layer of that benchmark at 1024^2
#: needs 85 products of C in all with it, 90 with half.
ENTERING_FRACTION = 0.5


@dataclass
class QPSolution:
    """Outcome of :func:`solve_qp` and of every solver built on it (brick arrays on the operator's lattice).

    ``displacement`` is the elastic displacement ``C p`` [length], the same for every solver (the
    layer's closure ``lam p`` or ``w(p)`` is not in it); ``None`` where a solver did not keep it.
    The arrays are in the namespace of the operator's device.
    """

    p: np.ndarray
    approach: float
    iterations: int
    converged: bool
    message: str
    kkt_residual: float
    displacement: np.ndarray
    status: str  # one of bem.result.STATUSES
    history: dict = field(default_factory=dict)


def _quantile(bk, values, q):
    """``numpy.quantile(values, q)`` (linear interpolation) of a 1-D array, as a Python float."""
    if bk.is_numpy:
        return float(np.quantile(values, q))
    v = bk.xp.sort(values)
    pos = q * (v.shape[0] - 1)
    lo = int(math.floor(pos))
    hi = min(lo + 1, v.shape[0] - 1)
    a, b, t = float(v[lo]), float(v[hi]), pos - lo
    return a + (b - a) * t if t < 0.5 else b - (b - a) * (1 - t)


def initial_pressure(op, h, lam, force, approach, x0, hardness=None, overwrite_x0=False):
    """The starting pressure of the constrained CG (brick array): ``x0`` clipped at 0, or under force
    control a uniform pressure on the quarter of the nodes with the smallest gap, or under approach
    control the Jacobi estimate ``(delta - h)_+ / (C_nn + lam)``; scaled to carry ``force``.

    With a ``hardness`` ``H`` the start is clipped at ``H``, and under force control the uniform
    pressure covers enough nodes to stay below ``0.8 H`` and is scaled by
    :func:`bem.plastic.fill_force`; where the rigid-plastic pressure (:func:`bem.plastic.plastic_start`) nearly keeps
    its order under its own displacement (:data:`RIGID_SHARE`) it is the start instead, and an ``x0`` whose
    nodes cannot carry the force below ``H`` is joined by it (:func:`bem.plastic.carry_force`).

    ``overwrite_x0``: a writeable float64 NumPy ``x0`` may be overwritten (clipped in place by
    :func:`bem.plastic.clipped_start`, so that no second array of its size is made); otherwise ``x0`` is not modified."""
    lat = op.lattice
    bk, mask = operator_backend(op)
    xp = bk.xp
    if x0 is not None:
        p = clipped_start(bk, x0, mask, hardness, overwrite_x0)
    elif force is not None:
        # rigid-punch-like start: pressure where the gap is smallest
        hm = xp.where(mask, h, xp.inf)
        share = 0.25
        if hardness is not None:  # enough nodes to carry the force below 0.8 H
            share = min(1.0, max(share, 1.25 * force / (lat.node_area * hardness * int(xp.count_nonzero(mask)))))
        level = _quantile(bk, hm[mask], share)
        p = xp.astype(mask & (hm <= level), bk.float64)
        if hardness is not None and (rigid := _rigid_plastic(op, bk, h, force / lat.node_area, hardness, mask)) is not None:
            return rigid
    else:
        p = xp.where(mask, xp.maximum(approach - h, 0.0), 0.0) / (op.diagonal + float(xp.max(lam) if is_per_node(lam) else lam))
        if hardness is not None:
            p = xp.minimum(p, hardness)
    if force is not None:
        total = float(xp.sum(p))
        if total <= 0:
            p = xp.astype(mask, bk.float64)
            total = float(xp.sum(p))
        if hardness is None:
            p *= force / lat.node_area / total
        else:
            p = carry_force(xp, p, force / lat.node_area, hardness, mask, h)
    return p


def _rigid_plastic(op, bk, h, target, hardness, mask):
    """The rigid-plastic pressure of the gap (:func:`bem.plastic.plastic_start`) where it nearly keeps its order under its own
    elastic displacement ``u``: fewer than :data:`RIGID_SHARE` of its nodes have a deformed gap ``h + u`` above the
    smallest one of the open nodes (a surface far softer in yield than in elasticity); else ``None``."""
    xp = bk.xp
    rigid = plastic_start(xp, h, target, hardness, mask)
    if rigid is None:
        return None
    v = op.matvec(rigid) + h
    on = rigid > 0
    lowest_open = float(xp.min(xp.where(on | ~mask, xp.inf, v)))
    n_out = int(xp.count_nonzero(on & (v > lowest_open)))
    return rigid if n_out < RIGID_SHARE * int(xp.count_nonzero(on)) else None


def entering_pressure(xp, g, tau, jacobi, per_node, preconditioned=False):
    """Pressure of the nodes that enter the contact (``p = 0``, gap ``g < 0``), with ``jacobi = 1 / (C_nn + lam)``
    (an array where ``per_node``) and ``tau`` the step of the iteration (0: none).

    A step along the gap itself (``preconditioned`` False) gives Polonsky-Keer's ``-tau g``, capped by the
    Jacobi estimate ``-g / (C_nn + lam)`` so that a node with a large layer compliance cannot overshoot.
    A step along the preconditioned gap ``M g`` has a dimensionless ``tau``: the entering node takes
    that step with :data:`ENTERING_FRACTION` of the Jacobi estimate of ``M`` there,
    ``-f min(tau, 1) g / (C_nn + lam)`` (nodes enter in clusters, and each closes part of its neighbours'
    gaps); with a compliance per node (Newton's model) the whole estimate, ``f = 1``.
    """
    if preconditioned:
        return -g * jacobi * ((1.0 if per_node else ENTERING_FRACTION) * (min(tau, 1.0) if tau > 0 else 1.0))
    return -g * ((xp.minimum(tau, jacobi) if per_node else min(tau, jacobi)) if tau > 0 else jacobi)


class BoundedSets(NamedTuple):
    """The sets of an iterate of the bounded QP (:func:`bounded_sets`)."""

    on: object  # p > 0 (brick)
    plastic: object  # p >= H (brick)
    idx: object  # the elastic contact 0 < p < H (a node selection): the nodes of the search direction
    pl: object  # the plastic nodes (a node selection)
    delta: float  # the approach (under force control the multiplier of the elastic contact)
    bracket: tuple | None  # the interval of the approach of a fully plastic contact (bem.plastic.plastic_approach)
    gap_min: float  # the smallest deformed gap off the plastic nodes
    plastic_gap: float  # the largest deformed gap of the plastic nodes (-inf without)


def bounded_sets(bk, p, v, hardness, delta, force, mask=None):
    """The sets, the approach and the gap extremes of an iterate of the bounded QP (:mod:`bem.plastic`).

    ``v = (C + lam) p + h`` (brick), the deformed gap ``v - delta``; ``delta`` the approach under approach
    control; ``mask`` the candidate nodes (``None``: every node).
    """
    xp = bk.xp
    on, plastic = p > 0, p >= hardness
    idx, pl = bk.select(on & ~plastic), bk.select(plastic)
    v_pl = float(xp.max(bk.take(v, pl))) if bk.count(pl) else -math.inf
    bracket = None
    if force is not None and bk.count(idx):
        delta = float(xp.mean(bk.take(v, idx)))
    elif force is not None and bk.count(pl):
        delta, bracket = plastic_approach(float(xp.min(xp.where(on if mask is None else on | ~mask, xp.inf, v))), v_pl)
    elif force is not None:
        delta = math.nan
    away = plastic if mask is None else plastic | ~mask
    return BoundedSets(on, plastic, idx, pl, delta, bracket, float(xp.min(xp.where(away, xp.inf, v))) - delta,
                       v_pl - delta)


def bounded_move(bk, p, sets, p_c0, t_c, tau, v, jacobi, per_node, target, hardness, preconditioned=False,
                 halvings=0, mask=None):
    """One step of the bounded constrained CG, on ``p`` (brick) in place; ``(changed, entered, s, failure, restart)``.

    The elastic nodes ``sets.idx`` move from ``p_c0`` along ``-tau t_c``, projected onto ``[0, H]``; the
    open nodes whose gap ``v - delta`` is negative enter (:func:`entering_pressure`, at most ``H``), the
    plastic nodes whose gap is positive leave (:func:`bem.plastic.leaving_pressure`); under force control
    (``target = P / a``) :func:`bem.plastic.fill_force` carries the force. Where the step has no elastic direction
    (``tau = 0`` or no elastic node) and the force cannot be carried, or the nodes at ``H`` carry too much, the
    pressure is the rigid-plastic one of the deformed gap ``v`` (:func:`bem.plastic.plastic_start` on ``mask``, ``None``:
    every node): a contact that is (nearly) fully plastic. Elsewhere, where the force cannot be carried, the step
    is halved up to ``halvings`` times (the periodic step: :data:`BACKTRACK_HALVINGS`; the general step none: the
    same iterations on the rough sphere of ``benchmarks/cases.py`` with a hardness) and, where none of those can
    either, goes up to the first bound. ``jacobi = 1 / (C_nn + lam)`` (a brick array where ``per_node``).
    ``changed``: a node reached a bound, entered, left or was capped (``C p`` is then to be recomputed);
    ``entered``: a node entered the contact or left the plastic set; ``s``: the factor of the elastic nodes;
    ``failure``: ``(message, status)`` where no step can be taken; ``restart``:
    the step was shortened, or nodes capped at ``H``, so that the force is carried (the step that keeps its
    directions on entering nodes restarts them there).
    """
    xp, idx, pl, delta = bk.xp, sets.idx, sets.pl, sets.delta

    def jac(sel):
        return bk.take(jacobi, sel) if per_node else jacobi

    p_c = xp.minimum(xp.maximum(p_c0 - tau * t_c, 0.0), hardness)
    hit = bool(xp.any((p_c == 0) | (p_c == hardness)))
    bk.put(p, idx, p_c)
    low = bk.select(v < delta)
    overlap = bk.subset(low, bk.take(p, low) == 0)  # open nodes that close: they enter
    leave = bk.subset(pl, bk.take(v, pl) > delta)  # plastic nodes whose gap opens: they leave
    bk.put(p, overlap, xp.minimum(entering_pressure(xp, bk.take(v, overlap) - delta, tau, jac(overlap), per_node,
                                                    preconditioned), hardness))
    bk.put(p, leave, leaving_pressure(xp, hardness, entering_pressure(xp, delta - bk.take(v, leave), tau, jac(leave),
                                                                      per_node, preconditioned)))
    moved = bool(bk.count(overlap) or bk.count(leave))
    if target is None:
        return hit or moved, moved, 1.0, None, False
    filled = fill_force(xp, p, target, hardness)
    shorter, short = tau, filled is None
    for _ in range(halvings if filled is None and bk.count(idx) else 0):  # a shorter projected step
        shorter *= 0.5
        bk.put(p, idx, xp.minimum(xp.maximum(p_c0 - shorter * t_c, 0.0), hardness))
        filled = fill_force(xp, p, target, hardness)
        if filled is not None:
            hit = True
            break
    over = hardness * int(xp.count_nonzero(p >= hardness)) > target * (1.0 + 1e-13)  # the nodes at H carry too much
    if (filled is None or over) and (tau == 0 or not bk.count(idx)):  # no elastic step: the smallest deformed gaps
        rigid = plastic_start(xp, v, target, hardness, (v == v) if mask is None else mask)
        if rigid is not None:
            p[...] = rigid
            return True, True, 1.0, None, True
    if filled is None and bk.count(idx):  # the nodes below H cannot carry the force: the step up to the first bound
        bk.put(p, overlap, 0.0)
        bk.put(p, leave, hardness)
        reach = xp.where(t_c > 0, p_c0 / xp.where(t_c > 0, t_c, 1.0),
                         xp.where(t_c < 0, (p_c0 - hardness) / xp.where(t_c < 0, t_c, 1.0), xp.inf))
        bk.put(p, idx, xp.minimum(xp.maximum(p_c0 - min(tau, float(xp.min(reach))) * t_c, 0.0), hardness))
        hit, moved = True, False
        filled = fill_force(xp, p, target, hardness)
    if filled is None:
        bk.put(p, idx, p_c0)
        bk.put(p, overlap, 0.0)
        bk.put(p, leave, hardness)
        return True, False, 1.0, ("no elastic contact node can carry the force", "stalled"), True
    new, s, capped = filled
    p[...] = new
    return hit or moved or capped, moved, s, None, short or capped


def is_stiff(D, diagonal, threshold):
    """The nodes whose compliance ``D`` leaves the FFT preconditioner in charge, ``D <= threshold C_nn``
    (Jacobi ``1 / (C_nn + D)`` elsewhere: :func:`bem.kalker.compliance_preconditioner`)."""
    return D <= threshold * diagonal


def is_per_node(lam):
    """Whether the compliance ``lam`` is given per node (an array) rather than uniform."""
    return getattr(lam, "ndim", 0) > 0


def elastic_displacement(bk, u, lam, p, out=None, offset=None):
    """``C p = u - lam p - offset`` (float64) from ``u = (C + lam) p + offset``, ``lam`` [length/pressure] per node
    or uniform, ``offset`` None or ``(nodes, values)`` (0 elsewhere): ``u`` where both are 0; ``out``: its array."""
    if not is_per_node(lam) and not lam:
        v = bk.xp.astype(u, bk.xp.float64, copy=False)
    else:  # (NumPy: bem.newton_passes, one pass on a large lattice)
        v = with_compliance(u, lam, p, out, -1) if bk.is_numpy else u - lam * p
    return v if offset is None else bk.add_at(v, offset[0], -offset[1])


def iterate_residual(contact_gap, gap_min, scale, gap_max, force_error=None, plastic_gap=None):
    """The KKT residual of an iterate (:func:`bem.kkt.kkt_residual` from its parts; non-finite: ``inf``).

    ``max(max_contact |g|, (-min g)_+) / scale`` (every contact node has ``-g <= max_contact |g|``), with
    ``contact_gap = max_contact |g|``, ``gap_min = min g``, ``scale`` the displacement scale and
    ``gap_max()`` the largest ``|g|``, the scale where ``scale`` is not positive (or 1); under force
    control the larger of that and ``force_error = |a sum p - P| / P``. With a hardness
    (:mod:`bem.plastic`) the contact is the elastic one (``0 < p < H``), ``gap_min`` the smallest gap
    off the plastic nodes and ``plastic_gap = max_plastic g`` (a plastic node may overlap, ``g <= 0``).
    """
    parts = [contact_gap, -gap_min, 0.0] if plastic_gap is None else [contact_gap, -gap_min, plastic_gap, 0.0]
    kkt = (math.nan if any(math.isnan(v) for v in parts) else max(parts)) / (scale if scale > 0 else gap_max() or 1.0)
    if force_error is not None:
        kkt = float(np.max([kkt, force_error]))
    return kkt if math.isfinite(kkt) else np.inf


def stopping_rule(kkt, rtol):
    """``(converged, message, status)`` of the QP's stopping rule at the KKT residual ``kkt``
    (non-finite: ``nonfinite``; ``kkt <= rtol``: ``converged``), ``None`` to go on."""
    if not math.isfinite(kkt):
        return False, "the iteration produced a non-finite value", "nonfinite"
    if kkt <= rtol:
        return True, f"KKT residual {kkt:.2e} <= rtol {rtol:.1e}", "converged"
    return None


class Record:
    """The history of a constrained CG (``residual``, ``p_max``, ``n_contact``, ``changes`` per
    iteration) and its outcome under the one stopping rule.

    Parameters
    ----------
    rtol : float
        Tolerance on the KKT residual.
    maxiter : int
        Iteration limit (for the message of a run that reaches it).
    """

    def __init__(self, rtol, maxiter):
        self.rtol, self.maxiter = rtol, maxiter
        self.history = {"residual": [], "p_max": [], "n_contact": [], "changes": []}
        self.converged, self.message, self.status = False, "", "maxiter"
        self.stopped = self.empty = False

    def stops(self, kkt, p_max, n_contact, changes, no_contact):
        """Record an iterate; whether the iteration stops there: :func:`stopping_rule`, or no node in
        contact and no gap closed (``no_contact``: ``p = 0`` is the solution, residual 0)."""
        hist = self.history
        hist["residual"].append(kkt)
        hist["p_max"].append(p_max)
        hist["n_contact"].append(n_contact)
        hist["changes"].append(changes)
        if (stop := stopping_rule(kkt, self.rtol)) is not None:
            self.converged, self.message, self.status = stop
        elif no_contact:
            self.converged, self.message, self.status = True, "no contact at this approach", "converged"
            self.empty = True
        else:
            return False
        self.stopped = True
        return True

    def fail(self, message, status):
        """Stop without convergence (``status`` one of :data:`bem.result.STATUSES`)."""
        self.message, self.status, self.stopped = message, status, True

    def solution(self, p, delta, kkt, displacement, name):
        """The :class:`QPSolution` of the last iterate ``p`` (``kkt`` its residual; 0 where no contact was the answer)."""
        if not self.stopped:
            self.message = (f"no convergence in maxiter = {self.maxiter} iterations (KKT residual {kkt:.2e} > "
                            f"rtol {self.rtol:.1e})")
        if not self.converged:
            log.debug("%s: %s", name, self.message)
        if self.empty:
            kkt = 0.0
        return QPSolution(p=p, approach=float(delta), iterations=len(self.history["residual"]),
                          converged=self.converged, message=self.message, status=self.status,
                          kkt_residual=float(kkt), displacement=displacement, history=self.history)


class CGStep(NamedTuple):
    """The operations of one operator's constrained-CG step, in its own basis, for :func:`run_constrained_cg`."""

    measure: Callable  # measure(k) -> the KKT residual of the current iterate (iterate_residual)
    confirms: Callable  # confirms(kkt) -> True where C p was recomputed exactly and the iterate is measured again
    observe: Callable  # observe() -> (p_max, n_contact, changes, no_contact) of the iterate, for Record.stops
    advance: Callable  # advance(k) -> None after the step of iteration k, or (message, status) where no step can be taken
    report: Callable  # report() -> the pressure for the callback


def run_constrained_cg(step, record, maxiter, callback=None):
    """The one loop of the constrained conjugate gradients of Kalker's QP (Polonsky & Keer 1999).

    Each iteration measures the iterate (its KKT residual), confirms a residual at the tolerance on an
    exact product, records it and stops by the one stopping rule (:meth:`Record.stops`), or takes a
    step (``step.advance``) and reports the pressure to ``callback(k, p)``. Returns the last residual.
    """
    kkt = np.inf
    for k in range(1, maxiter + 1):
        kkt = step.measure(k)
        if step.confirms(kkt):
            continue
        if record.stops(kkt, *step.observe()):
            break
        if (failure := step.advance(k)) is not None:
            record.fail(*failure)
            break
        if callback is not None:
            callback(k, step.report())
    return kkt
