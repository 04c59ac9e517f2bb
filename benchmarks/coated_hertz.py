"""Benchmark: a sphere on a coated flat against the same sphere on the bare substrate (a script, not a test).

The candidate region holds ``n x n`` nodes, the Hertz contact of the substrate spans 60 % of it
(as in ``benchmarks/bem_hertz.py``). Both problems are solved the same way: an
``InfluenceOperator`` (with ``bodies=`` for the coated one) and ``bem.kalker.solve_qp`` under
force control with the operator's preconditioner, KKT residual ``--rtol``. Prints the time of the
coated coefficient table on first use (``bem.coated_kernel.coated_table``, not cached), the
operator's construction with the table cached, and the median solve times of ``--repeat`` runs
(interleaved between the two bodies; a first, untimed run of each warms the FFT caches), with iterations and KKT residuals.

Run: ``python benchmarks/coated_hertz.py [--side 1024] [--repeat 3] [--thickness 0.5]``
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time

import numpy as np

from bem.coated_kernel import coated_table
from bem.coating import Bodies, Coating
from bem.kalker import solve_qp
from bem.lattice import Lattice
from bem.operator import InfluenceOperator
from bem.reference import hertz_sphere

R, FORCE = 1.0, 1.0
E_S, NU_S, E_C, NU_C = 2.0, 0.3, 0.5, 0.35  # substrate, coating: a soft coating


def _solve(op, h, rtol):
    t0 = time.perf_counter()
    sol = solve_qp(op, h, force=FORCE, rtol=rtol, preconditioner=op.preconditioner())
    return time.perf_counter() - t0, sol


def run(side, *, thickness, rtol, repeat):
    bodies = Bodies(E_S, NU_S, math.inf, 0.3, Coating(1.0, E_C, NU_C))  # thickness set below
    ref = hertz_sphere(R, bodies.E_star, force=FORCE)
    half = side // 2
    step = ref.contact_radius / (0.6 * half)
    lat = Lattice.from_extent(step, (half * step, half * step * math.sqrt(3) / 2))
    bodies = Bodies(E_S, NU_S, math.inf, 0.3, Coating(thickness * ref.contact_radius, E_C, NU_C))
    h = (lat.x ** 2 + lat.y ** 2) / (2 * R)
    t0 = time.perf_counter()
    coated_table(step, lat.shape, bodies)
    build = time.perf_counter() - t0
    ops = {"uncoated": InfluenceOperator(lat, bodies.E_star), "coated": None}
    t0 = time.perf_counter()
    ops["coated"] = InfluenceOperator(lat, bodies.E_star, bodies=bodies)  # the table from the cache
    construct = time.perf_counter() - t0
    runs = {name: [] for name in ops}
    for name, op in ops.items():
        _solve(op, h, rtol)  # warm-up
    for _ in range(repeat):  # interleaved, so that a change of the machine's load hits both
        for name, op in ops.items():
            runs[name].append(_solve(op, h, rtol))
    rows = {}
    for name in ops:
        sol = runs[name][-1][1]
        rows[name] = dict(construct=f"{construct:.2f}" if name == "coated" else "-", times=[t for t, _ in runs[name]],
                          iterations=sol.iterations, kkt=sol.kkt_residual, p_max=float(np.max(sol.p)),
                          approach=sol.approach)
    return lat, step, build, rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--side", type=int, default=1024, help="lattice side (nodes - 1)")
    parser.add_argument("--repeat", type=int, default=3, help="timed solves (median reported)")
    parser.add_argument("--thickness", type=float, default=0.5, help="coating thickness / Hertz radius of the substrate")
    parser.add_argument("--rtol", type=float, default=1e-10, help="KKT tolerance")
    args = parser.parse_args(argv)
    load = os.getloadavg()[0]
    lat, step, build, rows = run(args.side + 1, thickness=args.thickness, rtol=args.rtol, repeat=args.repeat)
    print(f"lattice {lat.shape[0]} x {lat.shape[1]} ({lat.n_nodes:,} nodes), coating t = {args.thickness} a_s "
          f"= {args.thickness * 0.6 * (args.side // 2):.0f} steps, E_c/E_s = {E_C / E_S}, load average at start {load:.1f}")
    print(f"coated coefficient table, first call: {build:.2f} s")
    print("| body | operator [s] | solve [s] (runs) | iterations | KKT residual | p_max | approach |")
    print("|---|---|---|---|---|---|---|")
    for name, r in rows.items():
        runs = ", ".join(f"{t:.2f}" for t in r["times"])
        print(f"| {name} | {r['construct']} | {statistics.median(r['times']):.2f} ({runs}) | {r['iterations']} | "
              f"{r['kkt']:.1e} | {r['p_max']:.4g} | {r['approach']:.4g} |")
    ratio = statistics.median(rows["coated"]["times"]) / statistics.median(rows["uncoated"]["times"])
    print(f"coated / uncoated solve time: {ratio:.2f}; load average at end {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
