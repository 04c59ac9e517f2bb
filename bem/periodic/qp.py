"""Kalker's QP on a periodic cell: the conjugate gradients of :func:`bem.kalker.solve_qp` in the Fourier basis.

The step of :meth:`bem.periodic.PeriodicOperator.qp` in the one loop :func:`bem.cg_rules.run_constrained_cg`: the
iteration of :func:`bem.kalker.solve_qp` (constrained conjugate gradients on the active set, Polonsky & Keer 1999; its
FFT preconditioner, entering rule, Jacobi cap and stopping rule) on :class:`bem.periodic.PeriodicOperator`, whose ``C``
is diagonal in the Fourier basis of the cell (a 2 x 2 block per frequency, one block row per row parity); every node is
a candidate. Nodes entering the contact do not restart the directions: ``t = z + beta t_old`` on the current contact,
``beta = max(0, g.(z - z_old) / g_old.z_old)`` (Polak-Ribiere+), the step the minimum along ``t``, ``tau = g.t / t.(C +
lam) t`` (``g.t = g.z`` while the contact does not change), and ``t = z`` where ``g.t <= 0``. On a rough surface, whose
contact set changes at most iterations until it settles, a loop that restarts at every entering node degrades to
preconditioned steepest descent (82 iterations against 51 on a 256^2 self-affine cell,
``tests/bem/test_periodic_qp.py``). While the contact changes in the first ``EARLY`` iterations (uniform compliance, no
hardness; :mod:`bem.periodic.qp_parts`) the step is ``STEP_SHARE`` of that minimum (with nodes clipped, the energy along
the clipped path is least at 0.85-0.95 of it) and only the nodes whose gap is below ``ENTER_SHARE`` times the most
negative one enter (without it, half of those that enter leave at the next step). An entering node (``p = 0``, ``g <
0``) takes the step with a share of the Jacobi estimate of the preconditioner there, ``p = -f min(tau, 1) g / (C_nn +
lam)`` (``f`` = :data:`bem.cg_rules.ENTERING_FRACTION`): ``tau`` is dimensionless here (``t`` is ``M g``), and ``-tau
g`` would give it ``tau C_nn`` of its Jacobi pressure, a fraction that falls with the step (nodes entering with almost
no pressure and leaving, at a constant KKT residual, on a 672 x 776 rough cell at 1e-4 of the mean contact pressure:
``tests/bem/test_periodic_robustness.py``). Further:

- the iteration keeps ``u = (C + lam) p`` in double precision, updated after a step by the product of its move in
  single precision (rounded to a relative ``1e-7`` of the step, which falls with the residual): where the contact set
  did not change ``tau (C + lam) t``, the search direction's product; where it changed (NumPy, a confirmed stop)
  that of ``t'``, ``tau t' = p - p_new / s``: ``t`` but at the clipped and entering nodes. ``u`` is recomputed from
  ``p`` after every 20 updates, and at a change while the products run in single precision (below), before ``u`` was
  once recomputed in double precision (from the caller's ``u0``), in an unconfirmed solve (whose caller takes its
  ``u``) or off NumPy;
- the curvature ``t.(C + lam) t`` is a sum over the spectrum of that product (Parseval, summed in double precision,
  block by block as the product is made: :func:`bem.periodic.spectra.mixed`);
- the preconditioner runs in single precision: it only has to approximate ``(C + lam)^-1``; without a hardness it is
  corrected at the edges of the contact once the contact settles (:mod:`bem.periodic.edge`);
- so does the recomputed ``u`` while the KKT residual is above ``1e-4`` (:data:`SINGLE_ABOVE`), in a solve that
  starts above ``1e-2`` (:data:`SINGLE_START` times that) or stops above ``1e-4`` (``rtol >= SINGLE_ABOVE``, a
  Newton step's model far from the answer), where the rounding of single precision (a relative ``1e-7`` of ``C p``)
  is far below what the iteration resolves: halved transforms in the early iterations, where the contact set
  settles. At the first residual below it (or at ``rtol`` when the stopping check is confirmed) ``u`` is recomputed
  in double precision, and so from there on; the stopping check, when confirmed, is on a double-precision product;
- after a step that let no node enter and left every contact node a positive pressure, the contact is the same: the
  next iteration reuses its nodes, the step's pressures and direction there and ``D`` on it, with no selection and no
  gathers; after another, the next contact is made from the step's arrays (:class:`bem.periodic.qp_parts.ContactNodes`);
- on a large cell, with numba, the block products, three passes over the cell and the step's move, put and brick
  writes (:mod:`bem.periodic.step_passes`) run compiled on the FFT threads.

With a compliance per node (the model of a Newton step, :mod:`bem.newton`) the products are those of ``C`` alone, ``u =
C p + D p`` (plus the gap's ``offset``) and the curvature adds ``sum D t^2``; the preconditioner is that of
:func:`bem.kalker.compliance_preconditioner` (single precision), corrected at the edges of its FFT part's nodes, with
its oblique projection under force control (by ``M 1`` of the starting contact, or of the first model QP of the
Newton solve, its ``projection``: any direction of nonzero sum).

With a hardness ``H`` (:mod:`bem.plastic`) the direction lives on the elastic contact ``0 < p < H`` and the step is
:func:`bem.cg_rules.bounded_move`; the directions restart (``beta = 0``) after a step shortened or capped at ``H`` to
carry the force (without: no convergence in 688 iterations on a 64-column self-affine cell at 18 % of ``H``,
``tests/bem/test_hardness_units.py``), not where nodes enter or leave (531 iterations on a 512^2 law of 20 pressures at
``H = E* h'_rms``, 695 when those restart too).

A step costs four transforms of the cell in single precision while the contact set does not change (two for the
preconditioner, two for the search direction's product), five where it changes (``u`` recomputed: two in double
precision below ``SINGLE_ABOVE``). The step runs on the array namespace of the operator's device (:mod:`bem.backend`:
NumPy, CuPy or any array API namespace with ``xp.fft``); the host receives its scalars (about 16 a step, more with a
compliance per node or a hardness, and the sizes of three node selections). Other transforms round differently and take
the same iterations (``tests/bem/test_backend_namespace.py``); NumPy reuses arrays (:mod:`bem.periodic.qp_parts`).
"""

