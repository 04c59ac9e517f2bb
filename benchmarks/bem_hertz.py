"""Benchmark: Hertz sphere on 128^2 ... 2048^2 lattice nodes (a script, not a test).

Prints, for each lattice, the node count N, the iterations on the finest
lattice, the wall time (median of ``--repeat`` runs, imports excluded, the
first untimed run warms up the FFT caches), the peak resident memory and the
errors against Hertz. The candidate region holds ``n x n`` nodes (``n - 1``
a power of two, so the padded FFTs are 2^k long) and the contact diameter spans
60 % of it.

Run: ``python benchmarks/bem_hertz.py [--max 2048] [--repeat 3] [--rtol 1e-10]``
"""

from __future__ import annotations

import argparse
import math
import resource
import statistics
import time

import numpy as np

import bem
from bem.gaps import Paraboloid
from bem.reference import hertz_sphere

R, E_STAR, FORCE = 1.0, 1.0, 1.0


def run(n, *, rtol, repeat):
    ref = hertz_sphere(R, E_STAR, force=FORCE)
    half = (n - 1) // 2
    step = ref.contact_radius / (0.6 * half)
    extent = (half * step, half * step * math.sqrt(3) / 2)
    kw = dict(E_star=E_STAR, force=FORCE, step=step, extent=extent, rtol=rtol)
    bem.solve(Paraboloid(R), **kw)  # warm-up
    times, res = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = bem.solve(Paraboloid(R), **kw)
        times.append(time.perf_counter() - t0)
    r = np.hypot(res.x, res.y)
    inside = r < ref.contact_radius
    rms = math.sqrt(np.mean((res.p[inside] - ref.pressure(r[inside])) ** 2)) / ref.p_max
    return {
        "N": res.p.size,
        "across": 2 * ref.contact_radius / step,
        "iterations": res.iterations,
        "time_s": statistics.median(times),
        "kkt": res.kkt_residual,
        "p_max_err": res.p_max / ref.p_max - 1,
        "radius_err": res.contact_radius / ref.contact_radius - 1,
        "approach_err": res.approach / ref.approach - 1,
        "rms_err": rms,
        "rss_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6,
    }


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max", type=int, default=2048, help="largest lattice side (nodes)")
    parser.add_argument("--repeat", type=int, default=3, help="timed runs per size (median reported)")
    parser.add_argument("--rtol", type=float, default=1e-10, help="KKT tolerance")
    args = parser.parse_args(argv)
    sides = [s for s in (128, 256, 512, 1024, 2048) if s <= args.max]
    print("| lattice | N | nodes across contact | iterations | time [s] | KKT residual | "
          "p_max err | radius err | approach err | RMS err / p0 | peak RSS [GB] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for side in sides:
        row = run(side + 1, rtol=args.rtol, repeat=args.repeat if side <= 1024 else 1)
        print(f"| {side + 1}^2 | {row['N']:,} | {row['across']:.0f} | {row['iterations']} | {row['time_s']:.2f} | "
              f"{row['kkt']:.1e} | {row['p_max_err']:+.1e} | {row['radius_err']:+.1e} | "
              f"{row['approach_err']:+.1e} | {row['rms_err']:.1e} | {row['rss_gb']:.2f} |", flush=True)


if __name__ == "__main__":
    main()
