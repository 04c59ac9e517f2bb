"""Benchmark: the finest cell's iterations with the preconditioner corrected at the edges of the contact.

Each surface, size and mean pressure is solved by ``bem.solve_periodic`` (nested iteration, KKT residual ``1e-10``,
``E* = 1``) once for each ``theta`` of :mod:`bem.periodic.edge` (``theta = 0``: the correction made and zero, the
preconditioner ``M_AA`` alone), in one process; the rows give the finest cell's iterations, the products with ``C``
of every level, the KKT residual and the share of nodes in contact. Iterations and products do not depend on the
machine. Surfaces (the gap ``max(z) - z``):

- ``self-affine``: the surface of ``periodic_rough.py`` (Hurst exponent 0.8, rms slope 0.1, roll-off at 4 and
  cut-off at 128 periods of the cell), seeds 2026 (the benchmark cell's) and ``--seeds``; hundreds of spots;
- ``wavy``: ``0.01 (2 - cos(2 pi x / Lx) - cos(2 pi y / Ly))``, one spot;
- ``bumps``: the same with four periods each way plus ``0.003 sin(2 pi (3 x / Lx + 5 y / Ly))``, sixteen spots.

Run: ``python benchmarks/periodic_edge.py --out benchmarks/results/periodic_edge [--sizes 256 512] [--thetas 0 0.7
0.9] [--seeds 1 2 3]`` (``edge.json``, ``edge.md`` in ``--out``).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]

import cases  # noqa: E402
import periodic_rough  # noqa: E402

import bem  # noqa: E402
import bem.periodic.edge as edge  # noqa: E402
from bem.periodic import PeriodicCell  # noqa: E402

BENCHMARK_SEED = periodic_rough.SEED  # the benchmark cell's surface
LOADS = {"self-affine": (0.003, 0.01, 0.03), "wavy": (0.003, 0.03), "bumps": (0.003, 0.03)}


def surface(name, n, seed):
    """``(cell, gap)`` of the surface ``name`` on the ``n x n`` cell (``seed``: the self-affine surface's)."""
    if name == "self-affine":
        periodic_rough.SEED = seed
        return cases.periodic_cell(n)
    cell = PeriodicCell(1.0 / n, n, n)
    lx, ly = cell.size
    k = 1 if name == "wavy" else 4
    z = -0.01 * (2 - np.cos(2 * math.pi * k * cell.x / lx) - np.cos(2 * math.pi * k * cell.y / ly))
    if name == "bumps":
        z -= 0.003 * np.sin(2 * math.pi * (3 * cell.x / lx + 5 * cell.y / ly))
    return cell, z.max() - z


def finest(cell, h, pbar, theta):
    """The row of one solve with ``theta``: the finest cell's iterations, the products with ``C`` of every level, the
    KKT residual and the share of nodes in contact."""
    edge_theta, edge.THETA = edge.THETA, theta
    try:
        res = bem.solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=pbar, rtol=cases.RTOL)
    finally:
        edge.THETA = edge_theta
    return dict(iterations=res.iterations, products=res.n_matvec, kkt=float(res.kkt_residual),
                converged=bool(res.converged), contact=round(float(np.mean(res.p > 0)), 4))


def markdown(rows, thetas):
    head = "| surface | seed | N | mean pressure / E* | contact | " + " | ".join(
        f"finest iterations (products, all levels), theta {t}" for t in thetas) + " |"
    lines = [head, "|" + "---|" * (5 + len(thetas))]
    for r in rows:
        runs = " | ".join(f"{s['iterations']} ({s['products']})" for s in r["runs"])
        lines.append(f"| {r['surface']} | {r['seed'] if r['surface'] == 'self-affine' else '-'} | {r['n']}^2 | "
                     f"{r['mean_pressure']} | {r['runs'][0]['contact']} | {runs} |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="results folder")
    parser.add_argument("--sizes", nargs="+", type=int, default=[256, 512])
    parser.add_argument("--thetas", nargs="+", type=float, default=[0.0, edge.THETA])
    parser.add_argument("--seeds", nargs="*", type=int, default=[1, 2, 3], help="self-affine seeds beside 2026")
    parser.add_argument("--surfaces", nargs="+", choices=sorted(LOADS), default=sorted(LOADS))
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for n in args.sizes:
        for name in args.surfaces:
            for seed in [BENCHMARK_SEED] + args.seeds if name == "self-affine" else [None]:
                cell, h = surface(name, n, seed)
                for pbar in LOADS[name]:
                    runs = [finest(cell, h, pbar, t) for t in args.thetas]
                    if not all(r["converged"] for r in runs):
                        raise RuntimeError(f"{name} {n}^2 at {pbar}: a solve did not converge: {runs}")
                    rows.append(dict(surface=name, seed=seed, n=n, mean_pressure=pbar, thetas=args.thetas, runs=runs))
                    print(json.dumps(rows[-1]), flush=True)
            periodic_rough.SEED = BENCHMARK_SEED
    cases.write_whole(os.path.join(args.out, "edge.json"),
                      json.dumps(dict(machine=cases.machine(), rows=rows), indent=1))
    cases.write_whole(os.path.join(args.out, "edge.md"), markdown(rows, args.thetas))
    print(markdown(rows, args.thetas))


if __name__ == "__main__":
    main()
