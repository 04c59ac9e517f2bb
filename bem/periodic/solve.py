"""The entry point :func:`solve_periodic`: contact of a periodic cell (a rough surface patch)."""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import numpy as np

from ..checks import check_bool, check_choice, check_gap_values, check_int, check_node_count, check_positive, fail
from ..errors import InputError
from ..kkt import kkt_residual
from ..options import METHODS, check_options, solver_for
from ..result import ContactResult
from .cell import PeriodicCell
from .influence import PeriodicOperator
from .qp import solve_periodic_qp

__all__ = ["solve_periodic", "PeriodicContactResult"]

log = logging.getLogger(__name__)

_COARSEST_NODES = 4096  # nested iteration stops coarsening below this many nodes
# KKT residual to which the coarser cells of nested iteration are solved. The QP's iterations on
# the finest cell do not fall with a tighter coarse solution (benchmarks/periodic_rough.py surface,
# 1024 x 1024: 47 from coarse residuals 1e-2 and 1e-3, 46 from 1e-4 and 1e-6), while the coarse
# cells' own iterations double from 1e-2 to 1e-6; Newton with a root layer takes one step more on
# the finest cell from 1e-3 than from 1e-4 and 1e-6 (13 against 12 at 1024 x 1024, 64 inner
# iterations against 62, the same time there) while its coarse cells cost a third less, so it solves
# them to 1e-3 (0.14 s less in all on that benchmark); the other solvers keep 1e-6.
_COARSE_RTOL = {"kalker": 1e-2, "newton": 1e-3}
_COARSE_RTOL_DEFAULT = 1e-6
_PERIODIC_RTOL = 1e-8  # gap(x + L) = gap(x) to this fraction of the gap's range


@dataclass
class PeriodicContactResult(ContactResult):
    """:class:`bem.ContactResult` of a periodic cell (``lattice`` is the :class:`PeriodicCell`).

    ``force`` is the force on one cell and ``displacement`` has zero mean over the cell;
    ``gap`` is the deformed gap ``C p + w(p) + h - delta``.
    """

    @property
    def mean_pressure(self):
        """Mean pressure over the cell, ``force / (Lx Ly)`` [pressure]."""
        return self.force / self.lattice.area

    @property
    def contact_fraction(self):
        """Fraction of the nodes in contact (``p > 0``): the relative contact area."""
        return float(np.count_nonzero(self.p > 0)) / self.p.size

    @property
    def mean_gap(self):
        """Mean deformed gap over the cell, ``mean(h + w(p)) - delta`` [length] (the mean-plane separation)."""
        return float(np.mean(self.gap))

    def summary(self):
        out = super().summary()
        del out["contact_radius"]
        out.update(mean_pressure=float(self.mean_pressure), contact_fraction=self.contact_fraction,
                   mean_gap=self.mean_gap, cell=[int(self.lattice.n_cols), int(self.lattice.n_rows)])
        return out


def _cell_and_gap(gap, step, cell):
    """The cell and the nodal gap (brick array) from an array or a periodic callable."""
    if callable(gap):
        if cell is None or not isinstance(cell, PeriodicCell):
            fail("cell", cell, "a bem.periodic.PeriodicCell when gap is a callable")
        if step is not None:
            raise InputError(f"step = {step!r} is not allowed with a cell: the cell has its step.")
        h = _evaluate(gap, cell, 0.0, 0.0)
        lx, ly = cell.size
        scale = float(np.ptp(h)) or max(float(np.abs(h).max()), 1.0)
        for name, sx, sy in (("Lx", lx, 0.0), ("Ly", 0.0, ly)):
            shifted = _evaluate(gap, cell, sx, sy)
            worst = float(np.abs(shifted - h).max())
            if worst > _PERIODIC_RTOL * scale:
                raise InputError(f"gap = {gap!r} is not allowed: it must be periodic over the cell "
                                 f"({cell.n_cols} x {cell.n_rows} nodes of step {cell.step:.6g}, Lx = {lx:.6g}, "
                                 f"Ly = {ly:.6g}); gap(x + {name}) differs from gap(x) by {worst:.3g}.")
        return cell, h
    if cell is not None:
        raise InputError("cell is not allowed with a gap array: the cell follows from the array's shape and step.")
    h = np.asarray(gap, dtype=float) if not isinstance(gap, np.ndarray) else gap.astype(float, copy=False)
    if h.ndim != 2:
        fail("gap", f"<array of shape {h.shape}>", "a brick array of shape (n_rows, n_cols) or a callable")
    check_node_count("gap", f"<array of shape {h.shape}>", h.size, what="the periodic cell")
    if step is None:
        fail("step", step, "given with a gap array (the lattice step c)")
    cell = PeriodicCell(step, h.shape[1], h.shape[0])
    if not np.all(np.isfinite(h)):
        r, q = np.argwhere(~np.isfinite(h))[0]
        fail("gap", f"<array with {h[r, q]!r} at row {r}, column {q}>", "finite")
    return cell, h


