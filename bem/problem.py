"""The checks of :func:`bem.solve`, one set for every domain (docs/method.md, "Checks of bem.solve").

:func:`check_problem` checks the arguments that do not depend on the domain's lattice, in the
order of the signature, before anything is built; :func:`initial_guess` checks ``x0`` against
the lattice. Each rule is that of :mod:`bem.checks` and the message names the keyword.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .backend import get_backend
from .coating import Bodies, Coating
from .checks import (check_bool, check_callable, check_choice, check_finite_array, check_int, check_layer, check_load,
                     check_rtol, check_scale, fail)
from .errors import InputError
from .materials import effective_modulus
from .options import METHODS, check_options, solver_for

__all__ = ["Problem", "bodies_of", "check_problem", "initial_guess", "modulus"]


@dataclass(frozen=True)
class Problem:
    """The checked arguments of :func:`bem.solve` (``solver``: the one that runs, :func:`bem.options.solver_for`;
    ``bodies``: the coated bodies, a :class:`bem.Bodies`, or ``None`` when neither is coated)."""

    E_star: float
    bodies: object
    force: float | None
    approach: float | None
    layer: object
    method: str
    solver: str
    rtol: float
    maxiter: int | None
    nested: bool
    precondition: bool
    callback: object
    backend: object
    options: dict
    hardness: float | None = None


def modulus(E_star, E1, nu1, E2, nu2):
    """``E_star`` checked, or the effective modulus of ``E1, nu1, E2, nu2`` (one or the other given) [pressure]."""
    given = [v is not None for v in (E1, nu1, E2, nu2)]
    if E_star is not None:
        if any(given):
            raise InputError("E_star is not allowed together with E1, nu1, E2, nu2: give one or the other.")
        return check_scale("E_star", E_star)
    if not all(given):
        raise InputError("E_star = None is not allowed without all of E1, nu1, E2, nu2: give E_star or all four.")
    return effective_modulus(E1, nu1, E2, nu2)


def bodies_of(E1, nu1, E2, nu2, coating1, coating2):
    """The coated bodies (:class:`bem.Bodies`) of the arguments of :func:`bem.solve`, ``None`` without a coating.

    A coating needs its substrate: ``E1, nu1, E2, nu2`` given (not ``E_star``)."""
    for name, coating in (("coating1", coating1), ("coating2", coating2)):
        if coating is not None and not isinstance(coating, Coating):
            raise InputError(f"{name} = {coating!r} is not allowed: it must be a bem.Coating(thickness, E, nu) "
                             "or None.")
    if coating1 is None and coating2 is None:
        return None
    if any(v is None for v in (E1, nu1, E2, nu2)):
        name = "coating1" if coating1 is not None else "coating2"
        raise InputError(f"{name} is not allowed without E1, nu1, E2, nu2: a coating's substrate is its body's "
                         "material, so give the bodies' moduli and Poisson ratios instead of E_star.")
    return Bodies(E1, nu1, E2, nu2, coating1, coating2)


def _load(domain, force, approach, mean_pressure):
    if mean_pressure is None:
        return check_load(force, approach)
    area = getattr(domain, "area", None)
    if area is None:
        fail("mean_pressure", mean_pressure, "given on a periodic cell only (a half-space region takes force)")
    if force is not None or approach is not None:
        fail("(force, approach, mean_pressure)", (force, approach, mean_pressure), "exactly one given")
    return check_scale("mean_pressure", mean_pressure) * area, None


def check_problem(domain, *, E_star, E1, nu1, E2, nu2, coating1=None, coating2=None, force, approach, mean_pressure,
                  layer, method, rtol, maxiter, nested, precondition, callback, device, options, hardness=None):
    """The checked :class:`Problem` (the keywords of :func:`bem.solve`); :class:`bem.InputError` naming the first
    bad argument."""
    E_star = modulus(E_star, E1, nu1, E2, nu2)
    bodies = bodies_of(E1, nu1, E2, nu2, coating1, coating2)
    force, approach = _load(domain, force, approach, mean_pressure)
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
    if check_layer("layer", layer) is not None and method == "kalker" and not layer.is_linear:
        raise InputError(
            f"method = 'kalker' is not allowed with layer = {layer!r}: Kalker's QP solves smooth bodies "
            "and linear layers only; use method='newton' (or a paper method) for a nonlinear layer.")
    solver = solver_for(method, layer)
    options = check_options(method, solver, options)
    if hardness is not None:
        hardness = _hardness(domain, hardness, force, mean_pressure, solver)
    if nested is None:
        nested = solver in ("kalker", "newton")
    return Problem(E_star=E_star, bodies=bodies, force=force, approach=approach, layer=layer, method=method,
                   solver=solver, rtol=rtol, maxiter=maxiter, nested=nested, precondition=precondition,
                   callback=callback, backend=backend, options=options, hardness=hardness)


def _hardness(domain, hardness, force, mean_pressure, solver):
    """The checked hardness ``H`` [pressure]: finite and > 0, a cell's mean pressure at most ``H`` (every node
    at ``H`` carries ``H Lx Ly``), and a solver that bounds the pressure (Kalker's QP, Newton)."""
    hardness = check_scale("hardness", hardness)
    if solver not in ("kalker", "newton"):
        raise InputError(f"hardness = {hardness!r} is not allowed with method = {solver!r}: the paper's fixed-point "
                         "methods do not bound the pressure; use method='newton'.")
    area = getattr(domain, "area", None)
    if area is not None and force is not None and force > hardness * area:
        name, value = ("mean_pressure", mean_pressure) if mean_pressure is not None else ("force", force)
        fail(name, value, f"at most hardness = {hardness!r} times the cell area {area:.6g} (every node at the "
             "hardness)" if name == "force" else f"<= hardness = {hardness!r} (every node at the hardness)")
    return hardness


def initial_guess(x0, lattice):
    """``x0`` as a brick array of ``lattice`` (0 off the candidate nodes): given as the ``(N,)`` values at the
    candidate nodes or as a brick array of ``lattice.shape``; finite (negative entries are clipped by the solver)."""
    x0 = check_finite_array("x0", x0)
    n = int(np.count_nonzero(lattice.mask))
    if x0.shape == (n,):
        guess = np.zeros(lattice.shape)
        guess[lattice.mask] = x0
        return guess
    if x0.shape == lattice.shape:
        return np.where(lattice.mask, x0, 0.0)
    raise InputError(f"x0 has shape {x0.shape} which is not allowed: it must be ({n},) (the candidate nodes) "
                     f"or {lattice.shape} (a brick array).")
