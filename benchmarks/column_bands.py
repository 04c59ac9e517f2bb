"""Benchmark: the product ``C t`` of the half-space by bands of spectrum columns against the whole-array path.

For each size the rough sphere of :mod:`cases` is solved once (KKT residual ``1e-10``) with every product recorded;
the products of the finest lattice at its iterations 5, 10 and 20 are then repeated, each ``--repeat`` times by
each path in turn (``bem.column_bands.BANDS_ABOVE`` set to 0 for the bands, to infinity for the whole array):
the median time of one product and the traced peak of its temporaries (``tracemalloc``) per node, and the
largest difference of the two paths' outputs relative to their maximum.

Run: ``python benchmarks/column_bands.py [--sizes 512 1024 2048] [--repeat 15]``
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
import tracemalloc

import numpy as np

import cases


def record(n):
    """The finest operator of the rough sphere at ``n`` and the vectors it multiplied, in order."""
    import bem.operator as operator

    seen = {"n": 0}
    original = operator.InfluenceOperator.matvec

    def matvec(self, p):
        if self.lattice.n_nodes > seen["n"]:
            seen.update(n=self.lattice.n_nodes, op=self, vectors=[])
        if self.lattice.n_nodes == seen["n"] and len(seen["vectors"]) < 21:
            seen["vectors"].append(p.copy())
        return original(self, p)

    solve, _ = cases.prepare("rough-sphere", n)
    operator.InfluenceOperator.matvec = matvec
    try:
        solve()
    finally:
        operator.InfluenceOperator.matvec = original
    return seen["op"], [seen["vectors"][k] for k in (5, 10, 20) if k < len(seen["vectors"])]


def measure(op, v, bands, repeat):
    """Median seconds of ``op.matvec(v)``, the traced peak of one call [bytes], and its output."""
    import bem.operator as operator

    operator.BANDS_ABOVE = 0 if bands else math.inf
    out = op.matvec(v)  # warm: the window's spectra made and cached
    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    op.matvec(v)
    peak = tracemalloc.get_traced_memory()[1] - base
    tracemalloc.stop()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        op.matvec(v)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), peak, out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[512, 1024, 2048])
    parser.add_argument("--repeat", type=int, default=15)
    args = parser.parse_args(argv)
    print(f"# {cases.machine()['cpu']}, {cases.machine()['cores']} cores, load {cases.loadavg()}")
    print("| N | nodes | iteration | window rows x columns | whole array [ms] | by bands [ms] | peak whole / bands "
          "[B/node] | difference |")
    print("|---|---|---|---|---|---|---|---|")
    for n in args.sizes:
        op, vectors = record(n)
        for k, v in zip((5, 10, 20), vectors):
            box = op._box(v)
            rows, cols = sum(r[1] for r in box[0]), box[1][1]
            (tw, pw, ow), (tb, pb, ob) = (measure(op, v, bands, args.repeat) for bands in (False, True))
            diff = float(np.abs(ow - ob).max() / np.abs(ow).max())
            print(f"| {n}^2 | {op.lattice.n_nodes:,} | {k} | {rows} x {cols} | {1e3 * tw:.2f} | {1e3 * tb:.2f} | "
                  f"{pw / op.lattice.n_nodes:.1f} / {pb / op.lattice.n_nodes:.1f} | {diff:.1e} |", flush=True)


if __name__ == "__main__":
    main()
