"""The benchmark problems shared by ``peers.py``, ``scaling.py`` and ``memory.py``, and the machine's readings.

Problems (``E* = 1``, KKT residual ``1e-10``):

- ``periodic``: the seeded self-affine cell of :mod:`periodic_rough` (Hurst 0.8, roll-off at a
  quarter of the cell, cut-off at 1/128 of it, rms slope 0.1), ``N x N`` nodes, mean pressure
  ``0.01 E*``; ``periodic-root`` the same with the root layer ``periodic_rough._root``.
- ``hertz``: the sphere of :mod:`side_by_side` (``R = 1``, square region of side 1, Hertz radius
  0.1: contact 4 % of the region) at the node density of an ``N x N`` grid; ``hertz-wide`` the
  same under the force of a Hertz radius 0.3 (contact 28 % of the region); ``hertz-root`` the
  sphere of ``hertz`` with the root layer ``w = 0.04 sqrt(p)`` of :mod:`side_by_side`.
- ``rough-sphere``: the same sphere and region carrying a rough surface, the Fourier series of
  :mod:`periodic_rough` with the unit square as its period (rms slope 0.1), under the force of a
  smooth Hertz radius 0.3 (contact 27 % of the region). :class:`Roughness`
  evaluates the series exactly at any nodes that lie on rows (a lattice or a grid), so every
  solver solves the same surface at its own nodes.

Readings: the peak resident set of the process (``VmHWM`` of ``/proc/self/status``; reset with
``/proc/self/clear_refs``), the machine (CPU model, cores, memory) and the load averages.
"""

from __future__ import annotations

import math
import os
import platform
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:
    sys.path[:0] = [HERE, os.path.dirname(HERE)]

RADIUS, SIDE, A_HERTZ, A_ROUGH, ROOT_K = 1.0, 1.0, 0.1, 0.3, 0.04
PBAR = 0.01
PROBLEMS = ("periodic", "periodic-root", "hertz", "hertz-root", "hertz-wide", "rough-sphere")
RTOL = 1e-10
LOAD_S = None  # seconds of the last prepare()'s load of the compiled kernels (numba's import and cached code)


def hertz_force(a):
    """Force that gives the Hertz radius ``a`` (``R = E* = 1``): ``a^3 = 3 P R / (4 E*)``."""
    return 4 * a**3 / (3 * RADIUS)


# -- the machine -------------------------------------------------------------------------------


def _status(key):
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1]) * 1024
    return float("nan")


def peak_rss():
    """Peak resident set of this process since the last :func:`reset_peak` [bytes] (``VmHWM``)."""
    return _status("VmHWM")


def rss():
    """Resident set of this process [bytes] (``VmRSS``)."""
    return _status("VmRSS")


