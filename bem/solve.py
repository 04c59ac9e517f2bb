"""The public entry point :func:`solve` of the half-space BEM."""

from __future__ import annotations

import logging
import time

import numpy as np

from .backend import get_backend, to_host
from .checks import (check_bool, check_callable, check_choice, check_finite_array, check_gap_values, check_int,
                     check_layer, check_load, check_rtol, check_scale)
from .errors import InputError, RegionTooSmallError
from .kalker import QPSolution
from .kkt import kkt_residual
from .lattice import Lattice
from .layers import beyond_table
from .materials import effective_modulus
from .operator import InfluenceOperator
from .options import METHODS, check_options, solver_for
from .result import ContactResult

__all__ = ["solve"]

log = logging.getLogger(__name__)

_COARSEST_NODES = 4096  # nested iteration stops coarsening below this many nodes


def _modulus(E_star, E1, nu1, E2, nu2):
    given = [v is not None for v in (E1, nu1, E2, nu2)]
    if E_star is not None:
        if any(given):
            raise InputError("E_star is not allowed together with E1, nu1, E2, nu2: give one or the other.")
        return check_scale("E_star", E_star)
    if not all(given):
        raise InputError("E_star = None is not allowed without all of E1, nu1, E2, nu2: give E_star or all four.")
    return effective_modulus(E1, nu1, E2, nu2)


def _levels(lattice, nested):
    """Lattices from coarsest to finest for nested iteration."""
    levels = [lattice]
    while nested:
        coarse = levels[-1].coarsen()
        if coarse is None or coarse.n_nodes < _COARSEST_NODES:
            break
        levels.append(coarse)
    return levels[::-1]


