"""Newton's method for the condensed interface problem (approach or force control).

After static condensation (:mod:`fem_reference.model`) the unknowns are the overlaps
``g`` of the ``n`` interface node pairs (and the approach ``delta`` under force
control). With the interface compliance ``C`` [length/force], the lumped ring areas
``A`` [length^2] and the initial gap ``h`` at the nodes, equilibrium of the penalised FEM
model reads::

    F1(g, delta) = g + C (A * p(g)) + h - delta = 0        [length]
    F2(g)        = sum(A * p(g)) - P = 0                    [force]   (force control)

(the elastic part of the approach ``d = delta - h - g`` equals ``C f`` with the nodal
forces ``f = A p``). They are the stationarity conditions of the convex functional::

    Pi(g, delta) = 1/2 d^T C^{-1} d + sum(A * Psi(g)) - P delta

(``Psi`` from :class:`fem_reference.interface.InterfaceLaw`; the ``P delta`` term only
under force control). Newton's step solves ``J dx = -F`` with the consistent tangent
``J = [[I + C diag(A p'(g)), -1], [(A p'(g))^T, 0]]`` (dense, ``n + 1`` unknowns);
``J = C H`` with the Hessian ``H`` of ``Pi``, so the step is a descent direction of
``Pi`` and a backtracking (Armijo) line search on ``Pi`` globalises the iteration: no
load steps are needed.

Stopping rule (checked before every step)::

    max|F1| <= rtol * max(|delta|, max|d|)   and   |F2| <= rtol * P   (force control)
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import LinAlgError, cho_factor, cho_solve, solve

__all__ = ["InterfaceSolution", "solve_interface"]

log = logging.getLogger(__name__)

_ARMIJO = 1e-4
_MIN_STEP = 2.0**-40


@dataclass
class InterfaceSolution:
    """State of the condensed problem after Newton's method.

    Attributes
    ----------
    g, p : ndarray, shape (n,)
        Overlaps [length] and pressures [pressure] at the interface pairs.
    delta : float
        Approach [length] (the ``delta`` of ``C``'s frame; see :func:`solve_interface`).
    converged : bool
        Whether the stopping rule was met.
    message : str
        Why the iteration stopped.
    status : str
        The outcome, one of :data:`fem_reference.result.STATUSES`.
    iterations : int
        Newton steps taken.
    history : dict
        Per-iteration ``residual`` (``max|F1| / scale``), ``force_residual``, ``step`` (line
        search factor) and ``n_contact`` (node pairs with ``g > 0``).
    """

    g: np.ndarray
    p: np.ndarray
    delta: float
    converged: bool
    message: str
    iterations: int
    status: str
    history: dict = field(default_factory=dict)


def solve_interface(C, A, h, law, *, force=None, approach=None, delta0=None, g0=None, rtol=1e-9,
                    maxiter=60):
    """Solve the condensed interface equations by Newton's method with a line search.

    Parameters
    ----------
    C : ndarray, shape (n, n)
        Symmetric positive definite interface compliance [length/force].
    A : ndarray, shape (n,)
        Lumped ring areas of the interface nodes [length^2].
    h : ndarray, shape (n,)
        Initial gap at the interface nodes [length].
    law : fem_reference.interface.InterfaceLaw
        Traction law ``p(g)``.
    force, approach : float
        Exactly one: total force ``P`` [force] or approach ``delta`` [length].
    delta0 : float, optional
        Starting approach under force control [length].
    g0 : ndarray, optional
        Starting overlaps [length]; default ``max(delta0 - h, 0)`` (rigid bodies).
    rtol : float
        Relative tolerance of the stopping rule (module docstring).
    maxiter : int
        Newton-step limit.

    Returns
    -------
    InterfaceSolution
    """
    n = h.size
    force_control = force is not None
    delta = float(delta0 if force_control else approach)
    g = np.maximum(delta - h, 0.0) if g0 is None else np.array(g0, dtype=float)
    history = {"residual": [], "force_residual": [], "step": [], "n_contact": []}
    try:
        cho = cho_factor(C)
    except LinAlgError:
        return InterfaceSolution(g=g, p=law.pressure(g), delta=delta, converged=False, iterations=0, status="singular",
                                 message="interface compliance is not positive definite (mesh too coarse "
                                        "for the truncation correction?)", history=history)

    def residuals(g, delta):
        p = law.pressure(g)
        F1 = g + C @ (A * p) + h - delta
        F2 = float(np.sum(A * p) - force) if force_control else 0.0
        return p, F1, F2

    def energy(g, delta):
        d = delta - h - g
        value = 0.5 * d @ cho_solve(cho, d) + float(np.sum(A * law.potential(g)))
        return value - force * delta if force_control else value

    converged, message, status, k = False, f"maxiter = {maxiter} Newton steps reached", "maxiter", 0
    p, F1, F2 = residuals(g, delta)
    for k in range(maxiter + 1):
        scale = max(abs(delta), float(np.abs(delta - h - g).max()), np.finfo(float).tiny)
        res = float(np.abs(F1).max()) / scale
        res_f = abs(F2) / force if force_control else 0.0
        history["residual"].append(res)
        history["force_residual"].append(res_f)
        history["n_contact"].append(int(np.count_nonzero(g > 0)))
        if not (np.isfinite(res) and np.isfinite(res_f)):
            message, status = "non-finite residual", "nonfinite"
            break
        if res <= rtol and res_f <= rtol:
            converged, message, status = True, "stopping rule met", "converged"
            break
        if k == maxiter:
            break
        AD = A * law.tangent(g)
        J = np.eye(n) + C * AD[None, :]
        rhs = -F1
        if force_control:
            J = np.block([[J, -np.ones((n, 1))], [AD[None, :], np.zeros((1, 1))]])
            rhs = np.append(rhs, -F2)
        try:
            dx = solve(J, rhs, check_finite=True)
        except (LinAlgError, ValueError) as exc:
            message, status = f"singular Newton matrix ({exc}); no node in contact?", "singular"
            break
        dg, dd = (dx[:n], float(dx[n])) if force_control else (dx, 0.0)
        grad_g = cho_solve(cho, F1)
        slope = float(grad_g @ dg) + ((F2 - float(np.sum(grad_g))) * dd if force_control else 0.0)
        e0 = energy(g, delta)
        t = 1.0
        while True:
            e1 = energy(g + t * dg, delta + t * dd)
            if e1 <= e0 + _ARMIJO * t * slope + 1e-12 * (abs(e0) + abs(slope)):
                break
            t *= 0.5
            if t < _MIN_STEP:
                break
        if t < _MIN_STEP:
            message, status = "line search failed (no descent along the Newton direction)", "stalled"
            break
        g, delta = g + t * dg, delta + t * dd
        history["step"].append(t)
        p, F1, F2 = residuals(g, delta)
    log.debug("interface Newton: %s after %d steps, residual %.3g", message, k, history["residual"][-1])
    return InterfaceSolution(g=g, p=law.pressure(g), delta=float(delta), converged=converged, message=message,
                             iterations=k, status=status, history=history)
