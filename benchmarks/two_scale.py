"""Benchmark: the fully resolved rough sphere of the two-scale check at millions of nodes.

The problem is that of ``contactlab study two-scale`` (:mod:`validation.studies.two_scale`,
its ``SETTINGS``): a sphere carrying the tiled self-affine roughness cell (Hurst 0.8, roll-off
``lambda_L = 20 um``, cut-off ``lambda_L/4``, rms height 0.1 um), ``sigma R/a_H^2 = 0.1``, at 16
nodes per ``lambda_L``, the candidate region ``|x|, |y| <= 2 a_H``; the ratio ``a_H/lambda_L`` is
chosen so that the region holds about ``--nodes`` nodes. One :func:`bem.solve` under force
control (KKT residual ``1e-8``, nested iteration), in a fresh process per size: wall time,
iterations, and the peak resident set (``ru_maxrss``). The 1-minute load average before and after
is printed: the machine may be shared. ``--hardness H`` [Pa] caps the pressure at ``H`` (plastic
asperities, the study's ``settings["hardness"]``).

Run: ``python benchmarks/two_scale.py [--nodes 4e6 16e6] [--hardness 5e9]``
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


def one(nodes, hardness=None):
    """Solve the resolved rough sphere with about ``nodes`` nodes (``hardness`` [Pa]: plastic asperities);
    returns a dict of measurements."""
    from validation.studies.two_scale import SETTINGS, _sphere, make_surface, resolved_solve

    s = dict(SETTINGS, hardness=hardness)
    step = s["roll_off"] / s["nodes_per_roll_off"]
    # nodes ~ (2 e/c) (2 e/(c sqrt(3)/2)), e = extent_factor a_H
    a = math.sqrt(nodes * math.sqrt(3) / 8) * step / s["extent_factor"]
    ratio = a / s["roll_off"]
    R, force = _sphere(s, ratio)
    surface = make_surface(s)
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    res, _ = resolved_solve(s, surface, R, force, s["nodes_per_roll_off"], s["extent_factor"] * a)
    wall = time.perf_counter() - t0
    return dict(nodes=int(res.lattice.n_nodes), ratio=ratio, hardness=hardness, plastic_area=res.plastic_area,
                wall_time_s=wall, converged=bool(res.converged),
                iterations=int(res.iterations), method=res.method, kkt_residual=float(res.kkt_residual),
                contact_fraction=float((res.p > 0).mean()), peak_rss_gib=resource.getrusage(
                    resource.RUSAGE_SELF).ru_maxrss / 2**20, load_before=load, load_after=os.getloadavg()[0])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=float, nargs="+", default=[4e6])
    ap.add_argument("--hardness", type=float, help="hardness H [Pa] of the asperities (default: elastic)")
    ap.add_argument("--one", type=float, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        print(json.dumps(one(args.one, args.hardness)))
        return
    for n in args.nodes:
        extra = [] if args.hardness is None else ["--hardness", repr(args.hardness)]
        out = subprocess.run([sys.executable, __file__, "--one", str(n), *extra], capture_output=True, text=True)
        print(out.stdout.strip() or f"nodes {n:.3g}: failed\n{out.stderr[-2000:]}", flush=True)


if __name__ == "__main__":
    main()