def solve(gap, *, E_star=None, E1=None, nu1=None, E2=None, nu2=None, force=None, approach=None,
          step, extent, layer=None, method="newton", rtol=1e-10, maxiter=None, x0=None,
          nested=None, precondition=True, callback=None, device="cpu", **options):
    """Frictionless normal contact of two elastic half-spaces with an interface layer.

    Minimises the generalised Kalker functional (eq. 11, 15)
    ``Phi(p) = a [1/2 p.C p + p.(h - delta)] + a sum W(p_n)`` over ``p >= 0``,
    ``a = sqrt(3)/2 c^2``, on the triangular lattice of step ``c``.

    Parameters
    ----------
    gap : callable
        Initial gap ``h(x, y)`` [length] (a :mod:`bem.gaps` shape or any vectorised callable).
    E_star : float, optional
        Effective modulus [pressure]; or give ``E1, nu1, E2, nu2`` instead.
    force, approach : float
        Exactly one: total force ``P`` [force] (force control, eq. 9) or the
        approach ``delta`` [length] (approach control).
    step : float
        Lattice step ``c`` [length].
    extent : float or (float, float)
        Half-width of the rectangular candidate region [length]; the region holds at most
        :data:`bem.checks.MAX_NODES` nodes (a memory guard, checked before anything is built).
        A gap with a ``check_region(extent)`` method (a measured surface's table,
        :meth:`bem.gaps.Measured.region`) refuses a region beyond its data.
    layer : bem.layers.Layer, optional
        Interface layer law ``w(p)``; ``None`` for smooth bodies.
    method : {"newton", "augmented_gap", "variable_compliance", "kalker"}
        ``"newton"`` (default): direct minimisation of eq. 15
        (:func:`bem.newton.solve_newton`); ``"augmented_gap"`` (eq. 17-20) and
        ``"variable_compliance"`` (eq. 21-23): the paper's methods
        (:mod:`bem.fixed_point`); ``"kalker"``: the QP of eq. 11/13
        (:func:`bem.kalker.solve_qp`), smooth or linear layer only. Without a
        layer, and for ``"newton"`` with a linear layer, the functional is
        quadratic and the QP is solved directly (:func:`solver_for`);
        ``result.method`` names the solver that ran, and an info message is logged when a
        paper method is asked for such a problem.
    rtol : float
        Tolerance on the KKT residual ``r`` (:func:`bem.kkt.kkt_residual`) of the
        returned state, the same for every method: ``converged`` means ``r <= rtol``.
        ``r`` is relative (gap violations over the largest ``|C p + w(p)|``, force balance
        over ``P``), so ``rtol`` lies in ``(0, 1e-2]`` (:data:`bem.checks.RTOL_MAX`).
    maxiter : int, optional
        Iteration limit of the solver that runs (CG iterations of the QP, Newton steps,
        outer iterations of the paper's methods).
    x0 : ndarray, optional
        Initial nodal pressures on the candidate nodes, shape ``(N,)``.
    nested : bool, optional
        Start from the solution on successively coarser lattices (step ``2c``,
        ``4c``, ...) interpolated onto the finer one. Each finer level is solved on
        the rectangular window of the nodes whose initial gap is below the approach
        (of the coarser level, with a margin): the others cannot close. Its solution
        is checked against the final approach, and the level solved again on the whole
        lattice if a node outside the window could close. Default: on for
        ``"newton"`` and the QP, off for the paper's methods so that their
        iteration histories start as in the paper.
    precondition : bool
        Use the FFT (and, with a layer, block-Jacobi) preconditioner in the conjugate
        gradients.
    callback : callable, optional
        ``callback(k, p_grid)`` after every iteration on the finest lattice; ``p_grid`` is a
        brick array in the namespace of ``device``.
    device : {"cpu", "cuda"} or module
        Where the arrays live and the FFTs run (:mod:`bem.backend`): ``"cpu"`` (NumPy,
        ``scipy.fft`` on :func:`bem.fft.threads` threads), ``"cuda"`` (CuPy and cuFFT, the
        ``gpu`` extra), or an array API standard namespace. The iterations keep their arrays
        on the device; the result's arrays are NumPy arrays on the host for every device.
        Layer laws other than the closed forms of :mod:`bem.layers.analytic` are evaluated
        on the host (:func:`bem.layers.device.device_layer`).
    **options
        Options of one solver, refused (:class:`bem.InputError`) where they do not apply
        to the solver that runs (:data:`OPTIONS`): ``record`` (keep every iterate in
        ``history["p"]``; Newton and the paper's methods), ``inner_maxiter`` (Newton),
        ``relaxation`` in ``(0, 1]`` (augmented gap), ``eps_h``, ``eps_p`` (the
        increments of eq. 20; augmented gap, and ``eps_p`` for variable compliance).

    Returns
    -------
    ContactResult

    Raises
    ------
    bem.InputError
        Bad input (the message names the argument).
    RegionTooSmallError
        The contact reaches the border of the candidate region.

    Notes
    -----
    Stopping rules, with ``r_k`` the KKT residual of iterate ``k`` (relative to the
    largest surface closure ``max |C p + w(p)|``; force balance relative to ``P``):

    - Kalker's QP: ``r_k <= rtol``, checked on an exactly recomputed ``C p``.
    - Newton: ``r_k <= rtol`` on an exact product; each inner QP is solved to
      ``max(rtol / 3, min(1e-2, eta_k r_k))``, ``eta_k = min(0.3, r_k / r_(k-1))``.
    - Augmented gap: the increments of eq. 20,
      ``||w(p_k) - w(p_{k-1})|| / ||w(p_k)|| <= eps_h`` and
      ``||p_k - p_{k-1}|| / ||p_k|| <= eps_p``, AND ``r_k <= rtol``.
    - Variable compliance: the same contact set twice (eq. 23) and
      ``||p_k - p_{k-1}|| / ||p_k|| <= eps_p``, AND ``r_k <= rtol``.

    ``eps_h`` and ``eps_p`` default to ``rtol``. A paper method that stalls (no 10 %
    smaller increment in 15 iterations) or diverges (8 growing increments) stops and
    says so. A result that does not meet its rule has ``converged = False`` and the
    reason in ``message``, and one warning is logged (with a summary of inner solves
    that missed their tolerance); a converged run logs no warning, except one whose peak
    pressure exceeds the last pressure of a tabulated layer law
    (:func:`bem.layers.beyond_table`: the law is continued beyond its data).
    """
    t_start = time.perf_counter()
    check_callable("gap", gap)
    E_star = _modulus(E_star, E1, nu1, E2, nu2)
    force, approach = check_load(force, approach)
    check_choice("method", method, METHODS)
    rtol = check_rtol("rtol", rtol)
    if maxiter is not None:
        maxiter = check_int("maxiter", maxiter)
    precondition = check_bool("precondition", precondition)
    if nested is not None:
        nested = check_bool("nested", nested)
    if callback is not None:
        check_callable("callback", callback)
    backend = get_backend(device)
    lattice = Lattice.from_extent(step, extent)
    if hasattr(gap, "check_region"):  # a gap known on a bounded region only (bem.gaps.RegionTable)
        gap.check_region(extent)
    _check_layer(layer, method)
    solver = solver_for(method, layer)
    options = check_options(method, solver, options)
    if nested is None:
        nested = solver in ("kalker", "newton")
    guess = None
    if solver != method and method != "newton":  # a paper method asked for a quadratic problem
        log.info("method = %r runs as Kalker's QP (result.method = %r): %s, so the functional is quadratic",
                 method, solver, "there is no layer" if layer is None else "the layer is linear")
    if x0 is not None:
        x0 = check_finite_array("x0", x0, ndim=1)
        if x0.shape != (lattice.n_nodes,):
            raise InputError(f"x0 has shape {x0.shape} which is not allowed: it must be ({lattice.n_nodes},).")
        guess = np.zeros(lattice.shape)
        guess[lattice.mask] = x0
        nested = False
    levels = _levels(lattice, nested)
    delta = approach  # the approach, or under force control its estimate from the coarser level
    for level, lat in enumerate(levels):
        finest = level == len(levels) - 1
        h = _gap_values(gap, lat)
        kw = dict(force=force, approach=approach, x0=guess, rtol=rtol if finest else max(rtol, 1e-6),
                  callback=callback if finest else None)
        if maxiter is not None:
            kw["maxiter"] = maxiter
        window = _candidate_window(lat, h, delta) if nested else None
        sol, ops = _run_level(solver, lat, E_star, h, layer, precondition, kw, options, window, backend)
        delta = sol.approach
        if not finest:
            guess = _prolong(lat, sol.p, levels[level + 1])
    _check_border(lattice, sol.p, extent)
    op = ops[-1] if ops[-1].lattice is lattice else InfluenceOperator(lattice, E_star, device=backend)
    closure = np.zeros(lattice.shape) if layer is None else np.where(lattice.mask, layer.w(sol.p), 0.0)
    result = _result(lattice, op, h, sol, closure, E_star, layer, solver, force, t_start, rtol,
                     n_matvec=sum(o.n_matvec for o in ops if o is not op))
    if not result.converged:
        log.warning("%s: %s%s", solver, result.message, _inner_summary(sol.history))
    elif (note := beyond_table(layer, result.p_max)) is not None:
        log.warning("%s", note)
    return result


