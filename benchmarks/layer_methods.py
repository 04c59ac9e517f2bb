"""Benchmark: every layer law x every method on the paper's test problem (a script, not a test).

The paper's problem (section 6, Fig. 4a): two paraboloids, normalised R = E* = P = 1,
the layer compliance ``lam = factor * C_nn`` (the paper's Fig. 5 uses 10), the
elastic-rigid threshold and the bilinear knee at ``0.5 p0`` (Hertz peak), the
bilinear second slope ``lam2 = lam tan(0.2)``. Prints iterations, wall time
(median of ``--repeat``), KKT residual and the difference from Newton.

Run: ``python benchmarks/layer_methods.py [--across 40] [--factor 10] [--repeat 3]``
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

import bem
from bem import layers
from bem.gaps import Paraboloid

METHODS = ("newton", "variable_compliance", "augmented_gap")


def laws(lam, p0):
    return {
        "linear": layers.Linear(lam),
        "root": layers.Root(lam * math.sqrt(p0)),
        "power s=2": layers.Power(lam / p0, 2.0),
        "elastic-rigid": layers.ElasticRigid(lam, 0.5 * p0),
        "bilinear": layers.Bilinear(lam, lam * math.tan(0.2), 0.5 * p0),
    }


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--across", type=int, default=40, help="nodes across the Hertz contact diameter")
    parser.add_argument("--factor", type=float, default=10.0, help="layer compliance in units of C_nn")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--relaxation", type=float, default=1.0, help="omega of the augmented gap method")
    args = parser.parse_args(argv)
    a = (3 / 4) ** (1 / 3)
    p0 = 3 / (2 * math.pi * a * a)
    step = 2 * a / args.across
    lam = args.factor * bem.diagonal_coefficient(step, 1.0)
    print(f"paper problem, {args.across} nodes across, lam = {args.factor:g} C_nn, omega = {args.relaxation:g}")
    print("| law | method | converged | iterations | time [s] | KKT residual | L2 diff. from Newton | message |")
    print("|---|---|---|---|---|---|---|---|")
    for name, layer in laws(lam, p0).items():
        ref = None
        for method in METHODS:
            kw = {"relaxation": args.relaxation} if method == "augmented_gap" else {}
            times = []
            for _ in range(args.repeat):
                t0 = time.perf_counter()
                res = bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=step, extent=2.2 * a,
                                layer=layer, method=method, **kw)
                times.append(time.perf_counter() - t0)
            ref = res if method == "newton" else ref
            diff = np.linalg.norm(res.p - ref.p) / np.linalg.norm(ref.p)
            print(f"| {name} | {method} | {res.converged} | {res.iterations} | {statistics.median(times):.2f} | "
                  f"{res.kkt_residual:.1e} | {diff:.1e} | {res.message[:60]} |", flush=True)


if __name__ == "__main__":
    import logging

    logging.disable(logging.WARNING)
    main()
