"""The paper's two iterative methods for a nonlinear layer (section 5).

Both reduce the structurally and physically nonlinear problem (eq. 14) to a
sequence of Kalker QPs (eq. 11, 13), each solved by the operator's own
constrained-CG step (``op.qp``: :func:`bem.kalker.solve_qp` on a half-space region,
:func:`bem.periodic.qp.solve_periodic_qp` on a periodic cell):

* augmented gap method (eq. 17-20): the layer closure of the previous iterate
  is added to the gap, ``h_bar = h + w(p_k)``, and the smooth-body QP is solved
  again; optional relaxation ``p_{k+1} = (1 - omega) p_k + omega p_QP``;
* variable compliance coefficients (eq. 21-23): the layer is replaced by a
  linear Winkler layer of per-node compliance ``lam_n = w(p_n) / p_n`` (the
  secant), i.e. the matrix ``C + diag(lam)`` changes and the gap stays.

They are fixed-point iterations: they converge where the map is a
contraction and may stall or diverge elsewhere. Each says so in its result:
``converged`` is True only if the paper's stopping rule is met AND the KKT
residual of the final state is at most ``rtol`` (the same tolerance as every
other solver), so a stalled iteration is never reported as a solution.

Where they can converge at all (the linearisation of the map at the solution,
in the layer-dominated limit ``C -> 0`` of a power law ``w = lam p^s``):

* augmented gap: the map is ``p -> K^-1(h + w(p))`` with derivative
  ``-C^-1 diag(w')``; it contracts only when the layer is stiffer than the
  bodies (``w' < C_nn`` roughly), never in the layer-dominated limit;
* variable compliance: at a node ``p_{k+1} = (delta - h) / (lam p_k^(s-1))``,
  derivative ``-(s - 1)``: it contracts for ``0 < s < 2`` only. For ``s >= 2``
  the iteration oscillates with a growing or constant amplitude once the layer
  dominates, and stalls or diverges (reported).
"""

from __future__ import annotations

import logging
import math

import numpy as np

from .backend import backend_of, operator_backend
from .cg_rules import QPSolution
from .kkt import layered_state
from .layers.device import device_layer

__all__ = ["solve_augmented_gap", "solve_variable_compliance"]

log = logging.getLogger(__name__)

_DIVERGING_STEPS = 8  # increments growing this many times in a row = diverging
_STALL_STEPS = 15  # no new smallest increment for this many iterations = stalled


def _increment(new, old):
    norm = backend_of(new).norm
    size = norm(new)
    return norm(new - old) / size if size > 0 else norm(new - old)


class _Tracker:
    """History, divergence watch and the final verdict shared by both methods."""

    def __init__(self, op, h, layer, force, approach, record):
        self.op, self.h, self.layer, self.force, self.approach = op, h, layer, force, approach
        self.backend, self.mask = operator_backend(op)
        self.hist = {"residual": [], "p_max": [], "n_contact": [], "changes": [], "increment_p": [],
                     "increment_h": [], "inner_iterations": [], "inner_missed": 0, "inner_worst": 0.0}
        if record:
            self.hist["p"] = []
        self.growing = 0
        self.best, self.since_best = np.inf, 0

    def count_inner(self, sub):
        if not sub.converged:
            self.hist["inner_missed"] += 1
            self.hist["inner_worst"] = max(self.hist["inner_worst"], float(sub.kkt_residual))

    def record(self, p, u, prev_contact, inc_p, inc_h, inner):
        gap, delta, kkt = layered_state(self.op, self.h, self.layer, p, u, force=self.force,
                                        approach=self.approach)
        contact = p > 0
        h = self.hist
        if h["increment_p"] and inc_p > h["increment_p"][-1]:
            self.growing += 1
        else:
            self.growing = 0
        if inc_p < 0.9 * self.best:
            self.best, self.since_best = inc_p, 0
        else:
            self.since_best += 1
        xp = self.backend.xp
        for key, val in (("residual", kkt), ("p_max", float(xp.max(p))), ("n_contact", int(xp.count_nonzero(contact))),
                         ("changes", int(xp.count_nonzero(contact != prev_contact))), ("increment_p", inc_p),
                         ("increment_h", inc_h), ("inner_iterations", inner)):
            h[key].append(val)
        if "p" in h:
            h["p"].append(self.backend.to_host(p[self.mask]).copy())
        return delta, kkt

    def failing(self):
        """``(status, reason)`` when the iteration is hopeless, else ``None``."""
        if self.growing >= _DIVERGING_STEPS:
            return "diverged", f"diverging: the pressure increment grew {_DIVERGING_STEPS} times in a row"
        if self.since_best >= _STALL_STEPS:
            return "stalled", (f"stalled: the pressure increment did not fall below 0.9 x its best value "
                    f"{self.best:.2e} in {_STALL_STEPS} iterations")
        return None

    def finish(self, name, p, u, delta, kkt, rule_met, reason, rtol, status):
        converged = bool(rule_met and kkt <= rtol)
        status = "converged" if converged else status
        message = f"{reason}; KKT residual {kkt:.2e}" if converged else f"{reason} (KKT residual {kkt:.2e})"
        if not converged:
            log.debug("%s: %s", name, message)
        return QPSolution(p=p, approach=delta, iterations=len(self.hist["residual"]), converged=converged,
                          message=message, status=status, kkt_residual=float(kkt), displacement=u, history=self.hist)