def _inner_summary(history):
    missed = history.get("inner_missed", 0)
    if not missed:
        return ""
    return (f" ({missed} inner QP solve(s) stopped before their tolerance; worst KKT residual "
            f"{history['inner_worst']:.2e})")


def _run(solver, op, h, layer, precondition, kw, options):
    """Dispatch one lattice level to the solver; the solution's arrays come back on the host."""
    sol = _dispatch(solver, op, h, layer, precondition, kw, options)
    if op.backend.is_numpy:
        return sol
    hist = dict(sol.history)
    return QPSolution(p=to_host(sol.p), approach=float(sol.approach), iterations=sol.iterations,
                      converged=sol.converged, message=sol.message, status=sol.status, kkt_residual=sol.kkt_residual,
                      displacement=to_host(sol.displacement), history=hist)


def _dispatch(solver, op, h, layer, precondition, kw, options):
    from .fixed_point import solve_augmented_gap, solve_variable_compliance
    from .kalker import solve_qp
    from .newton import solve_newton

    if solver == "kalker":
        lam = 0.0 if layer is None else layer.lam
        precond = op.preconditioner(lam=lam) if precondition else None
        return solve_qp(op, h, lam=lam, preconditioner=precond, **kw, **options)
    run = {"newton": solve_newton, "augmented_gap": solve_augmented_gap,
           "variable_compliance": solve_variable_compliance}[solver]
    return run(op, h, layer=layer, precondition=precondition, **kw, **options)


