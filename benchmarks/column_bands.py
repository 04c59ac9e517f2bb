"""Benchmark: the product ``C v`` of the half-space by bands of spectrum columns against the whole-array path.

For each size the rough sphere of :mod:`cases` is solved once (KKT residual ``1e-10``) with every product recorded;
the products of the finest lattice at its iterations 5, 10 and 20 are then repeated, each ``--repeat`` times by
each path in turn: the whole array (the window's four blocks, every row of the padded pair transformed at once), by
bands (the same spectra, ``bem.column_bands.convolve_by_bands``) and paired (by bands, with the two blocks and the
phase of ``bem.column_bands.paired_spectra`` on the window widened to the same rows of both parities, where the
operator takes them). Reported: the median time of one product, the traced bytes of the spectra and the peak of
one product's arrays (its output included) per node (``tracemalloc``), and the largest difference of the outputs
from the whole array's relative to their maximum.

Run: ``python benchmarks/column_bands.py [--sizes 512 1024 2048] [--repeat 15]``
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
import tracemalloc

import numpy as np

import bem.column_bands
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


def measure(op, v, path, repeat):
    """Median seconds of ``C v`` by ``path`` ("whole", "bands" or "paired"), the traced bytes of the spectra it uses
    and the peak of one product, and its output (0 at the masked nodes)."""
    import bem.operator as operator

    full = op._full()
    operator.BANDS_ABOVE = 16 << 20 if path == "paired" else (0 if path == "bands" else math.inf)
    op._spectra.clear()
    tracemalloc.start()
    if path == "paired":
        box, (shape, spectra) = op._window(op._box(v))
        if not isinstance(spectra, bem.column_bands.PairedSymbol):
            tracemalloc.stop()
            return None
    else:
        box = op._box(v)
        shape, spectra = op._kernel_spectra(full, box)
    made = tracemalloc.get_traced_memory()[0]
    out = np.empty(op.lattice.shape)

    def product():
        op._convolve(spectra, shape, v, box, full, out)

    tracemalloc.reset_peak()
    product()
    peak = tracemalloc.get_traced_memory()[1] - made
    tracemalloc.stop()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        product()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), made, peak + out.nbytes, out.copy()


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[512, 1024, 2048])
    parser.add_argument("--repeat", type=int, default=15)
    args = parser.parse_args(argv)
    print(f"# {cases.machine()['cpu']}, {cases.machine()['cores']} cores, load {cases.loadavg()}")
    print("| N | nodes | iteration | window rows x columns | whole array / by bands / paired [ms] | spectra [B/node] | "
          "peak of a product [B/node] | difference |")
    print("|---|---|---|---|---|---|---|---|")
    for n in args.sizes:
        op, vectors = record(n)
        nodes = op.lattice.n_nodes
        for k, v in zip((5, 10, 20), vectors):
            box = op._box(v)
            rows, cols = sum(r[1] for r in box[0]), box[1][1]
            runs = [r for r in (measure(op, v, path, args.repeat) for path in ("whole", "bands", "paired")) if r]
            diff = max(float(np.abs(r[3] - runs[0][3]).max() / np.abs(runs[0][3]).max()) for r in runs[1:])
            print(f"| {n}^2 | {nodes:,} | {k} | {rows} x {cols} | "
                  + " / ".join(f"{1e3 * r[0]:.2f}" for r in runs) + " | "
                  + " / ".join(f"{r[1] / nodes:.1f}" for r in runs) + " | "
                  + " / ".join(f"{r[2] / nodes:.1f}" for r in runs) + f" | {diff:.1e} |", flush=True)


if __name__ == "__main__":
    main()
