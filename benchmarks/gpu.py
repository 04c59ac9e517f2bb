"""Benchmark: the solvers on a CUDA device (``device="cuda"``; a script, not a test).

Cases (``--cases``), each with KKT residual 1e-10:

- ``solve``: the benchmark sphere (``benchmarks/side_by_side.py``: ``R = 1``, ``E* = 1``, square
  region of side 1, Hertz radius 0.1) at the node density of ``n x n`` grids, ``--sizes``
  (default 4096 and 8192: 16M and 64M nodes), ``hertz`` (no layer) and ``root``
  (``w = 0.04 sqrt(p)``, Newton);
- ``periodic``: the rough periodic cell of ``benchmarks/periodic_rough.py`` (mean pressure
  ``0.01 E*``, smooth and root layer) at ``--periodic-sizes`` (default 4096 and 8192);
- ``stress``: :func:`bem.subsurface_stress` of the Hertz solution on a ``4097 x 4097`` lattice
  (16M nodes) at 32 depths from 0 to 3 ``a``.

Reported per row: wall time (one untimed warm-up at the smallest size first, then the median
of ``--repeat`` runs), iterations, KKT residual, and the GPU memory: the peak of the bytes held
by CuPy's memory pool (``cupy.get_default_memory_pool().total_bytes()`` sampled after each
solve, the pool keeps what it allocated) and the device memory in use from
``cudaMemGetInfo``. Without CuPy or a CUDA device the script prints why and exits 0.

Run: ``python benchmarks/gpu.py [--cases solve periodic stress] [--sizes 4096 8192] [--repeat 3]``
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]

import numpy as np  # noqa: E402

import bem  # noqa: E402
from bem.gaps import Paraboloid  # noqa: E402

A_HERTZ, ROOT_K = 0.1, 0.04
FORCE = 4 * A_HERTZ**3 / 3


def _device():
    """``(cupy, None)`` or ``(None, reason)``."""
    try:
        import cupy
    except ImportError:
        return None, "CuPy is not installed (pip install contactlab[gpu])"
    try:
        n = cupy.cuda.runtime.getDeviceCount()
    except cupy.cuda.runtime.CUDARuntimeError as exc:
        return None, f"no CUDA device ({exc})"
    return (cupy, None) if n > 0 else (None, "no CUDA device")


def _memory(cupy):
    pool = cupy.get_default_memory_pool()
    free, total = cupy.cuda.runtime.memGetInfo()
    return pool.total_bytes() / 2**30, (total - free) / 2**30


def _timed(cupy, fn, repeat):
    cupy.get_default_memory_pool().free_all_blocks()
    times, out, pool_gb, used_gb = [], None, 0.0, 0.0
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        cupy.cuda.Device().synchronize()
        times.append(time.perf_counter() - t0)
        pool, used = _memory(cupy)
        pool_gb, used_gb = max(pool_gb, pool), max(used_gb, used)
    return out, statistics.median(times), pool_gb, used_gb


def case_solve(cupy, sizes, repeat):
    print("| case | grid | nodes | time [s] | iterations | KKT residual | pool [GiB] | device used [GiB] |")
    print("|---|---|---|---|---|---|---|---|")
    for n in sizes:
        step = math.sqrt(2 / math.sqrt(3)) / n
        for case in ("hertz", "root"):
            layer = bem.layers.Root(ROOT_K) if case == "root" else None

            def run():
                return bem.solve(Paraboloid(1.0), E_star=1.0, force=FORCE, step=step, extent=0.5, rtol=1e-10,
                                 layer=layer, device="cuda")

            res, t, pool, used = _timed(cupy, run, repeat)
            print(f"| {case} | {n}^2 | {res.p.size:,} | {t:.2f} | {res.iterations} | {res.kkt_residual:.1e} | "
                  f"{pool:.2f} | {used:.2f} |", flush=True)


def case_periodic(cupy, sizes, repeat):
    from periodic_rough import _root, surface_on_cell

    from bem.periodic import PeriodicCell, solve_periodic

    print("| case | cell | nodes | time [s] | iterations | KKT residual | contact | pool [GiB] | device used [GiB] |")
    print("|---|---|---|---|---|---|---|---|---|")
    for n in sizes:
        cell = PeriodicCell(1.0 / n, n, n)
        h = surface_on_cell(cell)
        for name, layer in (("smooth", None), ("root layer", _root(cell))):
            def run():
                return solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=0.01, rtol=1e-10, layer=layer,
                                      device="cuda")

            res, t, pool, used = _timed(cupy, run, repeat)
            print(f"| {name} | {n}^2 | {res.p.size:,} | {t:.2f} | {res.iterations} | {res.kkt_residual:.1e} | "
                  f"{res.contact_fraction:.3f} | {pool:.2f} | {used:.2f} |", flush=True)


def case_stress(cupy, repeat, side=4097, n_depths=32):
    from bem.reference import hertz_sphere

    ref = hertz_sphere(1.0, 1.0, force=1.0)
    half = (side - 1) // 2
    step = ref.contact_radius / (0.6 * half)
    extent = (half * step, half * step * math.sqrt(3) / 2)
    res = bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=step, extent=extent, rtol=1e-10, device="cuda")
    depths = np.linspace(0.0, 3.0, n_depths) * ref.contact_radius
    st, t, pool, used = _timed(cupy, lambda: bem.subsurface_stress(res, depths, nu=0.3, device="cuda"), repeat)
    print("| nodes | depths | time [s] | max von Mises / p0 | pool [GiB] | device used [GiB] |")
    print("|---|---|---|---|---|---|")
    print(f"| {res.p.size:,} | {n_depths} | {t:.2f} | {st.max_von_mises / ref.p_max:.6f} | {pool:.2f} | {used:.2f} |",
          flush=True)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="+", default=["solve", "periodic", "stress"],
                        choices=["solve", "periodic", "stress"])
    parser.add_argument("--sizes", type=int, nargs="+", default=[4096, 8192])
    parser.add_argument("--periodic-sizes", type=int, nargs="+", default=[4096, 8192])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    cupy, reason = _device()
    if cupy is None:
        print(f"skipped: {reason}; the GPU benchmarks need CuPy and a CUDA device.")
        return 0
    props = cupy.cuda.runtime.getDeviceProperties(cupy.cuda.Device().id)
    print(f"device: {props['name'].decode()}, {props['totalGlobalMem'] / 2**30:.0f} GiB; "
          f"host CPUs: {os.cpu_count()}; 1-minute load {os.getloadavg()[0]:.1f}")
    # warm-up: CUDA context, cuFFT plans, kernels
    bem.solve(Paraboloid(1.0), E_star=1.0, force=FORCE, step=math.sqrt(2 / math.sqrt(3)) / 256, extent=0.5,
              layer=bem.layers.Root(ROOT_K), device="cuda")
    if "solve" in args.cases:
        case_solve(cupy, args.sizes, args.repeat)
    if "periodic" in args.cases:
        case_periodic(cupy, args.periodic_sizes, args.repeat)
    if "stress" in args.cases:
        case_stress(cupy, args.repeat)
    return 0


if __name__ == "__main__":
    sys.exit(main())
