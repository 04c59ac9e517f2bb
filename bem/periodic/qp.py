"""Kalker's QP on a periodic cell: the conjugate gradients of :func:`bem.kalker.solve_qp` in the Fourier basis.

The step of the periodic operator (:meth:`bem.periodic.PeriodicOperator.qp`) in the one loop
:func:`bem.cg_rules.run_constrained_cg`, with the rules of :mod:`bem.cg_rules`.

The iteration of :func:`bem.kalker.solve_qp` (constrained conjugate gradients on the active
set, Polonsky & Keer 1999, with the FFT preconditioner, the same entering rule, Jacobi cap and
stopping rule), specialised to :class:`bem.periodic.PeriodicOperator` on NumPy, where ``C`` is
diagonal in the Fourier basis of the cell (a 2 x 2 block per frequency, one block row per row
parity) and every node is a candidate. It does not restart the conjugate directions when nodes
enter the contact: the new direction is ``t = z + beta t_old`` on the current contact with the
Polak-Ribiere+ coefficient ``beta = max(0, g.(z - z_old) / g_old.z_old)``, and the step is the
minimum along ``t``, ``tau = g.t / t.(C + lam) t`` (``g.t = g.z`` while the contact does not
change, the conjugate-gradient step); where ``g.t <= 0`` the step falls back to ``t = z``. On a
rough surface, whose contact set changes at most iterations until it settles, the general loop
restarts at every change and degrades to preconditioned steepest descent
(``tests/bem/test_periodic_qp.py``: 88 iterations against 57 on a 256 x 256 self-affine cell).
Nodes that enter the contact (``p = 0``, ``g < 0``) take the step of the preconditioned iteration
with a share of the Jacobi estimate of the preconditioner at that node, ``p = -f min(tau, 1) g / (C_nn + lam)``
(``f`` = :data:`bem.cg_rules.ENTERING_FRACTION`, chosen by the iteration counts stated there):
``tau`` is dimensionless here (``t`` is ``M g``), and ``-tau g`` would give an entering node
``tau C_nn`` of its Jacobi pressure, a fraction that falls with the step (on a 672 x 776 rough cell,
1e-4 of the mean contact pressure: a cycle of nodes entering with almost no pressure and leaving,
at a constant KKT residual, ``tests/bem/test_periodic_robustness.py``). Further:

- the iteration keeps ``u = (C + lam) p`` in double precision. After a step without a change
  of the contact set it is updated by ``tau (C + lam) t``, the product of the search direction,
  which runs in single precision: its rounding is a relative ``1e-7`` of the step, and the
  step falls with the residual. After a change of the contact set, and after every 20 updates,
  ``u`` is recomputed from ``p``;
- the curvature ``t.(C + lam) t`` is a sum over the spectrum of that product (Parseval,
  summed in double precision);
- the preconditioner runs in single precision: it only has to approximate ``(C + lam)^-1``;
- so does the recomputed ``u`` while the KKT residual is above ``1e-4`` (:data:`SINGLE_ABOVE`),
  in a solve that starts above ``1e-2`` (:data:`SINGLE_START` times that) or stops above
  ``1e-4`` (``rtol >= SINGLE_ABOVE``, a Newton step's model far from the answer), where the rounding
  of single precision (a relative ``1e-7`` of ``C p``) is far below what the iteration
  resolves: halved transforms in the early iterations, where the contact set settles. At the
  first residual below it (or at ``rtol`` when the stopping check is confirmed) ``u`` is
  recomputed in double precision, and so it is from there on; the stopping check, when
  confirmed, is always on a double-precision product.

With a compliance per node (the model of a Newton step, :mod:`bem.newton`) the products are
those of ``C`` alone, ``u = C p + D p`` and the curvature adds ``sum D t^2``; the preconditioner
is that of :func:`bem.kalker.compliance_preconditioner` (single precision), with its oblique
projection under force control (by ``M 1`` of the starting contact).

With a hardness ``H`` (:mod:`bem.plastic`) the direction lives on the elastic contact ``0 < p < H``
and the step is that of every constrained-CG step (:func:`bem.cg_rules.bounded_move`). The directions
restart (``beta = 0``) after a step that was shortened, or capped at ``H``, to carry the force: the fill
of the force at the bound breaks the conjugacy, and a Polak-Ribiere+ direction kept there repeats the step
that failed (on a 64-column self-affine cell at 18 % of ``H``, ``tests/bem/test_hardness_units.py``: no
convergence in 688 iterations without). Nodes that enter or leave keep the directions, as without a
hardness (a 512^2 law of 20 pressures at ``H = E* h'_rms``: 531 iterations, 695 when those restart too).

A step costs four transforms of the cell in single precision while the contact set does not
change (two for the preconditioner, one forward for the search direction, one inverse for its
product), five where it changes, two of them in double precision once the residual is below
``SINGLE_ABOVE`` (the general loop: four or six in double precision, or up to eight with a
compliance per node).
"""

