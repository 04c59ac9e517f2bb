"""The peers of ``peers.py``: ASPHER, tamaas and ContactMechanics on the problems of :mod:`cases`.

Each ``run_<peer>(problem, n)`` builds its gap array before the clock starts, solves to the
peer's own residual 1e-10 and returns a dict like :func:`cases.ours` (``nodes``, ``wall_s``,
``cpu_s``, ``iterations``, ``converged``, ``status``, ``contact_fraction``, ``note``). A peer
that is not installed raises :class:`ImportError`, which ``peers.py`` reports as a skip.

- ASPHER (``aspher``): ``solve_nested`` as its README advises (nested grids from 64, the
  ``"periodic"`` backend on the cell, ``"fft"`` on the half-space up to 2048 and ``"h2"`` above),
  ``tol=1e-10`` on its certified Frank-Wolfe error; ``aspher`` in its default precision,
  ``aspher-mixed`` with ``precision="float_then_double"``. Its cell and its region are squares:
  on the periodic problem it solves the same recipe on the unit square (``cases.periodic_grid_gap``).
- tamaas: ``PolonskyKeerRey`` (pressure control) at tolerance 1e-10 on the cell (Westergaard),
  and with the non-periodic operator (``ModelFactory.registerNonPeriodic``) on the half-space
  problems; its iterations and error are read from its log.
- ContactMechanics: ``constrained_conjugate_gradients`` (Polonsky-Keer) under force control on
  ``PeriodicFFTElasticHalfSpace`` / ``FreeFFTElasticHalfSpace``, penetration tolerance 1e-10 of
  the gap's range, force tolerance 1e-10 of the mean force per node, ``thermotol=1e-10``.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time

import numpy as np

import cases

#: ASPHER's half-space backend by grid size (its README: FFT up to 2048, H2 above)
ASPHER_FFT_MAX = 2048


def _problem(problem, n, *, square=False):
    """``(gap, (Ly, Lx), mean pressure, periodic)`` on the peers' ``n x n`` grid."""
    if problem == "periodic":
        gap, (lx, ly) = cases.periodic_grid_gap(n, square=square)
        return gap, (ly, lx), cases.PBAR, True
    if problem == "hertz":
        gap, a = cases.hertz_grid_gap(n), cases.A_HERTZ
    elif problem == "rough-sphere":
        gap, a = cases.rough_sphere_grid_gap(n), cases.A_ROUGH
    else:
        raise ValueError(f"problem {problem!r}: the peers solve periodic, hertz and rough-sphere")
    return gap, (cases.SIDE, cases.SIDE), cases.hertz_force(a) / cases.SIDE**2, False


def _clock():
    return time.perf_counter(), time.process_time()


def _since(t):
    return time.perf_counter() - t[0], time.process_time() - t[1]


def run_aspher(problem, n, *, mixed=False):
    import aspher

    gap, (ly, lx), pbar, periodic = _problem(problem, n, square=True)
    backend = "periodic" if periodic else ("fft" if n <= ASPHER_FFT_MAX else "h2")
    kw = dict(grid_size=n, gap=np.ascontiguousarray(gap.ravel()), p_nominal=pbar, domain_size=lx, E_star=1.0,
              tol=cases.RTOL, backend=backend)
    if mixed:
        kw["precision"] = "float_then_double"
    t = _clock()
    res = aspher.solve_nested(**kw)
    wall, cpu = _since(t)
    stages = list(res.stage_stats)
    finest = [s for s in stages if not str(s["name"]).startswith("coarse")]  # finest (and its polish)
    return dict(nodes=n * n, wall_s=wall, cpu_s=cpu, iterations=int(res.iterations),
                finest_iterations=int(sum(s["iterations"] for s in finest)) if finest else None,
                converged=bool(res.converged), status=str(res.status), residual=float(res.fw_error),
                contact_fraction=float(res.contact_area),
                note=f"backend {backend}, precision {'float_then_double' if mixed else 'default'}"
                     + (", the recipe on the unit square" if periodic else ""))


