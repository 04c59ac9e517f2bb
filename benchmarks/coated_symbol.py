"""Benchmark: the build of the coated periodic operator against the homogeneous one.

A cell of ``N x N`` nodes (default 1024) of step ``c = 1``; the homogeneous operator
(:class:`bem.PeriodicOperator` of ``E*``) and the operators of a coated body (coating
``E_c = E_s / 10``, ``nu_c = 0.3`` on a steel-like substrate against a rigid flat) for coating
thicknesses ``t / c`` in ``--thickness`` (default 0.5, 1, 4, 64). Each build runs in a fresh
process (the templates are cached per process), so the rows are first-call costs; a second
build of the same operator in the same process is a cache hit (the row "warm"). The alias sum
of the coating has about ``0.069 N g^2`` terms for the cut ``g`` (1/step,
:func:`bem.periodic.coated.alias_cut`), which the row shows.

``--solve N``: the seeded self-affine cell of ``benchmarks/periodic_rough.py`` (``N x N`` nodes,
mean pressure ``0.01 E*``, KKT ``1e-10``) solved homogeneous and coated (``t = 4 c``, the same
coating), each twice in one process: the first solve builds the operators of nested iteration,
the second finds them cached (the rows "warm": the cost of the solve itself).

Each row gives the wall time and the CPU time of the process (``time.process_time``, all its
threads) and the 1-minute load average: compare ratios within a run.

Run: ``python benchmarks/coated_symbol.py [--size 1024] [--thickness 0.5 1 4 64] [--solve 512]``
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

_CHILD = """
import json, math, sys, time
import bem
from bem.periodic import PeriodicCell, PeriodicOperator
from bem.periodic.coated import alias_cut, routes
n, t = int(sys.argv[1]), float(sys.argv[2])
cell = PeriodicCell(1.0, n, n)
E, nu = 210e9, 0.3
if t > 0:
    bodies = bem.Bodies(E, nu, math.inf, 0.0, coating1=bem.Coating(t, E / 10, 0.3))
    kw, E_star, cut = dict(bodies=bodies), bodies.E_star, alias_cut(bodies, 1.0)
else:
    kw, E_star, cut = {}, E / (1 - nu * nu), 0.0
w0, c0 = time.perf_counter(), time.process_time()
PeriodicOperator(cell, E_star, **kw)
w1, c1 = time.perf_counter(), time.process_time()
PeriodicOperator(cell, E_star, **kw)
w2 = time.perf_counter()
route = "-" if t == 0 else ("real space" if routes(n, n, 1.0, bodies)[1] else "alias sum")
print(json.dumps(dict(wall=w1 - w0, cpu=c1 - c0, warm=w2 - w1, cut=cut, terms=0.069 * n * n * cut * cut,
                      route=route)))
"""


_SOLVE = """
import json, math, sys, time
sys.path.insert(0, sys.argv[3])
import bem
from bem.periodic import PeriodicCell
from periodic_rough import surface_on_cell
n, t = int(sys.argv[1]), float(sys.argv[2])
cell = PeriodicCell(1.0 / n, n, n)
h = surface_on_cell(cell)
E, nu = 1.0, 0.3
kw = dict(E1=E, nu1=nu, E2=math.inf, nu2=0.0, mean_pressure=0.01 * E / (1 - nu * nu), rtol=1e-10)
if t > 0:
    kw["coating1"] = bem.Coating(t * cell.step, E / 10, 0.3)
for label in ("first", "warm"):
    w, c = time.perf_counter(), time.process_time()
    res = bem.solve(h, domain=cell, **kw)
    print(json.dumps(dict(label=label, wall=time.perf_counter() - w, cpu=time.process_time() - c,
                          iterations=res.iterations, kkt=res.kkt_residual, fraction=res.contact_fraction)))
"""


def _solve_rows(n):
    from pathlib import Path

    print(f"solve {n} x {n}: {'body':>10} {'solve':>6} {'wall s':>8} {'cpu s':>8} {'iter':>5} {'KKT':>9} "
          f"{'contact':>8}")
    for t in (0.0, 4.0):
        out = subprocess.run([sys.executable, "-c", _SOLVE, str(n), str(t), str(Path(__file__).parent)],
                             capture_output=True, text=True, check=True)
        for line in out.stdout.splitlines():
            r = json.loads(line)
            body = "plain" if t == 0 else f"t = {t:g} c"
            print(f"{'':>14}{body:>10} {r['label']:>6} {r['wall']:8.2f} {r['cpu']:8.2f} {r['iterations']:5d} "
                  f"{r['kkt']:9.2e} {r['fraction']:8.4f}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--thickness", type=float, nargs="+", default=[0.5, 1.0, 4.0, 64.0])
    ap.add_argument("--solve", type=int, default=0, metavar="N", help="also time a rough solve on N x N nodes")
    args = ap.parse_args(argv)
    print(f"cell {args.size} x {args.size} nodes, load {os.getloadavg()[0]:.2f}")
    print(f"{'t / c':>8} {'cut g':>8} {'terms':>10} {'route':>11} {'wall s':>8} {'cpu s':>8} {'warm s':>8}")
    for t in [0.0, *args.thickness]:
        out = subprocess.run([sys.executable, "-c", _CHILD, str(args.size), str(t)], capture_output=True, text=True,
                             check=True)
        r = json.loads(out.stdout)
        label = "none" if t == 0 else f"{t:g}"
        print(f"{label:>8} {r['cut']:8.3g} {r['terms']:10.3g} {r['route']:>11} {r['wall']:8.2f} {r['cpu']:8.2f} "
              f"{r['warm']:8.2f}")
    if args.solve:
        _solve_rows(args.solve)
    print(f"load {os.getloadavg()[0]:.2f} at the end ({time.strftime('%H:%M:%S')})")


if __name__ == "__main__":
    main()
