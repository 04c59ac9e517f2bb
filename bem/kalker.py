"""Kalker's discrete principle (eq. 11, 13) as a bound-constrained QP.

Minimise ``1/2 p.(C + diag(lam)) p + p.(h - delta)`` over ``p >= 0``, under
force control (``a sum p = P``, eq. 9, ``delta`` is the multiplier) or approach
control (``delta`` given). Solved by constrained conjugate gradients on the
active set (Polonsky & Keer 1999, doi:10.1016/S0043-1648(99)00113-1), with an
optional FFT preconditioner built from the inverse symbol of ``C + lam`` in
the spirit of Vollebregt 2014 (doi:10.1016/j.jcp.2013.10.005). :func:`solve_qp` is the step
of the half-space operator (on every device) in the one loop
:func:`bem.cg_rules.run_constrained_cg`, with the rules of :mod:`bem.cg_rules`.

With the preconditioner the direction is kept when the contact changes: ``t = z + beta t_old`` on the current
contact, ``beta = max(0, g.(z - z_old) / g_old.z_old)`` (Polak-Ribiere+, Gilbert & Nocedal 1992,
doi:10.1137/0802003; ``z`` the preconditioned gap, ``z_old`` 0 at entering nodes), the step to the minimum along
``t``, and ``t = z`` where ``g.t <= 0``, as in :mod:`bem.periodic.qp`; it restarts where the preconditioned residual
grew (``g.z > g_old.z_old``: nodes entered with most of it) and, with a hardness, after a step shortened or capped at
``H`` to carry the force (:func:`bem.cg_rules.bounded_move`). Restarting at every entering node (Polonsky and Keer)
costs the nested rough sphere of ``benchmarks/cases.py`` 31 finest iterations against 24 at 2048^2, 56 against 36
with a hardness at 512^2 (``docs/performance.md``). Without the preconditioner the loop is Polonsky and Keer's:
Fletcher-Reeves directions, restarted where nodes entered (kept directions took up to six times the iterations).

A step costs one product ``C t`` of the search direction, which updates ``C p``; where nodes enter the
contact, ``C p`` is recomputed after the step instead, and the step length takes its curvature ``t.C t``
from the operator's ``quadratic`` where it has one (:meth:`bem.InfluenceOperator.quadratic`: a forward
transform over the support's box in single precision, no product).
"""

from __future__ import annotations

import math

import numpy as np

from .backend import operator_backend
from .cg_rules import (RECOMPUTE_EVERY, CGStep, Record, bounded_move, bounded_sets, elastic_displacement,
                       entering_pressure, initial_pressure, is_per_node, is_stiff, iterate_residual, run_constrained_cg)
from .plastic import carry_force, in_place, note_fully_plastic

__all__ = ["solve_qp", "constrained_cg", "compliance_preconditioner"]