def solve_augmented_gap(op, h, *, layer, force=None, approach=None, x0=None, rtol=1e-10, eps_h=None,
                        eps_p=None, maxiter=300, relaxation=1.0, precondition=True,
                        callback=None, record=False):
    """Augmented gap method (eq. 17-20).

    Iterates ``h_bar_k = h + w(p_k)``, ``(p_{k+1}, delta_{k+1}) = K^-1 (h_bar_k, P)``
    from ``p_0 = 0`` (eq. 19), with optional relaxation ``omega``.

    Parameters
    ----------
    op, h, layer, force, approach, x0, precondition, callback, record
        As for :func:`bem.newton.solve_newton`.
    rtol : float
        KKT residual required of the result (:func:`bem.kkt.kkt_residual`); the
        inner QPs are solved to ``rtol / 10``.
    eps_h, eps_p : float, optional
        Limits of the increments of eq. 20 (default ``rtol``).
    maxiter : int
        Iteration limit.
    relaxation : float
        ``omega`` in ``(0, 1]``; 1 is the paper's method.

    Returns
    -------
    bem.cg_rules.QPSolution

    Notes
    -----
    Stopping rule (eq. 20), Euclidean norms over the nodes:

    ``||dh_k - dh_{k-1}|| / ||dh_k|| <= eps_h`` and ``||p_k - p_{k-1}|| / ||p_k|| <= eps_p``

    with ``dh_k = w(p_k)``, and the KKT residual ``<= rtol``. The iteration is declared diverging when the
    pressure increment grows 8 times in a row, and stalled when it has not
    fallen below 0.9 times its smallest value for 15 iterations.
    """
    eps_h = rtol if eps_h is None else eps_h
    eps_p = rtol if eps_p is None else eps_p
    bk, mask = operator_backend(op)
    xp = bk.xp
    layer = device_layer(layer, bk)
    h = xp.where(mask, bk.asarray(h), 0.0)
    track = _Tracker(op, h, layer, force, approach, record)
    p = xp.zeros(op.lattice.shape, dtype=bk.float64) if x0 is None else xp.where(mask, xp.maximum(bk.asarray(x0), 0.0), 0.0)
    u = op.matvec(p)
    dh_old = xp.where(mask, layer.w(p), 0.0)
    delta, kkt, rule_met, status = approach, np.inf, False, "maxiter"
    reason = f"no convergence in maxiter = {maxiter} iterations"
    for k in range(1, maxiter + 1):
        dh = xp.where(mask, layer.w(p), 0.0)
        sub = op.qp(h + dh, force=force, approach=approach, x0=p if bool(xp.any(p != 0)) else None,
                    rtol=rtol / 10, precondition=precondition)
        track.count_inner(sub)
        omega = relaxation if k > 1 else 1.0
        p_new = (1 - omega) * p + omega * sub.p
        if not bool(xp.all(xp.isfinite(p_new))):
            status, reason = "diverged", f"diverged: non-finite pressure at iteration {k}; the last finite iterate is returned"
            break
        u = (1 - omega) * u + omega * sub.displacement
        inc_p, inc_h = _increment(p_new, p), _increment(dh, dh_old) if k > 1 else 1.0
        prev_contact = p > 0
        p, dh_old = p_new, dh
        delta, kkt = track.record(p, u, prev_contact, inc_p, inc_h, sub.iterations)
        if callback is not None:
            callback(k, p)
        if not math.isfinite(kkt):
            status, reason = "nonfinite", "the iteration produced a non-finite value"
            break
        if k > 1 and inc_h <= eps_h and inc_p <= eps_p and kkt <= rtol:
            rule_met, reason = True, f"increments of eq. 20 below eps after {k} iterations"
            break
        if track.failing():
            status, reason = track.failing()
            reason += " (try relaxation < 1)"
            break
    return track.finish("augmented gap", p, u, delta, kkt, rule_met, reason, rtol, status)


