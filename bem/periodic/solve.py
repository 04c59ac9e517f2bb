"""The entry point :func:`solve_periodic`: :func:`bem.solve` on a periodic cell, under its own names."""

from __future__ import annotations

import numpy as np

from ..checks import check_node_count, fail
from ..errors import InputError
from .cell import PeriodicCell
from .result import PeriodicContactResult

__all__ = ["solve_periodic", "PeriodicContactResult"]


def solve_periodic(gap, *, step=None, cell=None, E_star=None, E1=None, nu1=None, E2=None, nu2=None, coating1=None,
                   coating2=None,
                   mean_pressure=None, approach=None, layer=None, hardness=None, method="newton", rtol=1e-10,
                   maxiter=None, x0=None, nested=None, precondition=True, callback=None, device="cpu", **options):
    """Frictionless normal contact of a periodic cell: an alias of :func:`bem.solve` with ``domain=cell``.

    ``solve_periodic(gap, cell=cell, ...)`` is ``bem.solve(gap, domain=cell, ...)``, and
    ``solve_periodic(h, step=c, ...)`` with a brick array ``h`` is
    ``bem.solve(h, domain=PeriodicCell(c, n_cols, n_rows), ...)`` for ``(n_rows, n_cols) = h.shape``:
    the same checks, solvers and result (:class:`PeriodicContactResult`).

    Parameters
    ----------
    gap : ndarray or callable
        Initial gap [length]: a brick array of shape ``(n_rows, n_cols)`` (the cell follows from the
        shape and ``step``), or a vectorised ``h(x, y)`` periodic over ``cell``.
    step : float
        Lattice step ``c`` [length], with a gap array.
    cell : PeriodicCell
        The cell, with a callable gap.
    mean_pressure, approach : float
        Exactly one: the mean pressure ``pbar`` [pressure] or the approach ``delta`` [length]
        (:func:`bem.solve`).
    E_star, E1, nu1, E2, nu2, coating1, coating2, layer, hardness, method, rtol, maxiter, x0, nested
        As for :func:`bem.solve`.
    precondition, callback, device, **options
        As for :func:`bem.solve`.

    Returns
    -------
    PeriodicContactResult
    """
    if (mean_pressure is None) == (approach is None):
        fail("(mean_pressure, approach)", (mean_pressure, approach), "exactly one given")
    if callable(gap):
        if cell is None or not isinstance(cell, PeriodicCell):
            fail("cell", cell, "a bem.periodic.PeriodicCell when gap is a callable")
        if step is not None:
            raise InputError(f"step = {step!r} is not allowed with a cell: the cell has its step.")
    else:
        if cell is not None:
            raise InputError("cell is not allowed with a gap array: the cell follows from the array's shape and step.")
        shape = np.shape(gap)
        if len(shape) != 2:
            fail("gap", f"<array of shape {shape}>", "a brick array of shape (n_rows, n_cols) or a callable")
        check_node_count("gap", f"<array of shape {shape}>", shape[0] * shape[1], what="the periodic cell")
        if step is None:
            fail("step", step, "given with a gap array (the lattice step c)")
        cell = PeriodicCell(step, shape[1], shape[0])
    from ..solve import solve

    return solve(gap, domain=cell, E_star=E_star, E1=E1, nu1=nu1, E2=E2, nu2=nu2, coating1=coating1,
                 coating2=coating2, mean_pressure=mean_pressure,
                 approach=approach, layer=layer, hardness=hardness, method=method, rtol=rtol, maxiter=maxiter, x0=x0, nested=nested,
                 precondition=precondition, callback=callback, device=device, **options)