def solve_qp(op, h, *, force=None, approach=None, lam=0.0, x0=None, rtol=1e-10,
             maxiter=None, preconditioner=None, callback=None, scale=None, u0=None, confirm=True, hardness=None,
             overwrite_x0=False, offset=None):
    """Solve the Kalker QP ``min 1/2 p.(C + lam) p + p.(h - delta), p >= 0`` (``0 <= p <= H`` with a hardness).

    Parameters
    ----------
    op : bem.operator.InfluenceOperator
        ``C`` on the candidate lattice.
    h : ndarray
        Gap at the nodes, brick array [length].
    force, approach : float
        Exactly one: total force ``P`` [force] or approach ``delta`` [length].
    lam : float or ndarray
        Linear layer compliance ``lam`` [length/pressure], scalar or per node (eq. 22's method, Newton's models).
    x0 : ndarray, optional
        Initial pressure (brick array); negative entries are clipped.
    overwrite_x0 : bool
        Whether a float64 NumPy ``x0`` may hold the iterate (clipped and masked in place, not copied: one array
        of the lattice fewer; with ``u0``, masked only).
    rtol : float
        Tolerance on the KKT residual.
    maxiter : int, optional
        Iteration limit (default ``max(200, 10 * sqrt(N))``).
    preconditioner : callable, optional
        ``z = M(r)`` on brick arrays approximating ``(C + lam)^-1``
        (:meth:`bem.operator.InfluenceOperator.preconditioner`,
        :func:`compliance_preconditioner`).
    callback : callable, optional
        ``callback(k, p)`` after every iteration.
    scale : float, optional
        Displacement scale of the KKT residual [length]; default
        ``max |C p + lam p|``. A caller whose ``lam`` is a model curvature (Newton)
        passes the scale of the problem it linearises.
    u0 : ndarray, optional
        ``C x0`` (brick array) where the caller has it, e.g. updated incrementally:
        spares the first product. The iterate starts from ``x0`` as given (under force
        control it must carry the force), and the stopping check is then confirmed on an
        exact product as after any incremental update.
    confirm : bool
        Confirm the stopping check on an exactly recomputed ``C p`` (default). A caller that re-checks the solution
        itself (Newton's inner solves) passes False and gets the solution of the incrementally updated products,
        which differ from the exact ones by round-off only.
    offset : tuple, optional
        ``(nodes, values)``: a part of the gap at some nodes (a backend's selection), added to ``h`` there with no
        array of the sum (Newton's model gap ``h + w(p) - D p``, whose second part lives where ``p > 0``).
    hardness : float, optional
        The bound ``H`` of the pressure [pressure] (:mod:`bem.plastic`): the nodes at ``p = H`` are
        plastic, held at ``H`` and left out of the search direction like the open nodes; the step
        is projected onto ``[0, H]``, a plastic node whose gap opens leaves at the pressure an
        entering node would take, and under force control the approach is the mean gap of the
        elastic contact. ``None``: no bound.

    Returns
    -------
    QPSolution

    Notes
    -----
    Stopping rule: iterate until

    ``max( max_{p>0} |g| , max_{p=0} (-g)_+ ) <= rtol * max |C p + lam p|``

    with ``g = C p + lam p + h - delta`` (and ``|a sum p - P| <= rtol P`` under force control, which the rescaling
    keeps to round-off), i.e. :func:`bem.kkt.kkt_residual` ``<= rtol``; the check uses an exactly recomputed ``C p``
    unless ``confirm`` is False.
    """
    lat, (bk, mask) = op.lattice, operator_backend(op)
    xp, a = bk.xp, lat.node_area
    per_node = is_per_node(lam)
    lam = xp.astype(xp.where(mask, lam, 0.0), xp.float64) if per_node else float(lam)  # (a model's D: float32)
    h = _masked_gap(bk, mask, h)
    if maxiter is None:
        maxiter = max(200, int(10 * math.sqrt(lat.n_nodes)))
    target = None if force is None else force / a
    off = bk.select(~mask)  # the few masked nodes (last node of the odd rows)
    if u0 is None or x0 is None:
        p = initial_pressure(op, h, lam, force, approach, x0, hardness, overwrite_x0)
        if p is not x0:  # x0 itself where overwrite_x0 allows: clipped and masked in place
            p = xp.where(mask, p, 0.0)
        if target is not None:
            p = p if float(xp.sum(p)) > 0 else xp.astype(mask, bk.float64)
            if hardness is None:
                p *= target / float(xp.sum(p))
            else:
                p = carry_force(xp, p, target, hardness, mask)
        u0 = None
    else:  # the caller's iterate and its product, as they are
        p = bk.put(x0, off, 0.0) if overwrite_x0 and in_place(bk, x0) else xp.where(mask, x0, 0.0)

    def apply(v):  # u of the iterate v: (C + lam) v and the gap's offset
        out = op.matvec(v)
        if per_node or lam:
            out += lam * v
        return out if offset is None else bk.add_at(out, *offset)

    def moved(r, tau, s):  # u after a step p = s (p - tau t), r = (C + lam) t (consumed); the offset not scaled
        nonlocal u, stale
        r *= tau
        u -= r
        if s != 1.0:
            u *= s
            u = u if offset is None else bk.add_at(u, offset[0], (1.0 - s) * offset[1])
        stale += 1

    if u0 is None:
        u, stale = apply(p), 0
    else:  # from the caller: C x0 (+ lam x0), to be confirmed like an incremental update
        u, stale = xp.where(mask, u0, 0.0), 1
        u += lam * p
        u = u if offset is None else bk.add_at(u, *offset)
    t_kept = None  # (nodes, values): the last search direction on its contact (kept compact, as last_z)
    gz_old, restart = 1.0, False  # restart the direction (the rules in advance)
    last_z = None  # (nodes, z): the last preconditioned gap on its contact, for the Polak-Ribiere+ coefficient
    record, kkt, delta = Record(rtol, maxiter), np.inf, approach
    prev_contact = p > 0
    m_one = None
    quadratic = getattr(op, "quadratic", None)
    fixed_scale = scale
    # With a per-node compliance the preconditioner holds Jacobi blocks that differ by decades, and plain mean
    # subtraction would wreck it: project obliquely. For a uniform compliance the mean (fewer Hertz iterations).
    oblique = per_node
    # The conjugate-gradient vectors live on the contact set, compact at the flat indices idx of its nodes (the
    # backend's node selections), spread to brick arrays only for the FFT products; full-array work is left to the
    # gap, the KKT check and the displacement update.
    contact = idx = n_idx = g = g_c = p_c0 = changes = g_min = low = None
    bounded = hardness is not None
    sets = None
    prev_plastic = p >= hardness if bounded else None
    jacobi = 1.0 / (op.diagonal + lam) if bounded else None

    def measure_bounded(k):  # measure() with the bound: the CG lives on the elastic contact 0 < p < H
        nonlocal contact, idx, n_idx, g, delta, g_c, p_c0, sets
        v = u + h
        bk.put(v, off, 0.0)
        sets = bounded_sets(bk, p, v, hardness, delta, force, mask)
        contact, idx, delta = sets.on & ~sets.plastic, sets.idx, sets.delta
        n_idx = bk.count(idx)
        g = v - delta
        bk.put(g, off, 0.0)
        scale = max(float(xp.max(u)), -float(xp.min(u))) if fixed_scale is None else fixed_scale
        g_c = bk.take(g, idx)
        p_c0 = bk.take(p, idx)
        return iterate_residual(bk.max0(xp.abs(g_c)), sets.gap_min, scale, lambda: float(xp.max(xp.abs(g))),
                                None if force is None else abs(a * float(xp.sum(p)) - force) / force,
                                plastic_gap=sets.plastic_gap)

    def measure(k):  # the gap, the approach under force control and the KKT residual of the iterate
        nonlocal contact, idx, n_idx, g, delta, g_c, p_c0, g_min, low
        contact = p > 0
        idx = bk.select(contact)
        n_idx = bk.count(idx)
        g = None  # the last gap goes before the new one is made
        g = u + h
        if force is not None:
            delta = float(xp.mean(bk.take(g, idx)))
        g -= delta
        bk.put(g, off, 0.0)
        scale = max(float(xp.max(u)), -float(xp.min(u))) if fixed_scale is None else fixed_scale
        g_c = bk.take(g, idx)
        p_c0 = bk.take(p, idx)
        # kkt_residual(p[mask], g[mask], ...) without the copies: p = g = 0 off the mask, p >= 0, and
        # max(max_contact |g|, max_free (-g)+) = max(max_contact |g|, (-min g)+) (contact nodes: -g <= max_contact |g|)
        g_min = float(xp.min(g))
        kkt = iterate_residual(bk.max0(xp.abs(g_c)), g_min, scale, lambda: float(xp.max(xp.abs(g))),
                               None if force is None else abs(a * float(xp.sum(p_c0)) - force) / force)
        # the step needs the nodes of negative gap (those that may enter), not the gap: not held through its products
        low, g = bk.select(g < 0), None
        return kkt

    def confirms(kkt):  # an incrementally updated C p at the tolerance: recompute it and measure again
        nonlocal u, stale
        if kkt <= rtol and stale and confirm:
            u = None  # not held through its own recomputation
            u, stale = apply(p), 0
            return True
        return False

    def observe():
        nonlocal changes, prev_contact, prev_plastic
        if bounded:  # changes of the contact and of the plastic set
            changes = int(xp.count_nonzero(sets.on != prev_contact)) + int(xp.count_nonzero(sets.plastic != prev_plastic))
            prev_contact, prev_plastic = sets.on, sets.plastic
            n_touch = n_idx + bk.count(sets.pl)
            return bk.max0(p), n_touch, changes, n_touch == 0 and float(xp.min(g)) >= 0
        changes = int(xp.count_nonzero(contact != prev_contact))
        prev_contact = contact
        return bk.max0(p_c0), n_idx, changes, n_idx == 0 and g_min >= 0

    def advance(k):  # one step of the constrained CG; (message, status) where it cannot be taken
        nonlocal m_one, gz_old, t_kept, u, stale, p, last_z, restart, g_c, p_c0
        if bounded and not n_idx:  # every contact node plastic: only entering and leaving nodes move
            return bounded_step(0.0, xp.zeros_like(g_c), None)
        if preconditioner is None:
            z = bk.copy(g_c)
            if force is not None:
                z -= xp.mean(z)
        else:
            z = bk.take(preconditioner(bk.spread(lat.shape, idx, g_c)), idx)
            if force is not None and not oblique:
                z -= xp.mean(z)
            elif force is not None:
                # oblique projection onto sum z = 0: z - M1 (1.z) / (1.M1), M1 cached per contact set
                if m_one is None or changes:
                    m_one = bk.take(preconditioner(xp.astype(contact, bk.float64)), idx)
                z -= m_one * (xp.sum(z) / xp.sum(m_one))
        gz = float(xp.sum(g_c * z))
        if preconditioner is None:  # Polonsky and Keer (gz_old = 0: one contact node under force control)
            beta = 0.0 if restart or not gz_old > 0 else gz / gz_old
        else:  # Polak-Ribiere+ on the current contact, z_old 0 at entering nodes (the rules: module docstring)
            beta = 0.0 if last_z is None or not gz_old > 0 or gz > gz_old or restart else max(
                0.0, (gz - float(xp.sum(g_c * _kept_at(bk, lat.shape, last_z, idx, changes)))) / gz_old)
            last_z = (idx, z)
        t_old = _kept_at(bk, lat.shape, t_kept, idx, changes) if t_kept else xp.zeros(n_idx, dtype=bk.float64)
        t_c, t_old = z + beta * t_old, None
        if force is not None:  # nodes that left the contact broke the zero sum of t
            t_c -= m_one * (xp.sum(t_c) / xp.sum(m_one)) if oblique and m_one is not None else xp.mean(t_c)
        gt = gz  # g.t: g.z on a conjugate direction
        if beta and preconditioner is not None:
            gt = float(xp.sum(g_c * t_c))
            if not gt > 0:  # no descent along t after a change of the contact: steepest descent
                t_c, gt = z, gz
        t_kept, t = (idx, t_c), bk.spread(lat.shape, idx, t_c)
        lam_c = bk.take(lam, idx) if per_node else lam  # the compliance at the contact
        gz_old, g_c = gz, None  # the gap at the contact is not held through the products
        # open nodes with g < 0 enter the contact below and C p is then recomputed: C t would serve only the
        # curvature t.(C + lam) t, which op.quadratic gives without the product
        if quadratic is not None and not bounded and bool(xp.any(bk.take(p, low) == 0)):
            tt, r, t = quadratic(t) + float(xp.sum(lam_c * t_c * t_c)), None, None
        else:
            p_c0 = None  # (C + lam) t in the buffer of t, lam t added at the contact; p at the contact gathered after
            r, t = op.matvec(t, overwrite_p=True), None
            p_c0 = bk.take(p, idx)
            r_c = bk.take(r, idx)
            if per_node or lam:
                r_c += lam_c * t_c
                bk.put(r, idx, r_c)
            if force is not None:
                r_c -= xp.mean(r_c)
            tt = float(xp.sum(t_c * r_c))
        if not bool(xp.any(t_c != 0)):
            # a single contact node under force control leaves no direction that keeps the
            # force: only nodes entering the contact (below) can move the iterate
            tau = 0.0
        elif tt <= 0 or not math.isfinite(tt):
            return f"search direction lost positive curvature (t.Ct = {tt:.3e})", "stalled"
        else:
            tau = gt / tt  # the minimum along t
        if bounded:
            return bounded_step(tau, t_c, r)
        p_c = p_c0 - tau * t_c
        clipped = p_c < 0
        p_c = xp.where(clipped, 0.0, p_c)
        p[...] = 0.0  # p_c on the contact, 0 elsewhere: in p itself, no second array of the lattice
        bk.put(p, idx, p_c)
        # re-entering nodes (p = 0, g < 0): Polonsky-Keer's -tau g capped by the Jacobi estimate
        # -g / (C_nn + lam), or with a preconditioner (tau then dimensionless) a share of that estimate
        overlap = bk.subset(low, bk.take(p, low) == 0)  # off-mask nodes have g = 0
        n_overlap = bk.count(overlap)
        if n_overlap:  # their gap u + h - delta (u not yet updated) as measured
            lam_o = bk.take(lam, overlap) if per_node else lam
            g_o = bk.take(u, overlap) + bk.take(h, overlap) - delta
            bk.put(p, overlap, entering_pressure(xp, g_o, tau, 1.0 / (op.diagonal + lam_o), per_node,
                                                 preconditioned=preconditioner is not None))
        s = 1.0
        if target is not None:
            s = target / float(xp.sum(p))  # the full sum: Newton's round-off floor depends on it
            if math.isfinite(s):
                p *= s  # nonzero only at the contact and the overlap: the same as scaling those
            else:
                bk.put(p, idx, bk.take(p, idx) * s)
                entering = bk.subset(overlap, ~bk.take(contact, overlap))  # a clipped contact node may re-enter
                bk.put(p, entering, bk.take(p, entering) * s)
        restart = preconditioner is None and bool(n_overlap)
        if bool(xp.any(clipped)) or n_overlap or stale >= RECOMPUTE_EVERY:
            u = r = None
            u, stale = apply(p), 0
        else:
            moved(r, tau, s)
        return None

    def bounded_step(tau, t_c, r):  # the step of the bounded QP (bem.cg_rules.bounded_move) and its product
        nonlocal restart, u, stale
        changed, entered, s, failure, shortened = bounded_move(bk, p, sets, p_c0, t_c, tau, g + delta, jacobi, per_node,
                                                               target, hardness, mask=mask,
                                                               preconditioned=preconditioner is not None)
        restart = entered if preconditioner is None else shortened
        if failure is not None:
            return failure
        if changed or r is None or stale >= RECOMPUTE_EVERY:
            u = r = None
            u, stale = apply(p), 0
        else:  # the elastic nodes moved along t and were scaled by s (the plastic ones by s - 1 of round-off)
            moved(r, tau, s)
        return None

    report = (lambda: bk.copy(p)) if bounded else (lambda: p)  # the bounded step updates p in place
    kkt = run_constrained_cg(CGStep(measure_bounded if bounded else measure, confirms, observe, advance, report),
                             record, maxiter, callback)
    note_fully_plastic(record, sets.bracket if bounded else None, bounded and not n_idx)
    return record.solution(p, delta, kkt, elastic_displacement(bk, u, lam, p, offset=offset), "Kalker QP")


