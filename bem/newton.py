"""Direct minimisation of the generalised Kalker functional (eq. 15) by Newton's method.

``Phi(p) = a [1/2 p.C p + p.(h - delta) + sum W(p_n)]`` is convex for a
non-decreasing ``w``. Each Newton step minimises its local quadratic model

``m(q) = 1/2 q.(C + D) q + q.(h + w(p) - D p)``  over ``q >= 0``
(and ``a sum q = P`` under force control),

with ``D = diag(w'(p))``, by the constrained conjugate gradients of Kalker's QP (:func:`bem.kalker.solve_qp`;
on a periodic cell :func:`bem.periodic.qp.solve_periodic_qp`), matrix-free with FFT products.
The model has the gradient of ``Phi`` at ``p``, so for any positive
``D`` the step ``d = q - p`` is a feasible descent direction, and an exact line
search on ``Phi(p + t d)``, ``t in (0, 1]``, makes the method globally
convergent; with ``D = w'`` it converges quadratically where ``w'`` is
continuous. Where ``w'`` is infinite (root and power laws with ``s < 1`` at
``p = 0``) a node without pressure uses the secant of ``w`` up to the pressure
the layer alone would carry there, ``w^-1(-g_n)``, which is finite; where ``w'``
jumps (elastic-rigid, bilinear) the one-sided derivative of the current branch
is used and the line search settles the kink. Where ``w'`` varies fast (a root law
at small pressures) the quadratic region of the step along ``d`` is small; the
pressure whose closure is the model's (:func:`bem.newton_moves.closure_move`),
kept where it lowers ``Phi`` further, is Newton's method in the closure there.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from .brent import brent_root
from .backend import backend_of, operator_backend
from . import heap
from .layers.device import device_layer
from .cg_rules import QPSolution
from .kalker import solve_qp
from .kkt import layered_state
from .newton_model import majorant, tangent
from .newton_passes import advance
from .newton_moves import closure_move, line_search, model_closure, release, scaled, settle_plastic, step_nodes
from .plastic import carry_force, clip, clipped_start, fully_plastic_note, in_place

__all__ = ["solve_newton"]

log = logging.getLogger(__name__)

# Forcing terms of the inexact Newton method (inner QP tolerance / KKT residual): Eisenstat & Walker's second
# choice, eta_k = _GAMMA (r_k / r_(k-1))^_ALPHA, at most _FORCING (Eisenstat & Walker 1996,
# doi:10.1137/0917003). With the closure move (bem.newton_moves.closure_move) the steps converge
# superlinearly, and the inner solves follow: on the root-layer cell of benchmarks/periodic_rough.py,
# 6 Newton steps and 55 inner iterations on the finest level, against 9 and 57 with eta_k = r_k / r_(k-1).
_FORCING = 0.3
_GAMMA, _ALPHA = 0.9, (1 + math.sqrt(5)) / 2
_SINGLE_MAX = float(np.finfo(np.float32).max)  # the model's D in single precision below it


# Dot products go through Backend.dot: on NumPy np.einsum, because np.dot and np.vdot call the
# threaded OpenBLAS ddot, which waits for its second thread and is slow by orders of magnitude
# when the other cores are busy; np.einsum is not (docs/performance.md, "The FFT back end").


def _advance(bk, p, u, sub, t, force, node_area, hardness):
    """``(p + t d, u + t C d)`` for the step ``d = q - p`` to the model's solution ``q = sub.p`` (``C q`` its
    displacement), ``p + t d`` clipped to the bounds and scaled to the force. On NumPy in the buffers of ``q`` and
    ``C q``, which the step consumes (the same numbers as the new arrays elsewhere)."""
    q, uq = sub.p, sub.displacement
    if not (in_place(bk, q) and in_place(bk, uq)):
        return scaled(clip(bk.xp, p + t * (q - p), hardness), force, node_area, hardness), u + t * (uq - u)
    advance(p, q, u, uq, t)  # q = max(p + t d, 0), uq = u + t C d (bem.newton_passes)
    if hardness is not None:
        np.minimum(q, hardness, out=q)
    if force is not None and hardness is None:
        q *= force / node_area / float(np.sum(q))
    else:
        q = scaled(q, force, node_area, hardness)
    return q, uq


def _model_qp(op, h, layer, D, contact, on, precondition, p, u, periodic, **kw):
    """The QP of a Newton step's model (compliance ``D`` per node, ``contact``: ``p > 0``, ``on``: its node
    selection and ``p`` there) from ``p`` and ``u = C p`` by the operator's constrained-CG step (``op.qp``);
    ``(solution, p, u)``. Its gap ``h + w(p) - D p`` goes as ``h`` and the offset ``w(p) - D p`` on the nodes of
    nonzero pressure (``w(0) = 0``, :mod:`bem.layers.base`): no array of it. Where it can
    (:func:`bem.plastic.in_place`) the QP holds its iterate in ``p``, kept meanwhile on those nodes only and
    returned as a new array (the same values), and on a ``periodic`` cell whose product ``C p`` (spectrum and ``u``)
    takes more than :data:`bem.heap.RELEASE_ABOVE` bytes its product in ``u`` (``overwrite_u0``), made again after
    (one product a step): an array of the lattice fewer through the QP each (a region's QP makes new ones)."""
    bk = backend_of(p)
    at, kept = on  # (kept: a copy, not p's bytes)
    offset = (at, bk.asarray(layer.w(kept)) - bk.take(D, at) * kept)
    own, hand = in_place(bk, p), periodic and in_place(bk, u) and heap.above(2 * u.nbytes)
    kw = dict(kw, overwrite_u0=True) if hand else kw  # (the region's QP takes no overwrite_u0)
    sub = op.qp(h, lam=D, precondition=precondition, contact=contact, x0=p, offset=offset, u0=u, overwrite_x0=own, **kw)
    p = bk.spread(p.shape, at, kept) if own else p
    if hand:  # the QP's arrays, freed, returned to the system before the product's spectrum and output are made
        heap.release(2 * u.nbytes)
    return sub, p, op.matvec(p) if hand else u


def _count_inner(hist, sub):
    """Tally inner QP solves that stopped before their tolerance (summarised once by the caller)."""
    if not sub.converged:
        hist["inner_missed"] += 1
        hist["inner_worst"] = max(hist["inner_worst"], float(sub.kkt_residual))


def solve_newton(op, h, *, layer, force=None, approach=None, x0=None, rtol=1e-10, maxiter=100,
                 precondition=True, callback=None, record=False, inner_maxiter=300, hardness=None, overwrite_x0=False):
    """Newton's method with exact line search for the layered contact problem.

    Parameters
    ----------
    op : bem.operator.InfluenceOperator
        ``C`` on the candidate lattice.
    h : ndarray
        Gap, brick array [length].
    layer : bem.layers.Layer
        Interface law.
    force, approach : float
        Exactly one: total force [force] or approach [length].
    x0 : ndarray, optional
        Initial pressure (brick array); default: the smooth-body solution
        followed by one step of the variable compliance method (eq. 22).
    rtol : float
        Tolerance on the KKT residual of eq. 14 (:func:`bem.kkt.kkt_residual`).
    maxiter : int
        Newton iteration limit.
    precondition : bool
        FFT preconditioner in the inner conjugate gradients.
    callback : callable, optional
        ``callback(k, p)`` after every Newton step.
    record : bool
        Keep every iterate in ``history["p"]``.
    inner_maxiter : int
        Iteration limit of each inner QP; an unfinished inner solve still gives
        a feasible trial point, and the line search decides how far to go.
    hardness : float, optional
        The bound ``p <= H`` [pressure] (:mod:`bem.plastic`): the inner QPs are bounded, so the
        step ``d = q - p`` stays in the box ``0 <= p <= H`` for ``t in (0, 1]``.
    overwrite_x0 : bool
        Whether a float64 NumPy ``x0`` may hold the iterate: each step's pressure is copied into it (one
        array of the lattice fewer where the caller holds ``x0`` anyway; the callback gets a copy).

    Returns
    -------
    bem.kalker.QPSolution

    Notes
    -----
    Stopping rule: ``r = kkt_residual(p, C p + w(p) + h - delta) <= rtol`` on an exactly recomputed ``C p``. Where the
    line search finds no measurable decrease of ``Phi`` (its change is below round-off near the solution) the full step
    is taken if it lowers ``r``; otherwise the iteration stops, not converged. After each step of a nonlinear law
    without a hardness, the pressure whose closure is the model's, ``w^-1(w(p) + t D (q - p))`` where ``q_n > 0``,
    replaces the step's when that lowers ``Phi`` (``history["closure_moves"]`` counts them); then nodes that the model
    solution releases (``q_n = 0``) are set to 0 when that lowers ``Phi`` (and with a hardness, those it puts at ``H``
    are set to ``H``; :mod:`bem.newton_moves`). The inner QP of step ``k`` is solved to ``min(1e-2, eta_k r_k)``, never
    below ``rtol / 3`` (``r_k`` the current KKT residual): an inexact Newton method with the forcing term ``eta_k =
    min(0.3, 0.9 (r_k / r_(k-1))^1.618)`` (Eisenstat & Walker's second choice), which follows the convergence of the
    outer iteration.
    """
    bk, mask = operator_backend(op)
    xp = bk.xp
    layer = device_layer(layer, bk)
    h = bk.asarray(h)
    if not bool(xp.all(mask)):  # a periodic cell's gap is used as it is (never written)
        h = xp.where(mask, h, 0.0)
    if x0 is None:
        # the smooth-body solution, then one secant (variable compliance) step: fair for stiff and soft layers alike
        start = solve_qp(op, h, force=force, approach=approach, rtol=1e-3,
                         preconditioner=op.preconditioner() if precondition else None, hardness=hardness)
        contact = start.p > 0
        lam = float(layer.secant(float(xp.mean(start.p[contact])))) if bool(xp.any(contact)) else 0.0
        if math.isfinite(lam) and lam > 0:
            start = solve_qp(op, h, force=force, approach=approach, lam=lam, rtol=1e-3,
                             preconditioner=op.preconditioner(lam=lam) if precondition else None, hardness=hardness)
        p = start.p
    else:
        p = clipped_start(bk, x0, mask, hardness, overwrite_x0)
        if force is not None and hardness is None:
            p *= force / op.lattice.node_area / float(xp.sum(p))
        elif force is not None:  # its nodes below H carry the force, or the nodes of smallest gap help them
            p = carry_force(xp, p, force / op.lattice.node_area, hardness, mask, h)
    own = p if overwrite_x0 and p is x0 else None  # the caller's x0, holding the iterate
    x0 = None
    u = op.matvec(p)
    hist = {"residual": [], "p_max": [], "n_contact": [], "changes": [], "step": [], "inner_iterations": [],
            "inner_missed": 0, "inner_worst": 0.0, "closure_moves": 0, **({"p": []} if record else {})}
    converged, message, status, exact = False, "", "maxiter", True
    bound = {} if hardness is None else {"hardness": hardness}  # the elastic inner solves take no bound
    prev = p > 0
    full = bool(xp.all(mask))  # every node a candidate (a periodic cell): no masking
    shared = op.shared_model_state() if precondition and hasattr(op, "shared_model_state") else {}  # (a cell's)

    def masked(x):
        return x if full else xp.where(mask, x, 0.0)

    def closure(p):  # w(p), 0 off the mask
        return masked(bk.asarray(layer.w(p)))

    for k in range(maxiter + 1):
        heap.release(24 * math.prod(p.shape))  # the free heap (the last QP's arrays) before the closure, C p + w, gap
        contact = p > 0  # read by the state, the model and its QP (p is not changed before)
        gap, delta, kkt = layered_state(op, h, layer, p, u, force=force, approach=approach, closure=closure(p),
                                         hardness=hardness, overwrite_closure=True, positive=contact)  # gap in w's
        if kkt <= rtol and not exact:  # confirm on an exact product before stopping
            u, exact = op.matvec(p), True
            gap, delta, kkt = layered_state(op, h, layer, p, u, force=force, approach=approach, closure=closure(p),
                                         hardness=hardness, overwrite_closure=True, positive=contact)
        hist["residual"].append(kkt)
        hist["p_max"].append(float(xp.max(p)))
        hist["n_contact"].append(int(xp.count_nonzero(contact)))
        hist["changes"].append(int(xp.count_nonzero(contact != prev)))
        if record:
            hist["p"].append(bk.to_host(p[mask]).copy())
        prev = contact
        if not math.isfinite(kkt):
            message, status = "the iteration produced a non-finite value", "nonfinite"
            break
        if kkt <= rtol:
            converged, status = True, "converged"
            message = f"KKT residual {kkt:.2e} <= rtol {rtol:.1e} after {k} Newton steps"
            break
        if k == maxiter:
            message = f"no convergence in maxiter = {maxiter} Newton steps (KKT residual {kkt:.2e} > rtol {rtol:.1e})"
            break
        on = (nodes := bk.select(contact)), bk.take(p, nodes)  # the contact's nodes and pressures, for the model
        p_ref = float(xp.mean(on[1])) if bk.count(on[0]) else 1.0
        if full:  # a model's D: single precision will do, made so where it can be
            D = tangent(bk, layer, p, gap, p_ref, single_below=_SINGLE_MAX, positive=contact, on=on)
        else:
            D = masked(tangent(bk, layer, p, gap, p_ref, positive=contact, on=on))
            D = xp.astype(D, xp.float32) if float(xp.max(D)) < _SINGLE_MAX else D
        gap = None  # made again at the next step or where needed: not held through the model's solve
        # forcing term: _FORCING, or less where the last step reduced the residual (Eisenstat & Walker)
        eta = min(_FORCING, _GAMMA * (kkt / hist["residual"][-2]) ** _ALPHA) if len(hist["residual"]) > 1 else _FORCING
        inner = max(rtol / 3, min(1e-2, eta * kkt))
        # the model starts at p with Newton's u and Newton checks each step on its own residual: no product to start
        # or to confirm the inner solve (fewer products on benchmarks/side_by_side.py's root layer)
        sub, p, u = _model_qp(op, h, layer, D, contact, on, precondition, p, u, full, force=force, approach=approach,
                              rtol=inner, maxiter=inner_maxiter, confirm=False, **bound, **shared)
        _count_inner(hist, sub)
        # the step d = q - p of the model's solution q (C d = uq - u), on the nodes with pressure before or after it
        at = step_nodes(bk, p, sub.p, u, sub.displacement, h, None if full else mask)
        t = line_search(bk, layer, at, delta)
        if t < 1e-10:  # no useful descent: tighter model solve where the model is too soft, then retry
            wp = closure(p)
            scale = float(xp.max(xp.abs(u + wp)))
            D = majorant(op, layer, p, sub.p, xp.astype(D, xp.float64), mask)  # (raised past single precision's range)
            wp = sub = at = None
            sub, p, u = _model_qp(op, h, layer, D, contact, on, precondition, p, u, full, force=force,
                                  approach=approach, rtol=max(rtol / 3, 1e-3 * kkt), maxiter=4 * inner_maxiter,
                                  scale=scale, confirm=False, **bound, **shared)
            _count_inner(hist, sub)
            at = step_nodes(bk, p, sub.p, u, sub.displacement, h, None if full else mask)
            t = line_search(bk, layer, at, delta)
        # the model's closure at the step, for the closure move (not for linear laws, where it is the step itself)
        moves = t > 0.0 and hardness is None and not layer.is_linear
        w_model = model_closure(bk, layer, at, D, t) if moves else None
        at, D, judged = at.end(t) if moves else None, None, None  # (p, q and C q there not held)
        if t == 0.0:
            # No decrease of Phi measurable along d: the change of Phi falls below its round-off while nodes of tiny
            # pressure (where w' is huge, e.g. a power law with small s) still violate their gap. The step is then
            # chosen by the KKT residual instead: t = 1, 1/2, 1/4, 1/8, the first that lowers it.
            d = sub.p - p
            for t_try in (1.0, 0.5, 0.25, 0.125):
                trial = scaled(clip(xp, p + t_try * d, hardness), force, op.lattice.node_area, hardness)
                u_trial = op.matvec(trial)
                if layered_state(op, h, layer, trial, u_trial, force=force, approach=approach,
                                 hardness=hardness)[2] < kkt:
                    judged = t_try
                    break
        hist["step"].append(t if judged is None else judged)
        hist["inner_iterations"].append(sub.iterations)
        if judged is not None:
            p, u, exact = trial, u_trial, True
        elif t == 0.0:
            message = f"line search found no descent (KKT residual {kkt:.2e} > rtol {rtol:.1e})"
            status = "stalled"
            break
        d = trial = u_trial = None
        # the nodes the model releases, and with a hardness those it puts at H (the moves of bem.newton_moves)
        released = sub.p == 0
        at_bound = None if hardness is None else sub.p >= hardness
        if judged is None:
            p, u = _advance(bk, p, u, sub, t, force, op.lattice.node_area, hardness)
            exact = False
        sub = None
        if w_model is not None:  # t > 0: the step along d was taken
            p, u, moved = closure_move(op, layer, p, u, w_model, at, delta, force=force)
            hist["closure_moves"] += moved
        w_model = at = None
        p, u = release(op, layer, h, p, u, released, delta, force=force, hardness=hardness)
        if hardness is not None:
            p, u = settle_plastic(op, layer, h, p, u, at_bound, delta, force=force, hardness=hardness)
        if own is not None and p is not own:  # the step's pressure into the caller's x0
            own[...] = p
            p = own
        if callback is not None:
            callback(k + 1, p if own is None else bk.copy(p))
        released = at_bound = None  # not held through the next step's model solve
    if converged and hardness is not None and force is not None and (
            bracket := _plastic_bracket(bk, mask, p, gap + delta, hardness)) is not None:
        hist["approach_bracket"] = list(bracket)
        message += fully_plastic_note(bracket)
    if not converged:
        log.debug("Newton: %s", message)
    out = QPSolution(p=p, approach=delta, iterations=len(hist["step"]), converged=converged, message=message,
                     status=status, kkt_residual=float(kkt), displacement=u, history=hist)
    if force is not None and not converged and math.isfinite(delta) and delta > 0:
        out = _force_by_approach(op, h, layer, force, out, rtol=rtol, maxiter=maxiter, precondition=precondition,
                                 inner_maxiter=inner_maxiter, hardness=hardness)
    return out


def _plastic_bracket(bk, mask, p, v, hardness):
    """The interval of the approach (:func:`bem.plastic.plastic_approach`) where every contact node is plastic,
    else None; ``v = C p + w(p) + h``."""
    xp = bk.xp
    plastic = mask & (p >= hardness)
    if bool(xp.any(mask & (p > 0) & ~plastic)) or not bool(xp.any(plastic)):
        return None
    open_ = mask & (p <= 0)
    return float(xp.max(v[plastic])), float(xp.min(v[open_])) if bool(xp.any(open_)) else math.inf


class _ApproachFailed(Exception):
    pass


def _force_by_approach(op, h, layer, force, failed, *, rtol, **kw):
    """Force control as a root of ``P(delta) = force`` over approach-controlled solves.

    The fallback when Newton under force control stops short (seen only with power laws of
    ``s`` near 0 and a dominating layer, where nodal pressures span tens of decades): the force
    is monotone in the approach, and approach control has no force constraint coupling the
    nodes. Brent's method on ``delta``, each evaluation an approach-controlled Newton solve.
    Returns ``failed`` unchanged if an inner solve fails.
    """
    a = op.lattice.node_area
    solved = {}

    def excess(delta):  # a cold start each time: warm starts across a steep P(delta) stall
        sol = solve_newton(op, h, layer=layer, approach=delta, rtol=rtol, **kw)
        if not sol.converged:
            raise _ApproachFailed(sol.message)
        solved[delta] = sol
        return a * float(backend_of(sol.p).xp.sum(sol.p)) / force - 1.0

    delta = failed.approach
    try:
        f0 = excess(delta)
        step, other = 1e-3, None
        for _ in range(60):
            trial = delta * (1 + step) if f0 < 0 else delta / (1 + step)
            if (f_other := excess(trial)) * f0 <= 0:
                other = trial
                break
            step *= 2
        if other is None:
            return failed
        root = brent_root(excess, delta, other, f0, f_other, xtol=4 * np.finfo(float).eps * delta,
                          rtol=4 * np.finfo(float).eps, maxiter=200)
        if root not in solved:
            excess(root)
    except _ApproachFailed:
        return failed
    sol = solved[root]
    u = op.matvec(sol.p)
    _, delta_f, kkt = layered_state(op, h, layer, sol.p, u, force=force, hardness=kw.get("hardness"))
    steps = sum(s.iterations for s in solved.values())
    hist = dict(failed.history, outer_approaches=sorted(solved))
    converged = kkt <= rtol
    message = (f"KKT residual {kkt:.2e} {'<=' if converged else '>'} rtol {rtol:.1e}: force control by "
               f"{len(solved)} approach-controlled solves ({steps} Newton steps) after '{failed.message}'")
    return QPSolution(p=sol.p, approach=delta_f, iterations=failed.iterations + steps, converged=converged,
                      message=message, status="converged" if converged else failed.status, kkt_residual=float(kkt),
                      displacement=u, history=hist)
