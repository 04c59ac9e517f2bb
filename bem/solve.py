"""The public entry point :func:`solve`: one driver over a domain (a half-space region or a periodic cell).

The driver checks the problem once (:mod:`bem.problem`), resolves the domain, and loops over the
domain's levels (nested iteration): each level is solved by the method's solver on the
domain's influence operator, its solution interpolated onto the next finer level. A growing
half-space region is enlarged when the contact reaches its border. The domain supplies the
lattice, the nodal gap, the levels, the operator, the level solve (on a candidate window of a
half-space region, :mod:`bem.windows`), the border check and the result class
(:class:`bem.HalfSpaceRegion`, :class:`bem.PeriodicCell`).
"""

from __future__ import annotations

import itertools
import logging
import time

import numpy as np

from .backend import to_host
from .errors import InputError, RegionTooSmallError
from .cg_rules import QPSolution
from .kkt import kkt_residual
from .layers import beyond_table
from .problem import check_problem, initial_guess
from .region import HalfSpaceRegion

__all__ = ["solve"]

log = logging.getLogger(__name__)


def solve(gap, *, E_star=None, E1=None, nu1=None, E2=None, nu2=None, coating1=None, coating2=None, force=None,
          approach=None, mean_pressure=None, domain=None, step=None, extent=None, layer=None, hardness=None,
          method="newton", rtol=1e-10, maxiter=None, x0=None, nested=None, precondition=True, callback=None,
          device="cpu", **options):
    """Frictionless normal contact of two elastic half-spaces with an interface layer, over a domain.

    Minimises the generalised Kalker functional (eq. 11, 15)
    ``Phi(p) = a [1/2 p.C p + p.(h - delta)] + a sum W(p_n)`` over ``p >= 0``,
    ``a = sqrt(3)/2 c^2``, on the triangular lattice of step ``c`` of the domain: a
    rectangular candidate region of the half-space (:class:`bem.HalfSpaceRegion`) or a
    periodic cell (:class:`bem.PeriodicCell`, a rough surface patch; every node may touch and
    the displacements have zero mean over the cell). The arguments are checked by one set of
    rules for both domains (:mod:`bem.problem`; docs/method.md, "Checks of bem.solve").

    Parameters
    ----------
    gap : callable or ndarray
        Initial gap [length]: a vectorised ``h(x, y)`` (a :mod:`bem.gaps` shape or any
        callable; on a cell it must be periodic, checked at the nodes), or, on a periodic
        cell, a brick array of the cell's shape (node ``(q, r)`` at
        ``x = (q + (r mod 2)/2) c``, ``y = r c sqrt3/2``).
    E_star : float, optional
        Effective modulus [pressure]; or give ``E1, nu1, E2, nu2`` instead.
    E1, nu1, E2, nu2 : float, optional
        Young's moduli [pressure] (``math.inf``: rigid) and Poisson's ratios [-] of the two
        bodies (of the substrates where a body is coated), instead of ``E_star``.
    coating1, coating2 : bem.Coating, optional
        A coating bonded to body 1 or 2 (:mod:`bem.coating`); needs ``E1, nu1, E2, nu2``. The
        operator then carries the bodies' compliance per Fourier mode ``2 (s1 + s2) / q``;
        ``result.E_star`` is the substrates' and ``result.bodies`` the :class:`bem.Bodies`.
    force, approach, mean_pressure : float
        Exactly one: total force ``P`` [force] (force control, eq. 9; on a cell the force on one
        cell), the approach ``delta`` [length] (approach control), or, on a cell, the mean
        pressure ``pbar`` [pressure] (the force ``pbar Lx Ly``). On a cell without a layer the
        approach must be below the mean gap (a full contact leaves the mean pressure
        undetermined).
    domain : bem.HalfSpaceRegion or bem.PeriodicCell, optional
        Where contact may occur. Default: ``HalfSpaceRegion(step, extent)``.
    step, extent : float
        Shorthand for ``domain=HalfSpaceRegion(step, extent)`` (lattice step ``c`` [length],
        half-widths of the region [length] or ``"auto"``, which grows), not with ``domain``. The region holds at most
        :func:`bem.checks.max_nodes` nodes (a memory guard, checked before anything is built).
        A gap with a ``check_region(extent)`` method (a measured surface's table,
        :meth:`bem.gaps.Measured.region`) refuses a region beyond its data.
    layer : bem.layers.Layer, optional
        Interface layer law ``w(p)``; ``None`` for smooth bodies.
    hardness : float, optional
        Hardness ``H`` [pressure] of an elastic-perfectly-plastic surface: the pressure is bounded,
        ``0 <= p <= H`` at every node, and a node at ``H`` yields (its gap may close beyond
        contact, the plastic deformation; :mod:`bem.plastic`). ``None``: elastic. Taken by Kalker's
        QP and ``"newton"`` (the paper's fixed-point methods refuse it). On a cell the mean
        pressure is at most ``H``; under force control a contact whose every node yields leaves
        the approach undetermined in an interval, whose lower end is returned
        (``history["approach_bracket"]``).
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
        Initial nodal pressures: shape ``(N,)`` (the candidate nodes) or a brick array of the
        lattice's shape; finite, negative entries clipped. Not with a growing region.
    nested : bool, optional
        Start from the solution on successively coarser lattices (step ``2c``,
        ``4c``, ...) interpolated onto the finer one. Each finer level is solved on
        the rectangular window of the nodes whose initial gap is below the approach
        (of the coarser level, with a margin): the others cannot close. Its solution
        is checked against the final approach, and the level solved again on the whole
        lattice if a node outside the window could close (a half-space region; a cell is
        solved whole, needs ``n_cols`` even and ``n_rows`` a multiple of 4 per level). Default: on for
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
        On a periodic cell a :class:`bem.PeriodicContactResult`; ``result.domain`` is the
        domain solved on, ``result.notes`` says how a growing region grew.

    Raises
    ------
    bem.InputError
        Bad input (the message names the argument).
    RegionTooSmallError
        The contact reaches the border of a region that does not grow (or cannot grow further).

    Notes
    -----
    Stopping rules, with ``r_k`` the KKT residual of iterate ``k`` (relative to the
    largest surface closure ``max |C p + w(p)|``; force balance relative to ``P``):

    - Kalker's QP: ``r_k <= rtol``, checked on an exactly recomputed ``C p``.
    - Newton: ``r_k <= rtol`` on an exact product; each inner QP is solved to
      ``max(rtol / 3, min(1e-2, eta_k r_k))``, ``eta_k = min(0.3, 0.9 (r_k / r_(k-1))^1.618)``.
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
    domain = _domain(domain, step, extent)
    domain.check_gap(gap)
    problem = check_problem(domain, E_star=E_star, E1=E1, nu1=nu1, E2=E2, nu2=nu2, coating1=coating1,
                            coating2=coating2, force=force, approach=approach,
                            mean_pressure=mean_pressure, layer=layer, method=method, rtol=rtol, maxiter=maxiter,
                            nested=nested, precondition=precondition, callback=callback, device=device,
                            options=options, hardness=hardness)
    region = domain.resolved(gap, E_star=problem.E_star, force=problem.force, approach=problem.approach, layer=layer)
    if x0 is not None and getattr(region, "grow", False):
        raise InputError(f"x0 is not allowed with {region!r}: its lattice changes as the region grows "
                         "(give grow=False and a numeric extent).")
    if problem.solver != method and method != "newton":  # a paper method asked for a quadratic problem
        log.info("method = %r runs as Kalker's QP (result.method = %r): %s, so the functional is quadratic",
                 method, problem.solver, "there is no layer" if layer is None else "the layer is linear")
    notes = []
    for attempt in itertools.count():
        try:
            result = _solve_on(region, gap, problem, x0, t_start)
            break
        except RegionTooSmallError:
            bigger = region.grown(gap, attempt)
            if bigger is None:
                raise
            note = (f"the contact reached the border of the automatic candidate region; extent enlarged from "
                    f"({region.extent[0]:.4g}, {region.extent[1]:.4g}) to ({bigger.extent[0]:.4g}, "
                    f"{bigger.extent[1]:.4g})")
            log.info(note)
            notes.append(note)
            region = bigger
    result.notes = notes
    if not result.converged:
        log.warning("%s: %s%s", problem.solver, result.message, _inner_summary(result.history))
    elif (note := beyond_table(layer, result.p_max)) is not None:
        log.warning("%s", note)
    return result


def _domain(domain, step, extent):
    """The domain: ``domain``, or the region of ``step`` and ``extent``."""
    if domain is None:
        if step is None or extent is None:
            raise InputError(f"(domain, step, extent) = ({domain!r}, {step!r}, {extent!r}) is not allowed: give "
                             "domain, or step and extent.")
        return HalfSpaceRegion(step, extent)
    if step is not None or extent is not None:
        raise InputError(f"step = {step!r} and extent = {extent!r} are not allowed with domain = {domain!r}: the "
                         "domain has its lattice.")
    if not all(hasattr(domain, name) for name in ("resolved", "levels", "operator", "solve_level")):
        raise InputError(f"domain = {domain!r} is not allowed: it must be a bem.HalfSpaceRegion or a "
                         "bem.PeriodicCell.")
    return domain


def _solve_on(region, gap, problem, x0, t_start):
    """Nested iteration over the levels of the resolved domain ``region``; the result on its finest lattice."""
    lattice = region.lattice()
    h = region.nodal_gap(gap, lattice)
    region.check_approach(problem.approach, h, problem.layer)
    nested, guess = problem.nested, None
    if x0 is not None:
        guess, nested = initial_guess(x0, lattice), False
    levels = region.levels(lattice, h, gap, nested)
    coarse_rtol = region.coarse_rtol(problem.solver, problem.precondition)

    def make_op(lat):
        if problem.bodies is None:
            return region.operator(lat, problem.E_star, problem.backend)
        return region.operator(lat, problem.E_star, problem.backend, bodies=problem.bodies)

    def run(op, h_lat, kw):
        return _run(problem.solver, op, h_lat, problem.layer, problem.precondition, kw, problem.options)

    rtol, delta = problem.rtol, problem.approach  # the approach, or under force control its coarser estimate
    handover = {}  # what a level hands over to the next: its product C p prolonged, where it made one
    while levels:  # each level leaves the list as it is solved: a coarser level's arrays go before the next
        lat, h_lat = levels.pop(0)
        finest = not levels
        kw = dict(force=problem.force, approach=problem.approach, x0=guess,
                  rtol=rtol if finest else max(rtol, coarse_rtol), callback=problem.callback if finest else None)
        if problem.maxiter is not None:
            kw["maxiter"] = problem.maxiter
        if guess is not None and problem.solver in ("kalker", "newton"):
            # the start is the solve's own (initial_guess copies, refine makes it): the solver holds its iterate in it
            kw["overwrite_x0"] = True
        if problem.hardness is not None:
            _check_capacity(region, lat, problem)
            kw["hardness"] = problem.hardness
        sol, ops, u = region.solve_level(run, make_op, lat, h_lat, kw, delta if nested else None, problem.solver,
                                         handover)
        delta = sol.approach
        if not finest:  # the coarse solution and operators are released before the finer level is solved
            guess = region.refine(lat, sol.p, levels[0][0])
            handover = {} if u is None else {"u": region.refine(lat, u, levels[0][0])}
            sol = ops = u = h_lat = None
    region.check_solution(lattice, sol.p)
    op = ops[-1] if ops[-1].lattice is lattice else make_op(lattice)
    n_matvec = sum(o.n_matvec for o in ops if o is not op)
    n_transforms = sum(o.n_transforms for o in ops if o is not op)
    # the result recomputes C p (where the level did not make it): the solver's copy, the start and the level's
    # operators go first
    guess = kw = ops = levels = None
    sol.displacement = None
    layer = problem.layer
    closure = None if layer is None else np.where(lattice.mask, layer.w(sol.p), 0.0)
    if u is None:  # (the level's own product where it made one on the finest lattice)
        u = to_host(op.matvec(sol.p))
    n_matvec += op.n_matvec
    n_transforms += op.n_transforms
    op = None  # its kernel spectra go before the result is made
    g, scale = _deformed_gap(u, closure, h, sol.approach)
    # the full arrays are handed over in a dict, so that the result can let each go once it has its nodes
    fields = dict(u=u, g=g, closure=closure)
    u = g = closure = h = h_lat = None
    return _result(region, lattice, fields, scale, sol, problem, t_start, (n_matvec, n_transforms))


def _deformed_gap(u, closure, h, approach):
    """``(g, s)``: the gap ``u + closure + h - approach`` and the scale ``max |u + closure|`` of the KKT residual
    (``closure`` None: no layer), without temporaries beyond ``g``."""
    if closure is None:  # (u + 0) + h - delta, in place
        g = u + h
        scale = max(float(u.max()), -float(u.min()))  # max |u|
    else:
        g = u + closure
        scale = max(float(g.max()), -float(g.min()))
        g += h
    g -= approach
    return g, scale


def _check_capacity(region, lattice, problem):
    """Raise :class:`bem.RegionTooSmallError` where the candidate nodes of ``lattice`` at the hardness cannot
    carry the force (a growing region then grows)."""
    if problem.force is None:
        return
    capacity = problem.hardness * lattice.node_area * int(np.count_nonzero(lattice.mask))
    if problem.force > capacity:
        raise RegionTooSmallError(
            f"force = {problem.force!r} is not allowed on {region!r}: its candidate nodes at hardness = "
            f"{problem.hardness!r} carry at most {capacity:.6g}. Make extent larger or reduce the load.")


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
    if solver == "kalker":  # the operator's own constrained-CG step
        return op.qp(h, lam=0.0 if layer is None else layer.lam, precondition=precondition, **kw, **options)
    from .fixed_point import solve_augmented_gap, solve_variable_compliance
    from .newton import solve_newton

    run = {"newton": solve_newton, "augmented_gap": solve_augmented_gap,
           "variable_compliance": solve_variable_compliance}[solver]
    return run(op, h, layer=layer, precondition=precondition, **kw, **options)


def _result(region, lattice, fields, scale, sol, problem, t_start, work):
    """The result on the candidate nodes from the full arrays ``fields`` (``u``, ``g`` and ``closure``, None
    without a layer: zeros), each let go once its nodes are taken; ``work``: the products with ``C`` and the
    transforms. Where every node is a candidate (a periodic cell) its arrays are flat views, not copies: x and y
    (the lattice's, read-only), p, the displacement and the gap; elsewhere the lattice's coordinates are made one
    at a time and released."""
    mask = lattice.mask
    whole = bool(mask.all())

    def nodes(values, writeable=True):
        if not whole:
            return values[mask]
        flat = values.reshape(-1)
        if not writeable:
            flat = flat.view()
            flat.flags.writeable = False
        return flat

    def coordinate(name):
        values = nodes(getattr(lattice, name), False)
        if not whole and hasattr(lattice, "release_coordinates"):
            lattice.release_coordinates()
        return values

    p = sol.p
    a = lattice.node_area
    p_n, g_n = nodes(p), nodes(fields.pop("g"))
    kkt = kkt_residual(p_n, g_n, displacement_scale=scale, force=problem.force, node_area=a, hardness=problem.hardness)
    if not np.all(np.isfinite(p)):
        raise FloatingPointError(f"{problem.solver}: the solver produced non-finite pressures ({sol.message})")
    n_nodes = p_n.size
    u_n = nodes(fields.pop("u"))
    closure = fields.pop("closure")
    closure = np.zeros(n_nodes) if closure is None else nodes(closure)
    x, y = coordinate("x"), coordinate("y")
    return region.result_class(
        x=x, y=y, p=p_n, displacement=u_n, closure=closure, gap=g_n,
        approach=float(sol.approach), force=float(a * p.sum()), p_max=float(p.max()),
        contact_area=float(a * np.count_nonzero(p_n > 0)), converged=bool(sol.converged),
        message=sol.message, status=sol.status, rtol=float(problem.rtol), iterations=int(sol.iterations),
        kkt_residual=float(kkt), method=problem.solver, wall_time_s=time.perf_counter() - t_start, lattice=lattice,
        E_star=problem.E_star, history=sol.history, layer=problem.layer, n_matvec=work[0], n_transforms=work[1],
        domain=region, bodies=problem.bodies, hardness=problem.hardness,
        plastic_area=0.0 if problem.hardness is None else float(a * np.count_nonzero(p[mask] >= problem.hardness)))