def _kept_at(bk, shape, kept, idx, changes):
    """The kept values ``kept = (nodes, values)`` at the node selection ``idx`` (1-D), 0 at nodes not kept: the
    values themselves where the contact did not change (``changes == 0``, the same nodes), else a gather from a
    brick array that holds them for this read only."""
    nodes, values = kept
    if not changes and bk.count(nodes) == bk.count(idx):
        return values
    return bk.take(bk.spread(shape, nodes, values), idx)


def _masked_gap(bk, mask, h):
    """``h`` with 0 off the candidate nodes: ``h`` itself where it is 0 there already (a region's nodal gap), so
    that the solve holds no copy of it."""
    h = bk.asarray(h)
    off = h[~mask]
    if off.size and not (bool(bk.xp.all(off == 0)) and not bool(bk.xp.any(bk.xp.signbit(off)))):
        return bk.xp.where(mask, h, 0.0)
    return h if h.dtype == bk.float64 else bk.xp.where(mask, h, 0.0)


def constrained_cg(op, h, *, lam=0.0, precondition=True, contact=None, **kw):
    """:func:`solve_qp` with the preconditioner of ``op``: the FFT inverse of ``C + lam`` in single precision
    (:meth:`bem.operator.InfluenceOperator.preconditioner`) for a uniform ``lam``, and
    :func:`compliance_preconditioner` on ``contact`` for a ``lam`` per node; none unless
    ``precondition``. The constrained-CG step of an operator without one of its own."""
    if not precondition:
        precond = None
    elif is_per_node(lam):
        precond = compliance_preconditioner(op, lam, contact)
    else:
        precond = op.preconditioner(lam=lam, single=True, overwrite_r=True)  # it may destroy its input
    return solve_qp(op, h, lam=lam, preconditioner=precond, **kw)


def compliance_preconditioner(op, D, contact, threshold=4.0):
    """Block-diagonal SPD preconditioner for ``C + diag(D)``.

    Nodes whose layer compliance dominates (``D > threshold * C_nn``) are nearly
    decoupled: Jacobi ``r / (C_nn + D)``. The others get the FFT inverse of
    ``C + lam`` (in single precision) with ``lam`` the median of their ``D`` on the contact.
    """
    bk, _ = operator_backend(op)
    xp = bk.xp
    stiff = is_stiff(D, op.diagonal, threshold)
    sel = stiff & contact
    lam = bk.median(D[sel], overwrite=True) if bool(xp.any(sel)) else 0.0
    fft = op.preconditioner(lam=lam, single=True)
    jacobi = 1.0 / (op.diagonal + D)
    if bool(xp.all(stiff)):
        return fft

    def apply(r):
        return xp.where(stiff, fft(xp.where(stiff, r, 0.0)), jacobi * r)

    return apply
