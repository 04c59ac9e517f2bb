"""Benchmark: contactlab against an independent Polonsky-Keer solver, same problem, same run.

The problem: sphere ``R = 1`` on a flat, ``E* = 1``, square candidate region
of side 1, force such that the Hertz radius is 0.1, node density of an ``N x N``
grid (contactlab: triangular lattice of step ``sqrt(2/sqrt3)/N``, the same nodes per
area), KKT residual ``1e-10``. Cases: ``hertz`` (no layer; the yardstick is plain PK,
:mod:`plain_pk`) and ``root`` (layer ``w = 0.04 sqrt(p)``; ours is
``bem.solve(..., layer=bem.layers.Root(0.04))``, the yardstick the Jacobi-preconditioned
nonlinear PK of :mod:`plain_pk`) and ``rough`` (the rough sphere of :mod:`cases`: the sphere with
its self-affine roughness, force of the Hertz radius 0.3; ours solves its callable, the yardstick
the same surface at the centres of its grid's cells; the time spent making the surface is not
counted for either).

Every size runs in its own subprocess; inside it the two solvers alternate
(ours, PK, ours, PK, ...) and the median of ``--repeat`` runs is reported, after one
untimed warm-up of each at N = 128. With ``--rss`` each (size, case, solver) is run
once more in a fresh subprocess whose peak resident set (``ru_maxrss``, interpreter
and libraries included) is reported. The 1-minute load average is printed per row:
on a shared machine compare ratios, not absolute times.

Run: ``python benchmarks/side_by_side.py [--sizes 128 256 512 1024] [--cases hertz root rough]
[--repeat 3] [--rss] [--skip-pk-above 2048]``
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]

RADIUS, E_STAR, A_HERTZ, SIDE, ROOT_K = 1.0, 1.0, 0.1, 1.0, 0.04
FORCE = 4 * A_HERTZ**3 * E_STAR / (3 * RADIUS)  # a^3 = 3 P R / (4 E*)


def ours(n, case):
    import bem
    from bem.gaps import Paraboloid

    if case == "rough":  # the rough sphere of cases: its callable's own time is not the solver's
        from cases import prepare, summary

        solve, gap = prepare("rough-sphere", n)
        res = solve()
        return dict(summary(res), gap_s=gap.seconds)
    step = math.sqrt(2 / math.sqrt(3)) * SIDE / n  # sqrt(3)/2 c^2 = (SIDE/n)^2
    layer = bem.layers.Root(ROOT_K) if case == "root" else None
    res = bem.solve(Paraboloid(RADIUS), E_star=E_STAR, force=FORCE, step=step, extent=SIDE / 2, rtol=1e-10,
                    layer=layer)
    return {"iterations": res.iterations, "kkt": res.kkt_residual, "nodes": res.p.size, "converged": res.converged}


def pk(n, case):
    import numpy as np
    from plain_pk import solve_pk

    if case == "rough":  # the rough sphere of cases on the grid; making the array is not the solver's time
        from cases import A_ROUGH, hertz_force, rough_sphere_grid_gap

        t0 = time.perf_counter()
        gap = rough_sphere_grid_gap(n)
        gap_s = time.perf_counter() - t0
        res = solve_pk(n, side=SIDE, e_star=E_STAR, force=hertz_force(A_ROUGH), gap=gap, rtol=1e-10)
        return {"iterations": res["iterations"], "kkt": res["kkt"], "nodes": n * n, "converged": res["kkt"] <= 1e-10,
                "gap_s": gap_s}
    layer = None
    if case == "root":
        layer = (lambda q: ROOT_K * np.sqrt(q), lambda q: 0.5 * ROOT_K / np.sqrt(q), lambda g: (g / ROOT_K) ** 2)
    res = solve_pk(n, side=SIDE, radius=RADIUS, e_star=E_STAR, force=FORCE, layer=layer, rtol=1e-10)
    return {"iterations": res["iterations"], "kkt": res["kkt"], "nodes": n * n, "converged": res["kkt"] <= 1e-10}


SOLVERS = {"ours": ours, "pk": pk}


def _timed(fn, n, case):
    t0 = time.perf_counter()
    out = fn(n, case)
    out["time_s"] = time.perf_counter() - t0 - out.pop("gap_s", 0.0)
    return out


def worker(n, case, repeat, solvers):
    for name in solvers:  # warm-up: imports, FFT plans
        SOLVERS[name](128, case)
    runs = {name: [] for name in solvers}
    for _ in range(repeat):
        for name in solvers:
            runs[name].append(_timed(SOLVERS[name], n, case))
    out = {}
    for name, rs in runs.items():
        out[name] = dict(rs[-1], time_s=statistics.median(r["time_s"] for r in rs),
                         times=[round(r["time_s"], 3) for r in rs])
    out["load"] = os.getloadavg()[0]
    return out


def rss_worker(n, case, solver):
    SOLVERS[solver](n, case)
    return {"rss_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6}


def _sub(args):
    done = subprocess.run([sys.executable, os.path.abspath(__file__), *args], capture_output=True, text=True,
                          check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[128, 256, 512, 1024])
    parser.add_argument("--cases", nargs="+", default=["hertz", "root"], choices=["hertz", "root", "rough"])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--rss", action="store_true", help="peak RSS per (size, case, solver) in a fresh process")
    parser.add_argument("--skip-pk-above", type=int, default=2048, help="run the yardstick only up to this N")
    parser.add_argument("--worker", nargs=3, help=argparse.SUPPRESS)
    parser.add_argument("--rss-worker", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        n, case, solvers = int(args.worker[0]), args.worker[1], args.worker[2].split(",")
        print(json.dumps(worker(n, case, args.repeat, solvers)))
        return
    if args.rss_worker:
        print(json.dumps(rss_worker(int(args.rss_worker[0]), args.rss_worker[1], args.rss_worker[2])))
        return
    print(f"# {os.cpu_count()} CPUs, affinity {len(os.sched_getaffinity(0))}, load at start "
          f"{os.getloadavg()[0]:.2f}; median of {args.repeat}, solvers alternating in one process")
    print("| case | N | nodes (ours) | ours [s] | its | KKT | PK [s] | its | KKT | PK / ours | "
          "RSS ours [GB] | RSS PK [GB] | load |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for case in args.cases:
        for n in args.sizes:
            solvers = ["ours", "pk"] if n <= args.skip_pk_above else ["ours"]
            row = _sub(["--worker", str(n), case, ",".join(solvers), "--repeat", str(args.repeat)])
            rss = {s: _sub(["--rss-worker", str(n), case, s])["rss_gb"] if args.rss and s in solvers else math.nan
                   for s in ("ours", "pk")}
            o, p = row["ours"], row.get("pk")
            pk_cols = (f"{p['time_s']:.2f} | {p['iterations']} | {p['kkt']:.1e} | {p['time_s'] / o['time_s']:.1f}"
                       if p else "- | - | - | -")
            print(f"| {case} | {n} | {o['nodes']:,} | {o['time_s']:.2f} | {o['iterations']} | {o['kkt']:.1e} | "
                  f"{pk_cols} | {rss['ours']:.2f} | {rss['pk']:.2f} | {row['load']:.1f} |", flush=True)


if __name__ == "__main__":
    main()
