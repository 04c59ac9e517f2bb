"""Benchmark: the layer law of a rough surface, ``bem.rough.layer_from_topography`` (a script, not a test).

A seeded self-affine surface (Hurst 0.8, ``n x n`` points on a unit cell, roll-off at 1/4,
cut-off at 1/32 of the cell, rms height 0.05) on the lattice of ``n`` nodes across, a ladder
of ``--pressures`` mean pressures from ``3e-3`` to ``0.3 E* h'_rms`` (geometric), each solve
warm-started from the previous one. Prints the ladder (contact fraction, mean gap, closure,
stiffness, iterations), the wall and CPU time of the ladder (the synthesis apart), the fitted Persson
rate ``gamma`` and the area factor ``kappa`` (docs/rough.md), and the load average of the
machine: the timing is only comparable between runs at a similar load.

Run: ``python benchmarks/layer_from_topography.py [--n 512] [--pressures 20] [--rtol 1e-8] [--save law.toml]``
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from bem import rough


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=512, help="grid points and lattice nodes across the cell")
    parser.add_argument("--pressures", type=int, default=20, help="steps of the ladder")
    parser.add_argument("--rtol", type=float, default=1e-8)
    parser.add_argument("--method", default="newton")
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--save", help="write the table file here")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    surface = rough.self_affine((args.n, args.n), (1.0, 1.0), hurst=0.8, rms_height=0.05, long_cutoff=0.25,
                                short_cutoff=1 / 32, seed=args.seed)
    t_surface = time.perf_counter() - t0
    slope = surface.stats.rms_slope
    pressures = np.geomspace(3e-3, 0.3, args.pressures) * slope  # E* = 1
    print(f"surface {args.n} x {args.n}, rms height {surface.stats.rms_height:.4g}, rms slope {slope:.4g} "
          f"(synthesis {t_surface:.2f} s); {args.pressures} mean pressures, {args.method}, rtol {args.rtol:g}")
    load_before = os.getloadavg()[0]
    t0, c0 = time.perf_counter(), time.process_time()
    law = rough.layer_from_topography(surface, 1.0, pressures=pressures, n_cols=args.n, method=args.method,
                                      rtol=args.rtol)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    load_after = os.getloadavg()[0]
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
    print(f"ladder: {wall:.2f} s wall, {cpu:.2f} s CPU (all threads), {int(law.iterations.sum())} iterations; 1-min load average "
          f"{load_before:.2f} before, {load_after:.2f} after on {os.cpu_count()} cores (a shared machine: "
          "other processes slow the run)")
    if args.save:
        print("saved", law.save(args.save))


if __name__ == "__main__":
    main()
