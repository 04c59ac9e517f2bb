"""Benchmark: subsurface stresses of the Hertz contact on lattices up to 1025^2 nodes (a script, not a test).

The problem of ``benchmarks/bem_hertz.py`` (sphere on a flat, R = E* = P = 1, contact diameter
60 % of the candidate region, KKT tolerance 1e-10). For each lattice: the time of
:func:`bem.subsurface_stress` at ``--depths`` depths from the surface down to 3 Hertz radii on
every candidate node (median of ``--repeat`` runs after one untimed warm-up; the BEM solve is
not timed), the time of the maximum-shear field computed on demand, the peak resident memory
of the process, and the errors of the largest von Mises stress and maximum shear and of their
depth against Hertz (Johnson 1985, eq. 3.45, nu = 0.3).

Run: ``python benchmarks/bem_stress.py [--sizes 257,513,1025] [--depths 32] [--repeat 3]``
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import statistics
import time

import numpy as np
from scipy.optimize import minimize_scalar

import bem
from bem.gaps import Paraboloid
from bem.reference import hertz_sphere

R, E_STAR, FORCE, NU = 1.0, 1.0, 1.0, 0.3


def hertz_maximum(nu=NU):
    """Largest |sigma_z - sigma_r| on the axis (von Mises there) / p0 and its depth / a (Johnson eq. 3.45)."""
    def minus_vm(zeta):
        s_z = -1.0 / (1.0 + zeta**2)
        s_r = -(1.0 + nu) * (1.0 - zeta * math.atan(1.0 / zeta)) + 0.5 / (1.0 + zeta**2)
        return -abs(s_z - s_r)

    best = minimize_scalar(minus_vm, bounds=(0.2, 1.0), method="bounded", options={"xatol": 1e-10})
    return -best.fun, best.x


def run(n, *, n_depths, repeat):
    ref = hertz_sphere(R, E_STAR, force=FORCE)
    half = (n - 1) // 2
    step = ref.contact_radius / (0.6 * half)
    extent = (half * step, half * step * math.sqrt(3) / 2)
    res = bem.solve(Paraboloid(R), E_star=E_STAR, force=FORCE, step=step, extent=extent, rtol=1e-10)
    depths = np.linspace(0.0, 3.0, n_depths) * ref.contact_radius
    bem.subsurface_stress(res, depths, nu=NU)  # warm-up (FFT plans, page faults)
    times, st = [], None
    for _ in range(repeat):
        st = None
        t0 = time.perf_counter()
        st = bem.subsurface_stress(res, depths, nu=NU)
        times.append(time.perf_counter() - t0)
    t0 = time.perf_counter()
    shear = float(st.tresca.max())
    t_tresca = time.perf_counter() - t0
    vm_ref, depth_ref = hertz_maximum()
    return {
        "N": res.p.size, "across": 2 * ref.contact_radius / step, "time_s": statistics.median(times), "times": times,
        "tresca_s": t_tresca, "vm_err": st.max_von_mises / ref.p_max / vm_ref - 1,
        "shear_err": st.max_tresca / ref.p_max / (vm_ref / 2) - 1, "shear_field_err": shear / st.max_tresca - 1,
        "depth_err": st.depth_of_max / ref.contact_radius - depth_ref,
        "rss_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6,
    }


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="257,513,1025", help="lattice sides (nodes), comma-separated")
    parser.add_argument("--depths", type=int, default=32, help="depths from 0 to 3 a")
    parser.add_argument("--repeat", type=int, default=3, help="timed runs per size (median reported)")
    args = parser.parse_args(argv)
    print(f"load average before: {', '.join(f'{v:.2f}' for v in os.getloadavg())} on {os.cpu_count()} cores")
    print("| lattice | N | nodes across contact | depths | time [s] (runs) | max-shear field [s] | von Mises max err | "
          "max shear err | depth err / a | peak RSS [GB] |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for side in (int(s) for s in args.sizes.split(",")):
        row = run(side, n_depths=args.depths, repeat=args.repeat)
        runs = ", ".join(f"{t:.2f}" for t in row["times"])
        print(f"| {side}^2 | {row['N']:,} | {row['across']:.0f} | {args.depths} | {row['time_s']:.2f} ({runs}) | "
              f"{row['tresca_s']:.2f} | {row['vm_err']:+.1e} | {row['shear_err']:+.1e} | {row['depth_err']:+.4f} | "
              f"{row['rss_gb']:.2f} |", flush=True)
    print(f"load average after: {', '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
