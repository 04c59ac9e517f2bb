"""Benchmark: the layer law of a rough surface, ``bem.rough.layer_from_topography`` (a script, not a test).

A seeded self-affine surface (Hurst 0.8, ``n x n`` points on a unit cell, roll-off at 1/4,
cut-off at 1/32 of the cell, rms height 0.05) on the lattice of ``n`` nodes across, a ladder
of ``--pressures`` mean pressures from ``3e-3`` to ``0.3 E* h'_rms`` (geometric), each solve
warm-started from the previous one. Prints the ladder (contact fraction, mean gap, closure,
stiffness, iterations), the wall and CPU time of the ladder (the synthesis apart), the fitted Persson
rate ``gamma`` and the area factor ``kappa`` (docs/rough.md), and the load average of the
machine: the timing is only comparable between runs at a similar load.

``--hardness S`` solves the law of plastic asperities, hardness ``H = S E* h'_rms`` (the ladder
must lie below it, ``S > 0.3``). ``--compare R`` times the elastic law and the law of hardness
``--hardness`` (default 0.5) ``R`` times each, interleaved (elastic, plastic, elastic, ...), each in
a fresh process, with the 1-minute load average before and after each, and prints the table of
docs/performance.md: the ratio of the medians is the cost of the hardness.

Run: ``python benchmarks/layer_from_topography.py [--n 512] [--pressures 20] [--rtol 1e-8] [--hardness 0.5]
[--save law.toml]``, ``python benchmarks/layer_from_topography.py --compare 3 [--n 512]``
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np

from bem import rough


def _surface(args):
    return rough.self_affine((args.n, args.n), (1.0, 1.0), hurst=0.8, rms_height=0.05, long_cutoff=0.25,
                             short_cutoff=1 / 32, seed=args.seed)


def measure(args):
    """Solve the ladder once; returns ``(law, pressures, surface, measurements)``."""
    surface = _surface(args)
    slope = surface.stats.rms_slope
    pressures = np.geomspace(3e-3, 0.3, args.pressures) * slope  # E* = 1
    hardness = None if args.hardness is None else args.hardness * slope
    load_before = os.getloadavg()[0]
    t0, c0 = time.perf_counter(), time.process_time()
    law = rough.layer_from_topography(surface, 1.0, pressures=pressures, n_cols=args.n, method=args.method,
                                      rtol=args.rtol, hardness=hardness)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    out = dict(n=args.n, hardness_rel=args.hardness, wall_s=wall, cpu_s=cpu, iterations=int(law.iterations.sum()),
               contact_fraction_top=float(law.contact_fraction[-1]),
               plastic_fraction_top=None if hardness is None else float(law.plastic_fraction[-1]),
               load_before=load_before, load_after=os.getloadavg()[0])
    return law, pressures, surface, out


def compare(args):
    """Elastic and plastic ladders, interleaved, each in a fresh process (module docstring)."""
    rel = 0.5 if args.hardness is None else args.hardness
    base = [sys.executable, __file__, "--one", "--n", str(args.n), "--pressures", str(args.pressures), "--rtol",
            repr(args.rtol), "--method", args.method, "--seed", str(args.seed)]
    runs = {"elastic": [], "plastic": []}
    for _ in range(args.compare):
        for case, extra in (("elastic", []), ("plastic", ["--hardness", repr(rel)])):
            done = subprocess.run(base + extra, capture_output=True, text=True)
            if done.returncode:
                print(f"{case}: failed\n{done.stderr[-2000:]}", flush=True)
                return
            runs[case].append(json.loads(done.stdout.strip().splitlines()[-1]))
            print(case, runs[case][-1], flush=True)
    print(f"\n{args.n} x {args.n} nodes, {args.pressures} mean pressures 3e-3 .. 0.3 E* h'rms, rtol {args.rtol:g}, "
          f"hardness H = {rel:g} E* h'rms; {args.compare} runs of each, interleaved, a fresh process each; "
          f"{os.cpu_count()} cores\n")
    print("| law | wall [s], median (runs) | CPU [s], median | iterations | A/A0 at the top | flowing at the top "
          "| 1-min load before .. after |")
    print("|---|---|---|---|---|---|---|")
    for case, rows in runs.items():
        plastic = rows[0]["plastic_fraction_top"]
        walls = ", ".join(f"{r['wall_s']:.2f}" for r in rows)
        print(f"| {case if case == 'elastic' else f'H = {rel:g} E* h_rms'} "
              f"| {statistics.median(r['wall_s'] for r in rows):.2f} ({walls}) "
              f"| {statistics.median(r['cpu_s'] for r in rows):.2f} | {rows[0]['iterations']} "
              f"| {rows[0]['contact_fraction_top']:.3f} | {'-' if plastic is None else f'{plastic:.3f}'} "
              f"| {min(r['load_before'] for r in rows):.1f} .. {max(r['load_after'] for r in rows):.1f} |")
    ratio = statistics.median(r["wall_s"] for r in runs["plastic"]) / statistics.median(
        r["wall_s"] for r in runs["elastic"])
    print(f"\nwall time with the hardness / without: {ratio:.2f} (medians)")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=512, help="grid points and lattice nodes across the cell")
    parser.add_argument("--pressures", type=int, default=20, help="steps of the ladder")
    parser.add_argument("--rtol", type=float, default=1e-8)
    parser.add_argument("--method", default="newton")
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--hardness", type=float, help="hardness H in units of E* h'rms (default: elastic)")
    parser.add_argument("--compare", type=int, metavar="R", help="time elastic against plastic, R runs of each")
    parser.add_argument("--one", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--save", help="write the table file here")
    args = parser.parse_args(argv)
    if args.compare:
        compare(args)
        return
    if args.one:
        print(json.dumps(measure(args)[3]))
        return
    t0 = time.perf_counter()
    _surface(args)
    t_surface = time.perf_counter() - t0
    law, pressures, surface, out = measure(args)
    slope = surface.stats.rms_slope
    print(f"surface {args.n} x {args.n}, rms height {surface.stats.rms_height:.4g}, rms slope {slope:.4g} "
          f"(synthesis {t_surface:.2f} s); {args.pressures} mean pressures, {args.method}, rtol {args.rtol:g}"
          + ("" if args.hardness is None else f", hardness {args.hardness:g} E* h'rms"))
    print("| p/(E* h'rms) | A/A0 | ubar/h_rms | w/h_rms | K h_rms/(E* h'rms) | iterations |")
    print("|---|---|---|---|---|---|")
    hr = surface.stats.rms_height
    for p, a, u, w, k, it in zip(pressures, law.contact_fraction, law.mean_gap, law.closure, law.stiffness,
                                 law.iterations):
        print(f"| {p / slope:.3e} | {a:.4e} | {u / hr:.4f} | {w / hr:.4f} | {k * hr / slope:.4g} | {it} |")
    band = (law.contact_fraction >= 0.015) & (law.contact_fraction <= 0.15)
    gamma = -np.polyfit(np.log(pressures[band]), law.mean_gap[band] / hr, 1)[0] if band.sum() >= 2 else np.nan
    small = (law.contact_fraction >= 0.01) & (law.contact_fraction <= 0.05)
    x = pressures[small] / slope
    kappa = float(np.dot(x, law.contact_fraction[small]) / np.dot(x, x)) if small.any() else np.nan
    print(f"gamma = {gamma:.3f} (fit over 1.5 % <= A/A0 <= 15 %), kappa = {kappa:.3f} (1 % <= A/A0 <= 5 %, "
          "h'rms from SurfaceStats)")
    print(f"ladder: {out['wall_s']:.2f} s wall, {out['cpu_s']:.2f} s CPU (all threads), {out['iterations']} iterations; "
          f"1-min load average {out['load_before']:.2f} before, {out['load_after']:.2f} after on {os.cpu_count()} "
          "cores (a shared machine: other processes slow the run)")
    if args.save:
        print("saved", law.save(args.save))


if __name__ == "__main__":
    main()