from __future__ import annotations

import math

import numpy as np

from ..backend import operator_backend
from ..cg_rules import (BACKTRACK_HALVINGS, RECOMPUTE_EVERY, CGStep, Record, bounded_move, bounded_sets,
                        entering_pressure, initial_pressure, iterate_residual, run_constrained_cg)
from ..plastic import carry_force, note_fully_plastic

__all__ = ["solve_periodic_qp", "SINGLE_ABOVE", "SINGLE_START"]

SINGLE_ABOVE = 1e-4  # KKT residual above which the products run in single precision
SINGLE_START = 100.0  # ... from a first residual above SINGLE_START * SINGLE_ABOVE


def solve_periodic_qp(op, h, *, force=None, approach=None, lam=0.0, x0=None, rtol=1e-10, maxiter=None,
                      callback=None, scale=None, u0=None, confirm=True, threshold=4.0, hardness=None):
    """Solve the Kalker QP ``min 1/2 p.(C + lam) p + p.(h - delta), p >= 0`` on a periodic cell (NumPy).

    Parameters
    ----------
    op : bem.periodic.PeriodicOperator
        ``C`` on the cell, on the ``"cpu"`` device.
    h : ndarray
        Gap at the nodes, brick array [length].
    force, approach : float
        Exactly one: total force on the cell ``P`` [force] or approach ``delta`` [length].
    lam : float or ndarray
        Linear layer compliance [length/pressure], >= 0: uniform, or per node (brick array; Newton's
        model compliance ``D``, with the preconditioner of :func:`bem.kalker.compliance_preconditioner`
        on the contact of ``x0``).
    x0 : ndarray, optional
        Initial pressure (brick array); negative entries are clipped.
    rtol : float
        Tolerance on the KKT residual (the rule of :func:`bem.kalker.solve_qp`, checked on an
        exactly recomputed ``C p`` unless ``confirm`` is False).
    maxiter : int, optional
        Iteration limit (default ``max(200, 10 * sqrt(N))``).
    callback : callable, optional
        ``callback(k, p)`` after every iteration.
    scale, u0, confirm
        As for :func:`bem.kalker.solve_qp`: the displacement scale of the KKT residual [length],
        ``C x0`` where the caller has it (the iterate then starts from ``x0`` as given), and
        whether to confirm the stopping check on an exact product. Unconfirmed, a solve that
        stops at ``rtol >= SINGLE_ABOVE`` returns ``C p`` to single precision.
    threshold : float
        With a per-node ``lam``: nodes with ``lam > threshold C_nn`` get the Jacobi preconditioner,
        as in :func:`bem.kalker.compliance_preconditioner`.
    hardness : float, optional
        The bound ``p <= H`` [pressure] (:mod:`bem.plastic`): the search direction lives on the elastic
        contact ``0 < p < H`` and the step is :func:`bem.cg_rules.bounded_move`.

    Returns
    -------
    bem.cg_rules.QPSolution
        As :func:`bem.kalker.solve_qp` with its FFT preconditioner; ``op.n_matvec`` counts the
        products ``(C + lam) v`` (spectral multiplications, in single or double precision).
    """
    lat = op.lattice
    a = lat.node_area
    per_node = np.ndim(lam) > 0
    D = np.asarray(lam, dtype=float) if per_node else None
    lam = 0.0 if per_node else float(lam)
    h = np.asarray(h, dtype=float)
    if maxiter is None:
        maxiter = max(200, int(10 * math.sqrt(lat.n_nodes)))
    target = None if force is None else force / a
    if u0 is None or x0 is None:
        p = initial_pressure(op, h, D if per_node else lam, force, approach, x0, hardness)
        if target is not None:
            p = p if float(p.sum()) > 0 else np.ones(lat.shape)
            if hardness is None:
                p *= target / float(p.sum())
            else:
                p = carry_force(np, p, target, hardness, np.ones(lat.shape, dtype=bool))
        u0 = None
    else:  # the caller's iterate and its product, as they are
        p = np.array(x0, dtype=float)
    p = np.array(p, dtype=float)  # updated in place below
    pf = p.reshape(-1)
    A = op.symbol(lam)  # C + lam I
    soft = None
    if per_node:  # compliance_preconditioner: the FFT inverse of C + median D on the stiff contact, Jacobi elsewhere
        stiff = D <= threshold * op.diagonal
        sel = stiff & (p > 0)
        lam_pc = float(np.median(D[sel])) if bool(sel.any()) else 0.0
        # the Jacobi estimate 1 / (C_nn + D) at the nodes that need it (whole only for the bounded step)
        jacobi = 1.0 / (op.diagonal + D) if hardness is not None else None
        soft = None if bool(stiff.all()) else ~stiff
    else:
        lam_pc, jacobi = lam, 1.0 / (op.diagonal + lam)
    M = op.symbol(lam_pc, inverse=True, single=True)
    A32 = op.symbol(lam, single=True)
    r_hat = None  # the spectrum of (C + lam) t, kept from step to step

    def product(v):
        op.n_matvec += 1
        if single:
            x = op.spectrum(v.astype(np.float32))
            return op.mix(x, A32, out=x)
        x = op.spectrum(v)
        return op.mix(x, A, out=x)

    def precondition(r32, idx, r_c):  # M r at the nodes idx: r_c = r there, r32 = r (float32) at the stiff nodes
        x = op.spectrum(r32)
        z = op.brick(op.mix(x, M, out=x), overwrite=True).reshape(-1)[idx].astype(float)
        if soft is not None:
            out = softf[idx]
            z[out] = jacobi_at(idx[out]) * r_c[out]
        return z

    single = False  # the first product in double precision: it sets the scale of the KKT residual
    if u0 is None:
        u, stale = op.brick(product(p), overwrite=True), 0
    else:  # C x0 from the caller, confirmed like an incremental update
        u, stale = np.array(u0, dtype=float), 1
    if per_node:
        u += D * p
        softf, Df = (None if soft is None else soft.reshape(-1)), D.reshape(-1)

        def jacobi_at(nodes):  # 1 / (C_nn + D) at the nodes (flat indices): the numbers of the whole array
            return 1.0 / (op.diagonal + Df[nodes])
    # the search direction, transformed in single precision, and in the same array the gap on the contact
    # that the preconditioner transforms (the direction at the contact nodes is taken out first)
    t = r32 = np.zeros(lat.shape, dtype=np.float32)
    g = np.empty(lat.shape)
    r32f = r32.reshape(-1)
    # the last preconditioned gap, on its contact only: its nodes (sorted) and values
    z_nodes, z_values = np.zeros(0, dtype=np.intp), np.zeros(0)
    gf, tf = g.reshape(-1), t.reshape(-1)

    def z_prev_at(nodes):  # the last z at the (sorted) nodes, 0 where they were off its contact
        if not z_nodes.size:
            return np.zeros(nodes.size)
        pos = np.searchsorted(z_nodes, nodes)
        np.minimum(pos, z_nodes.size - 1, out=pos)
        return np.where(z_nodes[pos] == nodes, z_values[pos], 0.0)
    gz_old, m_one, m_full = 1.0, None, None
    record, kkt, delta = Record(rtol, maxiter), np.inf, approach
    was_on = p > 0  # the contact of the previous iterate
    n_prev = int(np.count_nonzero(was_on))
    fixed_scale = scale
    contact = idx = g_c = p_c0 = g_min = None

    bounded, sets = hardness is not None, None
    restart = False  # with a hardness: the last step was shortened to carry the force, the direction restarts
    was_plastic, bk = (p >= hardness, operator_backend(op)[0]) if hardness is not None else (None, None)

    def measure_bounded(k):  # measure() with the bound: the CG lives on the elastic contact 0 < p < H
        nonlocal idx, g_c, p_c0, delta, g_min, single, sets
        np.add(u, h, out=g)  # the gap is g - delta
        sets = bounded_sets(bk, p, g, hardness, delta, force)
        idx, delta, g_min = sets.idx, sets.delta, sets.gap_min
        g_c, p_c0 = np.take(gf, idx) - delta, np.take(pf, idx)
        scale = max(float(u.max()), -float(u.min())) if fixed_scale is None else fixed_scale
        kkt = iterate_residual(float(np.abs(g_c).max(initial=0.0)), g_min, scale, lambda: float(np.abs(g - delta).max()),
                               None if force is None else abs(a * float(pf.sum()) - force) / force,
                               plastic_gap=sets.plastic_gap)
        if k == 1:
            single = kkt > SINGLE_START * SINGLE_ABOVE or (kkt > SINGLE_ABOVE and rtol >= SINGLE_ABOVE)
        return kkt

    def measure(k):  # the gap, the approach under force control and the KKT residual of the iterate
        nonlocal contact, idx, g_c, p_c0, delta, g_min, single
        contact = p > 0
        idx = np.flatnonzero(contact)  # a boolean array: several times faster than flatnonzero(p)
        np.add(u, h, out=g)  # the gap is g - delta: delta is subtracted on the contact only
        g_c, p_c0 = np.take(gf, idx), np.take(pf, idx)
        if force is not None:
            delta = float(np.mean(g_c)) if idx.size else math.nan
        g_c -= delta
        scale = max(float(u.max()), -float(u.min())) if fixed_scale is None else fixed_scale
        g_min = float(g.min()) - delta
        kkt = iterate_residual(float(np.abs(g_c).max(initial=0.0)), g_min, scale, lambda: float(np.abs(g - delta).max()),
                               None if force is None else abs(a * float(p_c0.sum()) - force) / force)
        if k == 1:  # single precision pays for its closing product only well above SINGLE_ABOVE
            single = kkt > SINGLE_START * SINGLE_ABOVE or (kkt > SINGLE_ABOVE and rtol >= SINGLE_ABOVE)
        return kkt

    def confirms(kkt):  # recompute C p exactly at the tolerance, or in double precision below SINGLE_ABOVE
        nonlocal single, u, stale
        if (kkt <= rtol and (stale or single) and confirm) or (single and kkt <= SINGLE_ABOVE):
            single = False  # confirm on an exact product, or go on in double precision
            u = None  # the product replaces it: not both at once
            u, stale = op.brick(product(p), overwrite=True), 0
            if per_node:
                u += D * p
            return True
        return False

    def observe_bounded():  # changes of the contact and of the plastic set
        nonlocal was_on, was_plastic
        changes = int(np.count_nonzero(sets.on != was_on)) + int(np.count_nonzero(sets.plastic != was_plastic))
        was_on, was_plastic = sets.on, sets.plastic
        n_touch = idx.size + sets.pl.size
        return float(pf.max(initial=0.0)), n_touch, changes, n_touch == 0 and g_min >= 0

    def observe():
        nonlocal was_on, n_prev
        kept = int(np.count_nonzero(was_on.reshape(-1)[idx]))  # nodes in both contacts
        changes = (idx.size - kept) + (n_prev - kept)
        was_on, n_prev = contact, idx.size
        return float(p_c0.max(initial=0.0)), int(idx.size), changes, idx.size == 0 and g_min >= 0

    def advance(k):  # one step of the constrained CG in the Fourier basis; (message, status) where none is taken
        nonlocal m_full, m_one, gz_old, r_hat, u, stale, z_nodes, z_values
        if bounded and not idx.size:  # every contact node plastic: only entering and leaving nodes move
            return bounded_step(0.0, np.zeros(0), None, None)
        t_old = np.take(tf, idx)  # the last direction on the contact (r32 is t)
        # the gap on the contact, single precision (on its stiff part with a per-node compliance)
        r32.fill(0.0)  # a fill: faster than zeroing the nodes of the last step
        if soft is None:
            r32f[idx] = g_c
        else:
            on = ~softf[idx]
            r32f[idx[on]] = g_c[on]
        z = precondition(r32, idx, g_c)
        if force is not None and soft is None:
            z -= z.mean()
        elif force is not None:
            # oblique projection onto sum z = 0, as in bem.kalker.solve_qp: z - M1 (1.z) / (1.M1), with M1
            # of the starting contact (any M1 with a nonzero sum keeps sum z = 0; one product a solve)
            if m_full is None:
                np.multiply(pf.reshape(p.shape) > 0, stiff, out=r32, casting="unsafe")
                x = op.spectrum(r32)  # M (contact & stiff), and the Jacobi estimate at the soft nodes
                m_full = op.brick(op.mix(x, M, out=x), overwrite=True).reshape(-1)  # single precision, kept so
            m_one = m_full[idx].astype(float)
            on_soft = softf[idx]
            m_one[on_soft] = jacobi_at(idx[on_soft])  # the Jacobi estimate at the soft nodes
            if not m_one.sum() > 0:  # a contact far from the starting one: the mean instead
                m_one = np.ones(idx.size)
            z -= m_one * (z.sum() / m_one.sum())
        gz = float(np.einsum("i,i->", g_c, z))  # no threaded BLAS
        # Polak-Ribiere+ on the current contact (z_prev is 0 at the nodes that entered it)
        beta = 0.0 if k == 1 or gz_old == 0 or restart else max(  # gz_old = 0: one contact node under force control
            0.0, (gz - float(np.einsum("i,i->", g_c, z_prev_at(idx)))) / gz_old)
        z_nodes, z_values = idx, z.copy()
        t_c = z + beta * t_old
        if force is not None:  # nodes that left the contact broke the zero sum of t
            t_c -= m_one * (t_c.sum() / m_one.sum()) if m_one is not None else t_c.mean()
        gt = float(np.einsum("i,i->", g_c, t_c))
        if not gt > 0:  # no descent along t after a change of the contact: steepest descent
            t_c, gt = z, gz
        t.fill(0.0)
        tf[idx] = t_c
        gz_old = gz
        T = op.spectrum(t)
        op.n_matvec += 1
        R = r_hat = op.mix(T, A32, out=r_hat)  # (C + lam) t, single precision
        tt = op.inner(T, R)  # t.(C + lam) t; t has zero sum on the contact under force control
        if per_node:
            D_c = Df[idx]
            tt += float(np.einsum("i,i,i->", D_c, t_c, t_c))
        if not np.any(t_c):
            tau = 0.0  # a single contact node under force control: only entering nodes can move
        elif tt <= 0 or not math.isfinite(tt):
            return f"search direction lost positive curvature (t.Ct = {tt:.3e})", "stalled"
        else:
            tau = gt / tt  # the minimum along t (gt = gz when the contact has not changed)
        if bounded:
            return bounded_step(tau, t_c, R, D_c if per_node else None)
        p_c = p_c0 - tau * t_c
        clipped = p_c < 0
        p_c[clipped] = 0.0
        pf[idx] = p_c  # p is 0 off idx
        # re-entering nodes (p = 0, g < 0): the step tau of the preconditioned direction with the Jacobi
        # estimate of M there, -f min(tau, 1) g / (C_nn + lam) (module docstring: entering nodes)
        low = np.flatnonzero(g < delta)
        overlap = low[pf[low] == 0]
        p_o = None
        if overlap.size:
            cap = jacobi_at(overlap) if per_node else jacobi
            p_o = entering_pressure(np, gf[overlap] - delta, tau, cap, per_node, preconditioned=True)
        entered = bool(overlap.size)
        s = 1.0
        if target is not None:
            total = float(p_c.sum()) + (float(p_o.sum()) if entered else 0.0)
            if not total > 0:  # every node left the contact and none entered: no force to rescale
                pf[idx] = p_c0
                return "the iteration produced a non-finite value", "nonfinite"
            s = target / total
            p_c *= s
            pf[idx] = p_c
        if entered:
            if s != 1.0:
                p_o *= s
            pf[overlap] = p_o
        if bool(clipped.any()) or entered or stale >= RECOMPUTE_EVERY:
            u = None
            u, stale = op.brick(product(p), overwrite=True), 0
            if per_node:  # u += D p, on the nodes where p > 0
                uf = u.reshape(-1)
                uf[idx] += D_c * p_c
                if entered:
                    uf[overlap] += Df[overlap] * p_o
        else:  # p = s (p - tau t) on the contact: u = s (u - tau (C + lam) t), plus D t per node
            cr = op.brick(R, overwrite=True)
            cr *= np.float32(tau)
            u -= cr
            if per_node:
                uf = u.reshape(-1)
                uf[idx] -= tau * (D_c * t_c)
            if s != 1.0:
                u *= s
            stale += 1
        return None

    def bounded_step(tau, t_c, R, D_c):  # the step of the bounded QP (bem.cg_rules.bounded_move) and its product
        nonlocal u, stale, restart
        changed, _, s, failure, restart = bounded_move(bk, p, sets, p_c0, t_c, tau, g, jacobi, per_node, target,
                                                       hardness, preconditioned=True, halvings=BACKTRACK_HALVINGS)
        if failure is not None:
            return failure
        if changed or R is None or stale >= RECOMPUTE_EVERY:
            u = None
            u, stale = op.brick(product(p), overwrite=True), 0
            if per_node:
                u += D * p
        else:  # the elastic nodes moved along t and were scaled by s (the plastic ones by s - 1 of round-off)
            cr = op.brick(R, overwrite=True)
            cr *= np.float32(tau)
            u -= cr
            if per_node:
                u.reshape(-1)[idx] -= tau * (D_c * t_c)
            if s != 1.0:
                u *= s
            stale += 1
        return None

    step = CGStep(measure_bounded, confirms, observe_bounded, advance, p.copy) if bounded else CGStep(
        measure, confirms, observe, advance, p.copy)
    kkt = run_constrained_cg(step, record, maxiter, callback)
    note_fully_plastic(record, sets.bracket if bounded else None, bounded and not idx.size)
    # C p: the layer's closure is not a displacement
    elastic = u - (D if per_node else lam) * p if per_node or lam else u.astype(float, copy=False)
    return record.solution(p, delta, kkt, elastic, "Kalker QP (periodic)")
