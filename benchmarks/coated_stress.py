"""Benchmark: stresses below a coated body (bem.coated_stress) against the homogeneous bem.subsurface_stress (a script, not a test).

A rigid sphere (R = 10) on a flat (E = 1, nu = 0.3) with a coating of thickness
``t = 0.3 a`` (``a`` the contact radius, about 0.72), ``E_c = 4``, ``nu_c = 0.25``, force 0.1; the
candidate region reaches 1.5 times 0.72 each way, ``--across`` nodes across the contact diameter. For
each lattice: the time of :func:`bem.coated_stress` at ``--depths`` depths from 0 to 3 ``t`` on
every candidate node at ``pad = 4`` and ``pad = 8`` (median of ``--repeat`` runs after a warm-up;
the solve is not timed), the time of :func:`bem.subsurface_stress` at the same depths, the
size of the padded cell and the largest difference between the two pads relative to ``p_max``
(the images' error at ``pad = 4``, to within that at ``pad = 8``).

Run: ``python benchmarks/coated_stress.py [--across 20,40,80] [--depths 16] [--repeat 3]``
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time

import numpy as np

import bem
from bem.gaps import Paraboloid

COAT = bem.Coating(0.3 * 0.72, 4.0, 0.25)


def timed(f, repeat):
    f()  # warm-up
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def run(across, *, n_depths, repeat):
    step = 2 * 0.72 / across
    res = bem.solve(Paraboloid(10.0), E1=1.0, nu1=0.3, E2=math.inf, nu2=0.0, coating1=COAT, force=0.1, step=step,
                    extent=1.5 * 0.72, rtol=1e-10)
    z = np.linspace(0.0, 3 * COAT.thickness, n_depths)
    t4, s4 = timed(lambda: bem.coated_stress(res, z, pad=4.0), repeat)
    t8, s8 = timed(lambda: bem.coated_stress(res, z, pad=8.0), repeat)
    th, _ = timed(lambda: bem.subsurface_stress(res, z, nu=0.3), repeat)
    diff = max(np.abs(s4.sigma - s8.sigma).max(), np.abs(s4.interface_coating - s8.interface_coating).max(),
               np.abs(s4.interface_substrate - s8.interface_substrate).max()) / res.p_max
    return {"N": res.p.size, "a/c": res.contact_radius / step, "t/c": COAT.thickness / step, "t4": t4, "t8": t8,
            "th": th, "cell4": s4.meta["cell"], "cell8": s8.meta["cell"], "diff": diff}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--across", default="20,40,80", help="nodes across the contact diameter, comma-separated")
    parser.add_argument("--depths", type=int, default=16, help="depths from 0 to 3 t")
    parser.add_argument("--repeat", type=int, default=3, help="timed runs per case (median reported)")
    args = parser.parse_args(argv)
    print(f"load average before: {', '.join(f'{v:.2f}' for v in os.getloadavg())} on {os.cpu_count()} cores")
    print("| N | a/c | t/c | depths | coated, pad 4 [s] (cell) | coated, pad 8 [s] (cell) | homogeneous [s] | "
          "pad 4 - pad 8 / p_max |")
    print("|---|---|---|---|---|---|---|---|")
    for across in (int(s) for s in args.across.split(",")):
        r = run(across, n_depths=args.depths, repeat=args.repeat)
        print(f"| {r['N']:,} | {r['a/c']:.1f} | {r['t/c']:.1f} | {args.depths} | {r['t4']:.2f} "
              f"({r['cell4'][0]}x{r['cell4'][1]}) | {r['t8']:.2f} ({r['cell8'][0]}x{r['cell8'][1]}) | "
              f"{r['th']:.2f} | {r['diff']:.1e} |", flush=True)
    print(f"load average after: {', '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