def _captured(fn):
    """``(fn(), text)``: what ``fn`` wrote on the process's stderr (tamaas logs there)."""
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile(mode="w+") as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            out = fn()
        finally:
            sys.stderr.flush()
            os.dup2(saved, 2)
            os.close(saved)
        tmp.seek(0)
        return out, tmp.read()


def run_tamaas(problem, n):
    import tamaas as tm

    gap, size, pbar, periodic = _problem(problem, n)
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, list(size), [n, n])
    model.E, model.nu = 1.0, 0.0  # E* = E / (1 - nu^2) = 1
    surface = np.ascontiguousarray(gap.max() - gap)  # the rigid surface's heights
    t = _clock()
    if not periodic:
        tm.ModelFactory.registerNonPeriodic(model, "dual")
    solver = tm.PolonskyKeerRey(model, surface, cases.RTOL, tm.PolonskyKeerRey.pressure,
                                tm.PolonskyKeerRey.pressure)
    if not periodic:
        solver.setIntegralOperator("dual")
    solver.setMaxIterations(100000)
    _, log = _captured(lambda: solver.solve(pbar))
    wall, cpu = _since(t)
    last = [line.split() for line in log.splitlines() if line.split() and line.split()[0].isdigit()][-1]
    p = np.asarray(model.traction)
    return dict(nodes=n * n, wall_s=wall, cpu_s=cpu, iterations=int(last[0]), residual=float(last[-1]),
                converged=float(last[-1]) <= cases.RTOL, status="converged" if float(last[-1]) <= cases.RTOL
                else "not converged", contact_fraction=float(np.mean(p > 0)),
                note="PolonskyKeerRey, Westergaard (periodic)" if periodic
                else "PolonskyKeerRey, non-periodic operator (registerNonPeriodic)")


def run_contactmechanics(problem, n):
    from ContactMechanics import FreeFFTElasticHalfSpace, PeriodicFFTElasticHalfSpace
    from ContactMechanics.Optimization import constrained_conjugate_gradients
    from SurfaceTopography import Topography

    gap, size, pbar, periodic = _problem(problem, n)
    force = pbar * size[0] * size[1]
    cls = PeriodicFFTElasticHalfSpace if periodic else FreeFFTElasticHalfSpace
    substrate = cls((n, n), 1.0, physical_sizes=size)
    topography = Topography(gap.max() - gap, physical_sizes=size, periodic=periodic)
    t = _clock()
    res = constrained_conjugate_gradients(substrate, topography, external_force=force,
                                          pentol=cases.RTOL * float(np.ptp(gap)),
                                          forcetol=cases.RTOL * force / (n * n), thermotol=cases.RTOL,
                                          maxiter=100000)
    wall, cpu = _since(t)
    p = np.asarray(res.jac)  # the force on each node
    return dict(nodes=n * n, wall_s=wall, cpu_s=cpu, iterations=int(res.nit), converged=bool(res.success),
                status=str(res.message), contact_fraction=float(np.mean(p > 0)),
                note="PeriodicFFTElasticHalfSpace" if periodic else "FreeFFTElasticHalfSpace")


def run_contactlab(problem, n):
    out = cases.ours("periodic" if problem == "periodic" else problem, n)
    out["note"] = "bem.solve_periodic" if problem == "periodic" else "bem.solve, half-space region"
    out["residual"] = out.pop("kkt")
    return out


SOLVERS = {
    "contactlab": run_contactlab,
    "aspher": run_aspher,
    "aspher-mixed": lambda problem, n: run_aspher(problem, n, mixed=True),
    "tamaas": run_tamaas,
    "contactmechanics": run_contactmechanics,
}
#: the Python package each solver needs (``pip install``), for the skip message
PACKAGES = {"contactlab": "contactlab", "aspher": "aspher", "aspher-mixed": "aspher", "tamaas": "tamaas",
            "contactmechanics": "contactmechanics"}
