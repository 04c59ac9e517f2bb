"""Benchmark: a periodic rough contact with and without a hardness (bem.solve_periodic(..., hardness=H)).

The surface of ``benchmarks/periodic_rough.py`` (seeded self-affine, Hurst 0.8, rms slope 0.1,
``E* = 1``) on ``N x N`` cells (``--sizes``, default 256 and 1024), mean pressure ``0.01 E*``,
KKT residual ``1e-10``, default options (nested iteration). Each size is solved elastic, then with
the hardness ``H`` at the fractions ``--fractions`` (default 0.5 and 0.25) of the elastic peak
pressure; each row gives the iterations on the finest cell, the products with ``C``, the wall and
CPU time (``time.process_time``), the KKT residual, the contact and plastic fractions and the
1-minute load average (compare ratios within a run, not times across runs).

Run: ``python benchmarks/periodic_hardness.py [--sizes 256 1024] [--fractions 0.5 0.25]``
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from periodic_rough import surface_on_cell  # noqa: E402  (the same seeded surface)

from bem.periodic import PeriodicCell, solve_periodic  # noqa: E402

PBAR = 0.01


def _solve(cell, h, hardness):
    t, c = time.perf_counter(), time.process_time()
    res = solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=PBAR, rtol=1e-10, hardness=hardness)
    return res, time.perf_counter() - t, time.process_time() - c


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[256, 1024])
    ap.add_argument("--fractions", type=float, nargs="+", default=[0.5, 0.25])
    args = ap.parse_args()
    rows = []
    for n in args.sizes:
        cell = PeriodicCell(1.0 / n, n, n)
        h = surface_on_cell(cell)
        elastic = None
        for fraction in [None, *args.fractions]:
            hardness = None if fraction is None else fraction * elastic.p_max
            res, wall, cpu = _solve(cell, h, hardness)
            if fraction is None:
                elastic = res
            rows.append({"n": n, "hardness_over_p_max": fraction, "hardness": hardness, "status": res.status,
                         "iterations": res.iterations, "n_matvec": res.n_matvec, "wall_s": wall, "cpu_s": cpu,
                         "kkt": res.kkt_residual, "contact_fraction": res.contact_fraction,
                         "plastic_fraction": res.plastic_fraction, "load": os.getloadavg()[0]})
            print(json.dumps(rows[-1]), flush=True)
    print("\n| N | H / p_max(elastic) | iterations | products | wall [s] | CPU [s] | KKT | contact | plastic | load |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        h = "elastic" if r["hardness_over_p_max"] is None else f"{r['hardness_over_p_max']:g}"
        print(f"| {r['n']} | {h} | {r['iterations']} | {r['n_matvec']} | {r['wall_s']:.2f} | {r['cpu_s']:.2f} | "
              f"{r['kkt']:.1e} | {r['contact_fraction']:.4f} | {r['plastic_fraction']:.4f} | {r['load']:.1f} |")


if __name__ == "__main__":
    main()