def solve_variable_compliance(op, h, *, layer, force=None, approach=None, x0=None, rtol=1e-10,
                              eps_p=None, maxiter=300, precondition=True, callback=None,
                              record=False):
    """Variable compliance coefficients (eq. 21-23).

    Starts from ``C_bar_0 = C`` (the smooth-body solution) and iterates
    ``C_bar_k = C + diag(lam_k)``, ``lam_k = w(p_k) / p_k``,
    ``(p_{k+1}, delta_{k+1}) = K(C_bar_k)^-1 (h, P)``.

    At a node without pressure the paper's secant ``w(p)/p`` is ``w'(0)``,
    which is infinite for the root and power (``s < 1``) laws and would bar the
    node from ever entering the contact. There (and only there) this
    implementation uses the secant at the mean contact pressure of the current
    iterate, so the contact can grow; where ``w'(0)`` is finite it is used as the
    paper states.

    Parameters
    ----------
    op, h, layer, force, approach, x0, precondition, callback, record
        As for :func:`bem.newton.solve_newton`.
    rtol : float
        KKT residual required of the result; the inner QPs are solved to ``rtol / 10``.
    eps_p : float, optional
        Limit of the pressure increment (default ``rtol``).
    maxiter : int
        Iteration limit.

    Returns
    -------
    bem.cg_rules.QPSolution

    Notes
    -----
    Stopping rule (eq. 23 and the pressure increment of eq. 20):
    ``J_k = J_{k-1}`` (same contact set), ``||p_k - p_{k-1}|| / ||p_k|| <= eps_p`` and the
    KKT residual ``<= rtol``. Under force control the first, layer-free step may collapse
    onto a few nodes when the layer dominates (the layer-free contact is smaller than a
    step); the next QP lets the contact grow again from there.
    """
    eps_p = rtol if eps_p is None else eps_p
    bk, mask = operator_backend(op)
    xp = bk.xp
    layer = device_layer(layer, bk)
    h = xp.where(mask, bk.asarray(h), 0.0)
    track = _Tracker(op, h, layer, force, approach, record)
    p = None if x0 is None else xp.where(mask, xp.maximum(bk.asarray(x0), 0.0), 0.0)
    u = xp.zeros(op.lattice.shape, dtype=bk.float64) if p is None else op.matvec(p)
    lam = xp.zeros(op.lattice.shape, dtype=bk.float64)
    delta, kkt, rule_met, status = approach, np.inf, False, "maxiter"
    reason = f"no convergence in maxiter = {maxiter} iterations"
    for k in range(1, maxiter + 1):
        contact = xp.zeros(op.lattice.shape, dtype=xp.bool) if p is None else p > 0
        if p is not None:
            p_ref = float(xp.mean(p[contact])) if bool(xp.any(contact)) else 1.0
            with bk.errstate(divide="ignore", invalid="ignore"):
                lam = xp.where(contact, layer.secant(p), layer.secant(xp.zeros_like(p)))
            lam = xp.where(xp.isfinite(lam), lam, float(layer.secant(p_ref)))
            lam = xp.where(mask, lam, 0.0)
        sub = op.qp(h, force=force, approach=approach, lam=lam, x0=p, rtol=rtol / 10, precondition=precondition,
                    contact=contact)
        track.count_inner(sub)
        p_new = sub.p
        if not bool(xp.all(xp.isfinite(p_new))):
            status, reason = "diverged", f"diverged: non-finite pressure at iteration {k}; the last finite iterate is returned"
            break
        u = sub.displacement
        inc_p = 1.0 if p is None else _increment(p_new, p)
        same_set = p is not None and not bool(xp.any((p_new > 0) != contact))
        p = p_new
        delta, kkt = track.record(p, u, contact, inc_p, np.nan, sub.iterations)
        if callback is not None:
            callback(k, p)
        if not math.isfinite(kkt):
            status, reason = "nonfinite", "the iteration produced a non-finite value"
            break
        if same_set and inc_p <= eps_p and kkt <= rtol:
            rule_met, reason = True, f"contact set and pressure stable after {k} iterations"
            break
        if track.failing():
            status, reason = track.failing()
            break
    return track.finish("variable compliance", p, u, delta, kkt, rule_met, reason, rtol, status)