# Candidate windows. C p >= 0 and w(p) >= 0 for p >= 0, so the deformed gap of a node is
# g_n >= h_n - delta: a node with h_n >= delta carries no pressure at the solution, whatever the
# others do. Nested iteration knows delta (the approach, or under force control its value on the
# coarser level), and each finer level is solved on the window of the brick array that holds
# the nodes with h_n < delta + _WINDOW_MARGIN (delta - min h), padded by _WINDOW_PAD nodes; the
# window's solution is the full one when every node outside it has h_n >= delta of that
# solution, which is checked (otherwise the level is solved again on the full lattice from the
# window's solution). Measured on the 1,048,703-node problem of benchmarks/side_by_side.py (root layer; the window
# holds 16 % of the nodes), same process, alternating, load 1.1: 1.23 s against 2.89 s on the full
# lattice; Hertz 0.88 s against 1.18 s. The full lattice still gets one product, for the result.
_WINDOW_MARGIN = 0.25
_WINDOW_PAD = 2
_WINDOW_UP_TO = 0.6  # a window with more than this fraction of the brick array is not worth it


def _candidate_window(lat, h, delta):
    """The window of ``lat`` holding the nodes whose gap may close near the approach ``delta``, or None."""
    if delta is None or not np.isfinite(delta):
        return None
    mask = lat.mask
    h_min = float(np.min(h, where=mask, initial=np.inf))
    if not delta > h_min:
        return None
    near = mask & (h < delta + _WINDOW_MARGIN * (delta - h_min))
    rows, cols = np.flatnonzero(near.any(axis=1)), np.flatnonzero(near.any(axis=0))
    (n_rows, n_cols), pad = lat.shape, _WINDOW_PAD
    r0, r1 = max(int(rows[0]) - pad, 0), min(int(rows[-1]) + 1 + pad, n_rows)
    c0, c1 = max(int(cols[0]) - pad, 0), min(int(cols[-1]) + 1 + pad, n_cols)
    if r1 - r0 < 4 or (r1 - r0) * (c1 - c0) > _WINDOW_UP_TO * n_rows * n_cols:
        return None
    return lat.window((r0, r1), (c0, c1))


def _clear_outside(lat, window, h, delta):
    """Whether every node of ``lat`` outside ``window`` has ``h >= delta`` (then ``g >= 0`` there at ``p = 0``)."""
    outside = lat.mask.copy()
    outside[window.index] = False
    return bool(np.isfinite(delta)) and float(np.min(h, where=outside, initial=np.inf)) >= delta


def _embedded(sol, window):
    """A window's solution as one of its parent lattice (``displacement`` is not carried over)."""
    hist = dict(sol.history)
    if "p" in hist:  # recorded iterates: candidate nodes of the window -> of the parent
        full = np.zeros(window.shape)
        parent = window.parent

        def lift(v):
            full[window.mask] = v
            return window.embed(full)[parent.mask]

        hist["p"] = [lift(v) for v in hist["p"]]
    return QPSolution(p=window.embed(sol.p), approach=sol.approach, iterations=sol.iterations,
                      converged=sol.converged, message=sol.message, status=sol.status, kkt_residual=sol.kkt_residual,
                      displacement=None, history=hist)


