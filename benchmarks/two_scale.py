"""Benchmark: the fully resolved rough sphere of the two-scale check at millions of nodes.

The problem is that of ``contactlab study two-scale`` (:mod:`validation.studies.two_scale`,
its ``SETTINGS``): a sphere carrying the tiled self-affine roughness cell (Hurst 0.8, roll-off
``lambda_L = 20 um``, cut-off ``lambda_L/4``, rms height 0.1 um), ``sigma R/a_H^2 = 0.1``, at 16
nodes per ``lambda_L``, the candidate region ``|x|, |y| <= 2 a_H``; the ratio ``a_H/lambda_L`` is
chosen so that the region holds about ``--nodes`` nodes. One :func:`bem.solve` under force
control (KKT residual ``1e-8``, nested iteration), in a fresh process per size: wall time,
iterations, and the peak resident set (``ru_maxrss``). The 1-minute load average before and after
is printed: the machine may be shared.

Run: ``python benchmarks/two_scale.py [--nodes 4e6 16e6]``
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time


def one(nodes):
    """Solve the resolved rough sphere with about ``nodes`` nodes; returns a dict of measurements."""
    import bem
    from validation.studies.two_scale import SETTINGS, _sphere, make_surface
    from validation.studies.two_scale_models import TiledRoughness

    s = SETTINGS
    step = s["roll_off"] / s["nodes_per_roll_off"]
    # nodes ~ (2 e/c) (2 e/(c sqrt(3)/2)), e = extent_factor a_H
    a = math.sqrt(nodes * math.sqrt(3) / 8) * step / s["extent_factor"]
    ratio = a / s["roll_off"]
    R, force = _sphere(s, ratio)
    cell = make_surface(s).to_lattice(s["nodes_per_roll_off"] * s["cell_roll_offs"])
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    res = bem.solve(TiledRoughness(cell, R), E_star=s["E_star"], force=force, step=step,
                    extent=s["extent_factor"] * a, rtol=s["rtol"])
    wall = time.perf_counter() - t0
    return dict(nodes=int(res.lattice.n_nodes), ratio=ratio, wall_time_s=wall, converged=bool(res.converged),
                iterations=int(res.iterations), method=res.method, kkt_residual=float(res.kkt_residual),
                contact_fraction=float((res.p > 0).mean()), peak_rss_gib=resource.getrusage(
                    resource.RUSAGE_SELF).ru_maxrss / 2**20, load_before=load, load_after=os.getloadavg()[0])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=float, nargs="+", default=[4e6])
    ap.add_argument("--one", type=float, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        print(json.dumps(one(args.one)))
        return
    for n in args.nodes:
        out = subprocess.run([sys.executable, __file__, "--one", str(n)], capture_output=True, text=True)
        print(out.stdout.strip() or f"nodes {n:.3g}: failed\n{out.stderr[-2000:]}", flush=True)


if __name__ == "__main__":
    main()