def reset_peak():
    """Reset ``VmHWM`` to the present resident set (Linux: write 5 to ``/proc/self/clear_refs``)."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def write_whole(path, text):
    """Write ``text`` to ``path`` whole or not at all (a temporary file beside it, then renamed)."""
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def loadavg():
    """The 1-, 5- and 15-minute load averages."""
    return [round(v, 2) for v in os.getloadavg()]


def machine():
    """CPU model, cores, the CPUs this process may use, memory [GB], the platform and the FFT libraries
    (:func:`bem.fft.back_end`)."""
    from bem.fft import back_end

    model = platform.processor() or "unknown"
    try:
        with open("/proc/cpuinfo") as f:
            model = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    memory = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    return dict(cpu=model, cores=os.cpu_count(), affinity=len(os.sched_getaffinity(0)),
                memory_gb=round(memory / 1e9, 1), platform=platform.platform(), python=platform.python_version(),
                numpy=np.__version__, fft=back_end())


# -- the surfaces ------------------------------------------------------------------------------


_CHUNK = 1 << 20  # points per chunk of Roughness.__call__


class Roughness:
    """The self-affine Fourier series of :mod:`periodic_rough` with period ``(lx, ly)``, evaluated exactly.

    ``z(x, y) = Re sum Z_mn exp(i (gx_m x + gy_n y))``. Points on rows (a lattice or a grid:
    few distinct ``y``, few distinct ``x``) cost two matrix products: ``A[row, m] = sum_n Z_mn
    exp(i gy_n y_row)``, then ``B[row, col] = Re sum_m A[row, m] exp(i gx_m x_col)``, over chunks of
    ``2**20`` points (the temporaries of a chunk, not of the whole lattice).
    ``seconds`` and ``cpu_seconds`` sum the wall and CPU time spent in calls (the solvers that
    take a callable pay it inside their solve; the benchmarks subtract it).
    """

    def __init__(self, lx=SIDE, ly=SIDE):
        from periodic_rough import _spectrum

        mm, nn, z = _spectrum(lx, ly)
        self.gx = 2 * math.pi * mm[0] / lx  # (K,)
        self.gy = 2 * math.pi * nn[:, 0] / ly  # (K,)
        self.z = z  # z[n, m]
        self.seconds = self.cpu_seconds = 0.0

    def __call__(self, x, y):
        t, c = time.perf_counter(), time.process_time()
        x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        flat_x, flat_y = x.reshape(-1), y.reshape(-1)
        out = np.empty(flat_x.size)
        for start in range(0, out.size, _CHUNK):  # in chunks: temporaries of a chunk, not of the whole lattice
            part = slice(start, start + _CHUNK)
            ux, ix = np.unique(flat_x[part], return_inverse=True)
            uy, iy = np.unique(flat_y[part], return_inverse=True)
            a = np.exp(1j * np.outer(uy, self.gy)) @ self.z  # (rows, m)
            out[part] = (a @ np.exp(1j * np.outer(self.gx, ux))).real[iy, ix]
        self.seconds += time.perf_counter() - t
        self.cpu_seconds += time.process_time() - c
        return out.reshape(x.shape)


class RoughSphere:
    """Gap of the rough sphere: ``(x^2 + y^2) / (2 R) - z(x, y)`` (a callable ``h(x, y)``)."""

    def __init__(self):
        self.roughness = Roughness()

    @property
    def seconds(self):
        return self.roughness.seconds

    @property
    def cpu_seconds(self):
        return self.roughness.cpu_seconds

    def __call__(self, x, y):
        return (np.square(x) + np.square(y)) / (2 * RADIUS) - self.roughness(x, y)


def grid_nodes(n, side=SIDE):
    """Centres of the ``n x n`` square grid on ``[-side/2, side/2]^2`` (``x`` along the last axis)."""
    c = (np.arange(n) + 0.5) * side / n - side / 2
    return np.meshgrid(c, c)


def hertz_grid_gap(n):
    """The sphere's gap on :func:`grid_nodes` (the peers' input)."""
    x, y = grid_nodes(n)
    return (x * x + y * y) / (2 * RADIUS)


def rough_sphere_grid_gap(n):
    """The rough sphere's gap on :func:`grid_nodes` (the peers' input)."""
    x, y = grid_nodes(n)
    return RoughSphere()(x, y)


def periodic_cell(n):
    """``(cell, h)``: the self-affine cell of :mod:`periodic_rough` with ``n x n`` nodes and its brick gap array."""
    from periodic_rough import PeriodicCell, surface_on_cell

    cell = PeriodicCell(1.0 / n, n, n)
    return cell, surface_on_cell(cell)


def periodic_grid_gap(n, *, square=False):
    """The cell's surface on a peer's square-indexed ``n x n`` grid (``x`` along the last axis).

    ``square=False``: the same surface on the same ``Lx x Ly = 1 x sqrt(3)/2`` rectangle (the grid of
    :func:`periodic_rough.plain_pk`); ``square=True``: the same recipe (seed, spectrum, rms slope)
    with the unit square as the cell, for a solver whose cell must be square; returns ``(h, (Lx, Ly))``.
    """
    from periodic_rough import PeriodicCell, _on_grid

    size = (1.0, 1.0) if square else PeriodicCell(1.0 / n, n, n).size
    h = _on_grid(*size, (n, n))
    return h.max() - h, size


# -- contactlab on each problem ----------------------------------------------------------------


def prepare(problem, n):
    """``(solve, gap)``: ``solve()`` runs contactlab on ``problem`` at size ``n``; ``gap`` is what it solves
    (a brick array, a :mod:`bem.gaps` shape or a :class:`RoughSphere`), made here, outside any clock.

    The compiled kernels are loaded here too, where numba is installed (:func:`bem.extremes.load`,
    :func:`bem.newton_passes.load`, and for a periodic cell :func:`bem.periodic.passes.load` and
    :func:`bem.periodic.step_passes.load`), as a peer's compiled module is imported before its clock: numba's import and
    the load of the kernels' cached code (:data:`LOAD_S` holds how long it took in this process).
    """
    global LOAD_S
    import bem
    from bem import extremes, newton_passes

    t = time.perf_counter()
    extremes.load()
    newton_passes.load()
    LOAD_S = time.perf_counter() - t
    if problem.startswith("periodic"):
        from bem.periodic import passes, step_passes
        from periodic_rough import _root

        t = time.perf_counter()
        passes.load()
        step_passes.load()
        LOAD_S += time.perf_counter() - t

        cell, h = periodic_cell(n)
        layer = _root(cell) if problem == "periodic-root" else None
        return (lambda: bem.solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=PBAR, rtol=RTOL,
                                           layer=layer)), h
    step = math.sqrt(2 / math.sqrt(3)) * SIDE / n  # the node density of an n x n grid of side SIDE
    layer = bem.layers.Root(ROOT_K) if problem == "hertz-root" else None
    if problem in ("hertz", "hertz-root", "hertz-wide"):
        gap, force = bem.gaps.Paraboloid(RADIUS), hertz_force(A_ROUGH if problem == "hertz-wide" else A_HERTZ)
    elif problem == "rough-sphere":
        gap, force = RoughSphere(), hertz_force(A_ROUGH)
    else:
        raise ValueError(f"problem {problem!r}: one of {PROBLEMS}")
    return (lambda: bem.solve(gap, E_star=1.0, force=force, step=step, extent=SIDE / 2, rtol=RTOL,
                              layer=layer)), gap


def summary(res):
    """The measurements of a contactlab result, as a dict."""
    return dict(nodes=int(res.p.size), iterations=int(res.iterations), products=int(res.n_matvec),
                transforms=int(res.n_transforms), kkt=float(res.kkt_residual),
                converged=bool(res.converged), status=str(res.status), contact_fraction=float(np.mean(res.p > 0)))


def ours(problem, n):
    """Solve ``problem`` with contactlab at size ``n``; :func:`summary` and the solve's wall and CPU time.

    The clock covers ``bem.solve`` (the kernel build included), not the making of a gap array; a
    callable gap's own evaluation time is measured and subtracted (``gap_s``).
    """
    solve, gap = prepare(problem, n)
    t, c = time.perf_counter(), time.process_time()
    res = solve()
    gap_s, gap_cpu = getattr(gap, "seconds", 0.0), getattr(gap, "cpu_seconds", 0.0)
    wall, cpu = time.perf_counter() - t - gap_s, time.process_time() - c - gap_cpu
    return dict(summary(res), wall_s=wall, cpu_s=cpu, gap_s=gap_s, load_s=LOAD_S)