def _evaluate(gap, cell, sx, sy):
    x, y = cell.x + sx, cell.y + sy
    return check_gap_values(gap(x, y), {"x": x, "y": y}, region="over the cell")


def _levels(cell, h, gap, nested):
    """(cell, gap) pairs from the coarsest to the finest."""
    levels = [(cell, h)]
    while nested:
        fine, hf = levels[-1]
        coarse = fine.coarsen()
        if coarse is None or coarse.n_nodes < _COARSEST_NODES:
            break
        levels.append((coarse, _evaluate(gap, coarse, 0.0, 0.0) if callable(gap) else fine.restrict(hf)))
    return levels[::-1]


def solve_periodic(gap, *, step=None, cell=None, E_star=None, E1=None, nu1=None, E2=None, nu2=None,
                   mean_pressure=None, approach=None, layer=None, method="newton", rtol=1e-10, maxiter=None,
                   x0=None, nested=None, precondition=True, callback=None, device="cpu", **options):
    """Frictionless normal contact of a periodic cell of two elastic half-spaces with an interface layer.

    The gap repeats with the periods of the cell (:class:`PeriodicCell`): a rough surface
    patch. Every node may touch. The same functional and solvers as :func:`bem.solve`, with
    the periodic influence operator (:class:`bem.periodic.PeriodicOperator`), whose
    displacements have zero mean over the cell.

    Parameters
    ----------
    gap : ndarray or callable
        Initial gap [length]: a brick array of shape ``(n_rows, n_cols)`` (node ``(q, r)`` at
        ``x = (q + (r mod 2)/2) c``, ``y = r c sqrt3/2``; the cell follows from the shape and
        ``step``), or a vectorised ``h(x, y)`` periodic over ``cell`` (checked at the nodes).
    step : float
        Lattice step ``c`` [length], with a gap array.
    cell : PeriodicCell
        The cell, with a callable gap.
    E_star : float, optional
        Effective modulus [pressure]; or give ``E1, nu1, E2, nu2`` instead.
    mean_pressure, approach : float
        Exactly one. ``mean_pressure`` ``pbar`` > 0 [pressure]: the force on a cell is
        ``pbar Lx Ly = sqrt(3)/2 c^2 sum p``. ``approach`` ``delta`` [length]: the deformed gap is
        ``C p + w(p) + h - delta`` with ``C p`` of zero mean, so that its mean (the mean-plane
        separation, :attr:`PeriodicContactResult.mean_gap`) is ``mean(h + w(p)) - delta``;
        without a layer it must be below ``mean(h)`` (a full contact leaves the mean pressure
        undetermined under approach control).
    layer, method, rtol, maxiter, x0, precondition, callback, device, **options
        As for :func:`bem.solve` (``x0`` a brick array of the cell's shape, or flattened; the
        result's arrays are NumPy arrays on the host for every ``device``).
    nested : bool, optional
        Start from the solution on cells of step ``2c``, ``4c``, ... (every other node,
        needs ``n_cols`` even and ``n_rows`` a multiple of 4 per level) interpolated onto the
        finer one. Default: on for ``"newton"`` and the QP, off for the paper's methods.

    Returns
    -------
    PeriodicContactResult

    Notes
    -----
    Stopping rules, as for :func:`bem.solve`, with ``g = C p + w(p) + h - delta`` and the KKT
    residual ``r = max(max_{p>0} |g|, max_{p=0} (-g)_+) / max |C p + w(p)|`` (and, under
    ``mean_pressure``, ``|sqrt(3)/2 c^2 sum p - pbar Lx Ly| / (pbar Lx Ly)``): Kalker's QP and
    Newton stop at ``r <= rtol`` on an exactly recomputed ``C p``; the paper's methods when
    their increments (eq. 20, 23) are below ``eps_h``, ``eps_p`` AND ``r <= rtol``. Timings:
    ``benchmarks/periodic_rough.py`` and docs/performance.md.
    """
    from ..backend import get_backend, to_host
    from ..solve import _check_layer, _inner_summary, _modulus, _run

    t_start = time.perf_counter()
    cell, h = _cell_and_gap(gap, step, cell)
    backend = get_backend(device)
    E_star = _modulus(E_star, E1, nu1, E2, nu2)
    if (mean_pressure is None) == (approach is None):
        fail("(mean_pressure, approach)", (mean_pressure, approach), "exactly one given")
    force = None if mean_pressure is None else check_positive("mean_pressure", mean_pressure) * cell.area
    if approach is not None:
        approach = float(approach) if np.isfinite(approach) else fail("approach", approach, "finite")
        if layer is None and not approach < float(h.mean()):
            fail("approach", approach, f"< the mean gap {float(h.mean()):.6g} without a layer (a full contact "
                 "leaves the mean pressure undetermined: give mean_pressure)")
    check_choice("method", method, METHODS)
    rtol = check_positive("rtol", rtol)
    if maxiter is not None:
        maxiter = check_int("maxiter", maxiter)
    precondition = check_bool("precondition", precondition)
    _check_layer(layer, method)
    solver = solver_for(method, layer)
    options = check_options(method, solver, options)
    nested = solver in ("kalker", "newton") if nested is None else check_bool("nested", nested)
    guess = None
    if x0 is not None:
        guess = np.asarray(x0, dtype=float)
        if guess.shape == (cell.n_nodes,):
            guess = guess.reshape(cell.shape)
        if guess.shape != cell.shape:
            raise InputError(f"x0 has shape {guess.shape} which is not allowed: it must be {cell.shape} "
                             f"or ({cell.n_nodes},).")
        nested = False
    levels = _levels(cell, h, gap, nested)
    coarse_rtol = _COARSE_RTOL.get(solver, _COARSE_RTOL_DEFAULT)
    for level, (lat, h_lat) in enumerate(levels):
        finest = level == len(levels) - 1
        kw = dict(force=force, approach=approach, x0=guess, rtol=rtol if finest else max(rtol, coarse_rtol),
                  callback=callback if finest else None)
        if maxiter is not None:
            kw["maxiter"] = maxiter
        op = PeriodicOperator(lat, E_star, device=backend)
        if solver == "kalker" and precondition and backend.is_numpy:  # the QP in the Fourier basis
            sol = solve_periodic_qp(op, h_lat, lam=0.0 if layer is None else layer.lam, **kw, **options)
        else:
            sol = _run(solver, op, h_lat, layer, precondition, kw, options)
        if not finest:
            guess = levels[level + 1][0].prolong(sol.p)
    p = sol.p
    u = to_host(op.matvec(p))
    closure = np.zeros(cell.shape) if layer is None else layer.w(p)
    g = u + closure + h - sol.approach
    a = cell.node_area
    kkt = kkt_residual(p.ravel(), g.ravel(), displacement_scale=float(np.abs(u + closure).max()), force=force,
                       node_area=a)
    if not np.all(np.isfinite(p)):
        raise FloatingPointError(f"{solver}: the solver produced non-finite pressures ({sol.message})")
    result = PeriodicContactResult(
        x=cell.x.ravel(), y=cell.y.ravel(), p=p.ravel(), displacement=u.ravel(), closure=closure.ravel(),
        gap=g.ravel(), approach=float(sol.approach), force=float(a * p.sum()), p_max=float(p.max()),
        contact_area=float(a * np.count_nonzero(p > 0)), converged=bool(sol.converged), message=sol.message,
        status=sol.status, rtol=float(rtol),
        iterations=int(sol.iterations), kkt_residual=float(kkt), method=solver,
        wall_time_s=time.perf_counter() - t_start, lattice=cell, E_star=E_star, history=sol.history,
        layer=layer, n_matvec=op.n_matvec)
    if not result.converged:
        log.warning("%s: %s%s", solver, result.message, _inner_summary(sol.history))
    return result