def _run_level(solver, lat, E_star, h, layer, precondition, kw, options, window, backend):
    """Solve one lattice level, on ``window`` where given; returns the solution and the operators used."""
    ops = []
    if window is not None:
        op = InfluenceOperator(window, E_star, device=backend)
        ops.append(op)
        kw_w = dict(kw, x0=None if kw["x0"] is None else kw["x0"][window.index])
        if kw["callback"] is not None:
            kw_w["callback"] = lambda k, p, cb=kw["callback"]: cb(k, window.embed(p))
        if solver == "kalker" and "maxiter" not in kw:  # the QP's default limit of the full lattice
            kw_w["maxiter"] = max(200, int(10 * np.sqrt(lat.n_nodes)))
        sol = _embedded(_run(solver, op, h[window.index], layer, precondition, kw_w, options), window)
        if _clear_outside(lat, window, h, sol.approach):
            return sol, ops
        # rare: the approach grew past the margin. The full lattice starts from the window's
        # solution; the result reports that solve's iterations.
        log.debug("candidate window too small (approach %.6g): solving on the full lattice", sol.approach)
        kw = dict(kw, x0=sol.p)
    op = InfluenceOperator(lat, E_star, device=backend)
    ops.append(op)
    return _run(solver, op, h, layer, precondition, kw, options), ops


def _prolong(coarse, p, fine):
    return coarse.prolong(p, fine)  # = coarse.interpolate(p, fine.x, fine.y) * fine.mask, 5-20x faster


def _check_layer(layer, method):
    if check_layer("layer", layer) is None:
        return
    if method == "kalker" and not layer.is_linear:
        raise InputError(
            f"method = 'kalker' is not allowed with layer = {layer!r}: Kalker's QP solves smooth bodies "
            "and linear layers only; use method='newton' (or a paper method) for a nonlinear layer."
        )


def _gap_values(gap, lattice):
    x, y = lattice.x, lattice.y
    h = check_gap_values(gap(x, y), {"x": x, "y": y}, mask=lattice.mask,
                         region="over the candidate region (make extent smaller or fix the gap)")
    return np.where(lattice.mask, h, 0.0)


def _check_border(lattice, p, extent):
    touching = lattice.border & (p > 0)
    if touching.any():
        n = int(touching.sum())
        raise RegionTooSmallError(
            f"extent = {extent!r} is not allowed for this load: the contact reaches the border of the "
            f"candidate region at {n} node(s). Make extent larger (the contact must stay inside it) "
            "or reduce the load. For a rough surface patch whose contact spreads over the whole region, "
            "the model is a periodic cell: bem.solve_periodic."
        )


def _result(lattice, op, h, sol, closure, E_star, layer, method, force, t_start, rtol, n_matvec=0):
    mask = lattice.mask
    p = sol.p
    u = to_host(op.matvec(p))
    g = u + closure + h - sol.approach
    a = lattice.node_area
    kkt = kkt_residual(p[mask], g[mask], displacement_scale=float(np.abs(u + closure).max()),
                       force=force, node_area=a)
    if not np.all(np.isfinite(p)):
        raise FloatingPointError(f"{method}: the solver produced non-finite pressures ({sol.message})")
    return ContactResult(
        x=lattice.x[mask], y=lattice.y[mask], p=p[mask], displacement=u[mask],
        closure=closure[mask], gap=g[mask],
        approach=float(sol.approach), force=float(a * p.sum()), p_max=float(p.max()),
        contact_area=float(a * np.count_nonzero(p[mask] > 0)), converged=bool(sol.converged),
        message=sol.message, status=sol.status, rtol=float(rtol), iterations=int(sol.iterations), kkt_residual=float(kkt), method=method,
        wall_time_s=time.perf_counter() - t_start, lattice=lattice, E_star=E_star,
        history=sol.history, layer=layer, n_matvec=n_matvec + op.n_matvec,
    )