from __future__ import annotations

import math

import numpy as np

from .. import heap
from ..backend import operator_backend
from ..cg_rules import (BACKTRACK_HALVINGS, RECOMPUTE_EVERY, CGStep, Record, bounded_move, bounded_sets,
                        elastic_displacement, entering_pressure, initial_pressure, is_per_node, is_stiff,
                        iterate_residual, run_constrained_cg)
from ..newton_passes import with_compliance
from ..plastic import carry_force, in_place, note_fully_plastic
from .edge import EdgeCorrection
from .passes import kernels
from .qp_parts import (STEP_SHARE, ContactBrick, ContactNodes, KeptOnContact, Projection, StepArrays, added_into,
                       early_steps, most_open, multiplied_into, product_array, weighted_square)
from .step_passes import step_kernels

__all__ = ["solve_periodic_qp", "SINGLE_ABOVE", "SINGLE_START"]

SINGLE_ABOVE = 1e-4  # KKT residual above which the products run in single precision
SINGLE_START = 100.0  # ... from a first residual above SINGLE_START * SINGLE_ABOVE


def solve_periodic_qp(op, h, *, force=None, approach=None, lam=0.0, x0=None, rtol=1e-10, maxiter=None,
                      callback=None, scale=None, u0=None, confirm=True, threshold=4.0, hardness=None,
                      overwrite_x0=False, offset=None, overwrite_u0=False, projection=None):
    """Solve the Kalker QP ``min 1/2 p.(C + lam) p + p.(h - delta), p >= 0`` on a periodic cell.

    Parameters
    ----------
    op : bem.periodic.PeriodicOperator
        ``C`` on the cell, on any device (the arrays in and out are in its namespace).
    h : array
        Gap at the nodes, brick array [length].
    force, approach : float
        Exactly one: total force on the cell ``P`` [force] or approach ``delta`` [length].
    lam : float or ndarray
        Linear layer compliance [length/pressure], >= 0: uniform, or per node (brick array; Newton's model compliance
        ``D``, with the preconditioner of :func:`bem.kalker.compliance_preconditioner` on the contact of ``x0``).
    x0 : ndarray, optional
        Initial pressure (brick array); negative entries are clipped.
    overwrite_x0 : bool
        Whether a float64 NumPy ``x0`` may hold the iterate (not copied: one array of the cell fewer).
    rtol : float
        Tolerance on the KKT residual (:func:`bem.kalker.solve_qp`'s rule, on an exact ``C p`` unless not ``confirm``).
    maxiter : int, optional
        Iteration limit (default ``max(200, 10 * sqrt(N))``).
    callback : callable, optional
        ``callback(k, p)`` after every iteration.
    scale, u0, confirm, offset
        As for :func:`bem.kalker.solve_qp`: the displacement scale of the KKT residual [length], ``C x0`` where the
        caller has it (the iterate then starts from ``x0`` as given), whether to confirm the stopping check on
        an exact product (unconfirmed, a stop at ``rtol >= SINGLE_ABOVE`` returns ``C p`` in single precision), and
        the gap's part at some nodes, ``(nodes, values)``, added to ``h`` there (no array of the sum).
    overwrite_u0 : bool
        Whether a float64 NumPy ``u0`` may hold the iteration's ``(C + lam) p``, in either precision (not copied: one
        array of the cell fewer; ``u0`` is then no longer ``C x0``).
    projection : bem.periodic.qp_parts.Projection, optional
        With a per-node ``lam``, ``M 1`` of the oblique projection: used where it holds one, else made here into it.
    threshold : float
        With a per-node ``lam``: nodes with ``lam > threshold C_nn`` get the Jacobi preconditioner (as in
        :func:`bem.kalker.compliance_preconditioner`).
    hardness : float, optional
        The bound ``p <= H`` [pressure] (:mod:`bem.plastic`): the search direction lives on the elastic contact ``0 <
        p < H`` and the step is :func:`bem.cg_rules.bounded_move`.

    Returns
    -------
    bem.cg_rules.QPSolution
        As :func:`bem.kalker.solve_qp` with its FFT preconditioner; ``op.n_matvec`` counts the products ``(C + lam) v``
        (spectral multiplications, in single or double precision).
    """
    lat, bk = op.lattice, operator_backend(op)[0]
    a, xp, per_node = lat.node_area, bk.xp, is_per_node(lam)
    D = bk.asarray(lam, xp.float32 if getattr(lam, "dtype", None) == xp.float32 else None) if per_node else None
    lam, h = 0.0 if per_node else float(lam), bk.asarray(h)
    maxiter = max(200, int(10 * math.sqrt(lat.n_nodes))) if maxiter is None else maxiter
    target = None if force is None else force / a
    if u0 is None or x0 is None:  # a new array, or x0 itself with overwrite_x0
        p = initial_pressure(op, h, D if per_node else lam, force, approach, x0, hardness, overwrite_x0)
        if target is not None:
            p = p if float(xp.sum(p)) > 0 else xp.ones(lat.shape, dtype=xp.float64)
            if hardness is None:
                p *= target / float(xp.sum(p))
            else:
                p = carry_force(xp, p, target, hardness, xp.ones(lat.shape, dtype=xp.bool))
        u0 = None
    else:  # the caller's iterate and its product, as they are
        p = x0 if overwrite_x0 and in_place(bk, x0) else bk.copy(bk.asarray(x0))  # updated in place below
    A, diag = op.symbol(lam), float(op.diagonal)  # C + lam I, C_nn
    passes, steps = kernels(lat.n_nodes, bk), step_kernels(lat.n_nodes, bk)  # over the cell, over the contact
    soft, stiff, made = False, None, False  # soft: some node's compliance dominates (Jacobi there); stiff: for M 1
    lam_pc, jacobi = lam, 1.0 / (diag + lam)
    if per_node:  # compliance_preconditioner: the FFT inverse of C + median D on the stiff contact, Jacobi elsewhere
        stiff = is_stiff(D, diag, threshold)
        sel = stiff & (p > 0)
        lam_pc = bk.median(D[sel], overwrite=True) if bool(xp.any(sel)) else 0.0
        jacobi = 1.0 / (diag + xp.astype(D, xp.float64)) if hardness is not None else None  # for bounded_move
        soft = not bool(xp.all(stiff))
        made = projection is not None and projection.values is not None  # M 1 given: stiff not held
        sel, stiff = None, stiff if soft and not made else None  # not held through the solve (stiff: to M 1)
    M, A32 = op.symbol(lam_pc, inverse=True, single=True), op.symbol(lam, single=True)
    brick = ContactBrick(bk, lat.shape, getattr(steps, "write", None))  # the gap on the contact, then the direction
    work = StepArrays(bk, lat.shape)  # the spectra and bricks of the products (NumPy: one array, reused)

    def product(v):  # (C + lam) v, a spectrum in work's bytes
        op.n_matvec += 1
        x = op.spectrum(work.single(v) if single else v, out=work.spectrum(np.complex64 if single else np.complex128))
        return op.mix(x, A32 if single else A, out=x)

    def apply_m(r32, out=None):  # M r, single precision (the spectrum in work's bytes), into out
        x = op.spectrum(r32, out=work.spectrum(np.complex64))
        return op.brick(op.mix(x, M, out=x), overwrite=True, out=out)

    def jacobi_at(sel, D_n=None):  # 1 / (C_nn + D) at the selected nodes (D_n: D there, where the caller has it)
        return 1.0 / (diag + (passes.gather(D, sel) if D_n is None else D_n))

    def plus_dp(v):  # v + D p (NumPy: into v, D p in work's bytes where not compiled; no spectrum held there)
        return with_compliance(v, D, p, v, 1, scratch=work.brick64()) if bk.is_numpy else added_into(bk, v, D * p)

    def product_u():  # u = (C + lam) p; on NumPy in the last u or in u0's bytes (qp_parts.product_array)
        nonlocal u, exact_base
        u = product_array(u, np.float32 if single else np.float64, home) if bk.is_numpy else None
        heap.release(16 * math.prod(work.spectrum_shape))  # the C library's free heap before a product of the cell
        u, exact_base = op.brick(product(p), overwrite=True, out=u), not single
        return u

    def offset_added(v, times=1.0):  # v plus times the gap's offset (NumPy: in place)
        return v if offset is None or not times else passes.add_at(v, *offset, times)

    def exact_u():  # (C + lam) p, D p per node, and the gap's offset
        return offset_added(plus_dp(product_u()) if per_node else product_u())

    # the first product in double precision (the KKT residual's scale); exact_base: u from a double-precision product
    single, u, exact_base, home = False, None, False, None  # (not the caller's u0 nor single); stale: updates since
    if u0 is None:
        u, stale = exact_u(), 0
    else:  # C x0 from the caller, confirmed like an incremental update; home: u0 holding u, in either precision
        home = u0 if overwrite_u0 and in_place(bk, u0) else None
        u = bk.copy(bk.asarray(u0)) if home is None else u0
        u, stale = offset_added(plus_dp(u) if per_node else u), 1
    last_z, record = KeptOnContact(bk, lat.shape), Record(rtol, maxiter)  # last_z: the last preconditioned gap
    gz_old, m_one, m_full, m_at, fixed_scale, delta = 1.0, None, None, None, scale, approach
    nodes = ContactNodes(bk, p, getattr(passes, "merge", None))  # the iterate's contact (steady: the last step's)
    idx = g_c = p_c0 = g_min = u_range = None  # u_range: max u, min u

    bounded, sets, restart = hardness is not None, None, False  # restart: a bounded step shortened to carry the force
    edge = None if bounded else EdgeCorrection(bk, apply_m, lat.shape, diag + lam_pc, M, work.brick32)  # M at edges
    was_on, was_plastic = (nodes.was_on, p >= hardness) if bounded else (None, None)  # the bound's own counts
    g = np.empty(lat.shape) if bounded and bk.is_numpy else None  # the gap u + h, an array in the bounded QP only
    enter = np.empty(lat.shape, dtype=bool) if bk.is_numpy and not bounded else None  # nodes that may enter

    def residual(k, contact_gap, force_error, plastic_gap=None):
        nonlocal single
        scale = max(u_range[0], -u_range[1]) if fixed_scale is None else fixed_scale
        kkt = iterate_residual(contact_gap, g_min, scale, lambda: float(xp.max(xp.abs(u + h - delta))), force_error,
                               plastic_gap=plastic_gap)
        if k == 1:  # single precision pays for its closing product only well above SINGLE_ABOVE
            single = kkt > SINGLE_START * SINGLE_ABOVE or (kkt > SINGLE_ABOVE and rtol >= SINGLE_ABOVE)
        return kkt

    def measure_bounded(k):  # measure() with the bound: the CG lives on the elastic contact 0 < p < H
        nonlocal idx, g_c, p_c0, delta, g_min, sets, g, u_range
        g, _, *u_range = passes.gap(u, h, g)  # the gap is g - delta; the extremes of u, the residual's scale
        sets = bounded_sets(bk, p, g, hardness, delta, force)
        idx, delta, g_min = sets.idx, sets.delta, sets.gap_min
        g_c, p_c0 = bk.take(g, idx) - delta, bk.take(p, idx)
        return residual(k, bk.max0(xp.abs(g_c)), None if force is None else abs(a * float(xp.sum(p)) - force) / force,
                        sets.plastic_gap)

    def measure(k):  # the gap, the approach under force control and the KKT residual of the iterate
        nonlocal idx, g_c, p_c0, delta, g_min, enter, u_range
        idx, p_c0 = nodes.read(p)
        g_c = passes.gap_at(u, h, idx)  # the gap is u + h - delta: delta is subtracted on the contact only
        delta = (float(xp.mean(g_c)) if bk.count(idx) else math.nan) if force is not None else delta
        enter, g_low, *u_range = passes.scan(u, h, delta, p, enter)  # with the mask of the entering test
        g_c -= delta
        g_min = g_low - delta
        force_error = None if force is None else abs(a * float(xp.sum(p_c0)) - force) / force
        return residual(k, bk.max0(xp.abs(g_c)), force_error)

    def confirms(kkt):  # recompute C p exactly at the tolerance, or in double precision below SINGLE_ABOVE
        nonlocal single, u, stale
        if (kkt <= rtol and (stale or single) and confirm) or (single and kkt <= SINGLE_ABOVE):
            single = False  # confirm on an exact product, or go on in double precision
            u, stale = exact_u(), 0
            return True
        return False

    def observe_bounded():  # changes of the contact and of the plastic set
        nonlocal was_on, was_plastic
        changes = int(xp.count_nonzero(sets.on != was_on)) + int(xp.count_nonzero(sets.plastic != was_plastic))
        was_on, was_plastic = sets.on, sets.plastic
        n_touch = bk.count(idx) + bk.count(sets.pl)
        return bk.max0(p), n_touch, changes, n_touch == 0 and g_min >= 0

    def observe():
        n, changes = nodes.changes()
        return bk.max0(p_c0), n, changes, n == 0 and g_min >= 0

    def advance(k):  # one step of the constrained CG in the Fourier basis; (message, status) where none is taken
        nonlocal m_full, m_one, m_at, gz_old, u, stale, stiff, g_c
        if bounded and not bk.count(idx):  # every contact node plastic: only entering and leaving nodes move
            return bounded_step(0.0, xp.zeros(0, dtype=xp.float64), None, None)
        steady = nodes.steady  # the last direction on the contact (float32) as written, D and what follows there
        if steady:
            t_old, (D_c, soft_c) = brick.last, nodes.kept
        else:  # gathers, at the entering nodes only where the contact was made from the step (ContactNodes.over)
            t_old = nodes.over(idx, lambda n: bk.take(brick.values, n), brick.last)
            D_c = nodes.over(idx, lambda n: passes.gather(D, n), nodes.kept[0]) if per_node else None
            nodes.kept = D_c, (soft_c := None if not soft else ~is_stiff(D_c, diag, threshold))
        # M g of the gap on the contact in single precision (on its stiff part, and Jacobi at the soft nodes, with a
        # compliance per node), gathered there
        z = apply_m(brick.write(idx, g_c if not soft else xp.where(soft_c, 0.0, g_c)), work.brick32())
        z = passes.gather(z, idx) if soft_c is None else steps.soft_gather(z, idx, soft_c, g_c, D_c, diag)
        z = z if edge is None else edge.applied(z, g_c, idx, record.history["changes"], nodes, soft_c)
        if force is not None and not soft:
            z -= xp.mean(z)
        elif force is not None:
            # oblique projection onto sum z = 0, as in bem.kalker.solve_qp: z - M1 (1.z) / (1.M1), M1 the given
            # projection's or of the starting contact (any M1 with a nonzero sum keeps sum z = 0; a product at most)
            if m_full is None:  # M (contact & stiff), made into the given projection where it holds none
                m_full, stiff = projection if made else (projection or Projection()).make(
                    bk, apply_m(xp.astype((p > 0) & stiff, xp.float32))), None
            if not steady:  # m_at: M 1 at the contact's nodes, the Jacobi estimate at the soft ones (they stay soft)
                m_at = nodes.over(idx, lambda n: m_full.at(bk, n), m_at)
                m_one = m_at = xp.where(soft_c, jacobi_at(idx, D_c), m_at)
                if not float(xp.sum(m_one)) > 0:  # a contact far from the starting one: the mean instead
                    m_one = xp.ones(bk.count(idx), dtype=xp.float64)
            z -= m_one * (float(xp.sum(z)) / float(xp.sum(m_one)))
        gz = bk.dot(g_c, z)  # no threaded BLAS
        # Polak-Ribiere+ on the current contact (z_prev is 0 at the nodes that entered it)
        beta = 0.0 if k == 1 or gz_old == 0 or restart else max(  # gz_old = 0: one contact node under force control
            0.0, (gz - bk.dot(g_c, last_z.at(idx, nodes))) / gz_old)
        last_z.keep(idx, z)
        t_c = z + beta * t_old
        if force is not None:  # nodes that left the contact broke the zero sum of t
            t_c -= m_one * (float(xp.sum(t_c)) / float(xp.sum(m_one))) if m_one is not None else xp.mean(t_c)
        gt = bk.dot(g_c, t_c)
        if not gt > 0:  # no descent along t after a change of the contact: steepest descent
            t_c, gt = z, gz
        gz_old, z = gz, None  # z not held past the direction
        T = op.spectrum(brick.write(idx, t_c), out=work.spectrum(np.complex64))
        op.n_matvec += 1
        # (C + lam) t, single precision, and t.(C + lam) t; t has zero sum on the contact under force control
        R, tt = op.mix_inner(T, A32, out=work.spectrum(np.complex64, second=True))
        if per_node:
            tt += weighted_square(bk, D_c, t_c)
        if not bool(xp.any(t_c != 0)):
            tau, early = 0.0, False  # a single contact node under force control: only entering nodes can move
        elif tt <= 0 or not math.isfinite(tt):
            return f"search direction lost positive curvature (t.Ct = {tt:.3e})", "stalled"
        else:  # the minimum along t (gt = gz when the contact has not changed); shortened while the contact moves
            tau = gt / tt * (STEP_SHARE if (early := early_steps(k, record, per_node or bounded)) else 1.0)
        if bounded:
            return bounded_step(tau, t_c, R, D_c if per_node else None)
        p_c, clipped, changed, positive = steps.move(p_c0, t_c, tau)  # max(p_c0 - tau t_c, 0)
        if not positive and (target is None or not bk.is_numpy):  # else p = 0 at the same nodes: put once below
            bk.put(p, idx, p_c)  # p is 0 off idx (read by the entering test off NumPy)
        # re-entering nodes (p = 0, g < 0): the step tau of the preconditioned direction with the Jacobi
        # estimate of M there, -f min(tau, 1) g / (C_nn + lam) (module docstring: entering nodes)
        if bk.is_numpy:  # g < 0 and p = 0 from measure (the same u and delta), and at the nodes clipped to 0 here
            enter.reshape(-1)[idx[clipped]] = g_c[clipped] < 0
        overlap = bk.select(enter if bk.is_numpy else (u + h < delta) & (p == 0))
        entered, g_c = bool(bk.count(overlap)), None  # the gap not held past the entering test
        g_o = passes.gap_at(u, h, overlap) - delta if entered else None
        overlap, g_o = most_open(bk, overlap, g_o) if entered and early else (overlap, g_o)
        p_o = entering_pressure(xp, g_o, tau, jacobi_at(overlap) if per_node else jacobi, per_node,
                                preconditioned=True) if entered else None
        t_move = terms = None  # a change in double precision: u from the product of the move t' (module docstring)
        if (changed or entered) and confirm and exact_base and not single and tau > 0 and stale < RECOMPUTE_EVERY and (
                bk.is_numpy):
            t_move = brick.write_move(clipped, p_c0[clipped] / tau, *((overlap, -p_o / tau) if entered else ()))
            terms = [(idx, D_c * (p_c - p_c0))] + ([(overlap, passes.gather(D, overlap) * p_o)] if entered else []) if (
                per_node) else []  # D (p_new / s - p), before the scaling by s
        s = 1.0
        if target is not None:
            total = float(xp.sum(p_c)) + (float(xp.sum(p_o)) if entered else 0.0)
            if not total > 0:  # every node left the contact and none entered: no force to rescale
                bk.put(p, idx, p_c0)
                return "the iteration produced a non-finite value", "nonfinite"
            s = target / total
        if target is not None or positive:
            steps.scale_put(p, idx, p_c, s)  # p_c *= s, then p at idx
        if entered:
            bk.put(p, overlap, (p_o := multiplied_into(bk, p_o, s)))
        if t_move is not None:  # p = s (p - tau t'): u = s (u - tau (C + lam) t'), plus D's terms per node
            update_u(R, tau, s, terms, t_move)
        elif not (changed or entered or stale >= RECOMPUTE_EVERY):  # p = s (p - tau t) on the contact
            update_u(R, tau, s, [(idx, multiplied_into(bk, t_c, D_c), -tau)] if per_node else [])  # D t in t
        else:  # t not held through the product; D p on the contact made before it
            t_c, dp = None, D_c * p_c if per_node else None
            u, stale = offset_added(product_u()), 0
            if per_node:  # u += D p, on the nodes where p > 0
                passes.add_at(u, idx, dp)
                if entered:
                    passes.add_at(u, overlap, passes.gather(D, overlap) * p_o)
        nodes.stepped(p_c, entered, overlap, p_o)  # after the product: the next contact is not held through it
        return None

    def update_u(R, tau, s, terms, t_move=None):  # s (u - tau (C + lam) t + terms): R the spectrum of (C + lam) t, or
        nonlocal u, stale  # t_move the brick of t' (its product made here); terms: D's, (nodes, values[, times])
        if t_move is not None:
            op.n_matvec += 1
            R = op.mix(op.spectrum(t_move, out=work.spectrum(np.complex64, second=True)), A32, out=R)
            brick.restore()
        r = op.brick(R, overwrite=True, out=work.brick32(second=False))
        passes.subtract_scaled(u, r, tau, 1.0 if terms else s)  # s: one pass
        for sel, values, *times in terms:  # (nodes, values[, times]): one array of the nodes' size at a time
            passes.add_at(u, sel, values, *times)
        if terms and s != 1.0:
            u *= s
        u = offset_added(u, 1.0 - s)  # the offset is not scaled with p
        stale += 1

    def bounded_step(tau, t_c, R, D_c):  # the step of the bounded QP (bem.cg_rules.bounded_move) and its product
        nonlocal u, stale, restart
        changed, _, s, failure, restart = bounded_move(bk, p, sets, p_c0, t_c, tau, g, jacobi, per_node, target,
                                                       hardness, preconditioned=True, halvings=BACKTRACK_HALVINGS)
        if failure is not None:
            return failure
        if changed or R is None or stale >= RECOMPUTE_EVERY:
            u, stale = exact_u(), 0
        else:  # the elastic nodes moved along t and were scaled by s (the plastic ones by s - 1 of round-off)
            update_u(R, tau, s, [] if D_c is None else [(idx, D_c * t_c, -tau)])
        return None

    step = CGStep(measure_bounded if bounded else measure, confirms, observe_bounded if bounded else observe, advance,
                  lambda: bk.copy(p))
    kkt = run_constrained_cg(step, record, maxiter, callback)
    note_fully_plastic(record, sets.bracket if bounded else None, bounded and not bk.count(idx))
    c_p = elastic_displacement(bk, u, D if per_node else lam, p, out=work.brick64(), offset=offset)  # in work's bytes
    return record.solution(p, delta, kkt, c_p, "Kalker QP (periodic)")

