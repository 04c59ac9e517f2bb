"""Benchmark: how :func:`bem.fft.in_parts` hands its parts to the pool (a script, not a test).

Two handovers of the same parts, alternating, in each of ``--processes`` fresh processes:

* ``locks``: ``bem.fft.in_parts``, each pool thread handed its part and collected through two locks;
* ``futures``: a :class:`concurrent.futures.ThreadPoolExecutor` of ``threads() - 1`` threads, ``submit``
  and ``result`` (a queue and a condition variable a part), the calling thread taking the last part.

Per process and handover, the median wall time of three kernels, ``--repeat`` calls each: ``empty``
(a part that does nothing: the handover alone), ``c2c`` (the complex transform along the columns of an
``N x N`` cell's half spectrum in single precision, ``bem.fft.cfft_in_place``'s parts) and ``scale``
(a float32 array of ``N x N`` entries multiplied by 2 in place).

Run: ``python benchmarks/handover.py --out DIR [--size 1024] [--processes 4] [--repeat 300]``
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path[:0] = [HERE, ROOT]


def one_process(size, repeat):
    """``{kernel: {handover: median ms}}`` in this process, the handovers alternating."""
    from concurrent.futures import ThreadPoolExecutor

    import numpy as np

    from bem import fft

    k = fft.threads()
    pool = ThreadPoolExecutor(max_workers=max(1, k - 1))
    spectrum = np.random.default_rng(0).standard_normal((size, size // 2 + 1)).astype(np.complex64)
    values = np.random.default_rng(1).standard_normal(size * size).astype(np.float32)
    scale_rows = values.reshape(size, size)
    lib = fft._library("c2c", np.complex64)

    kernels = {"empty": (lambda part: None, size),
               "c2c": (lambda part: lib.c2c(spectrum[:, part], (0,), True, 0, spectrum[:, part], 1), size // 2 + 1),
               "scale": (lambda part: np.multiply(scale_rows[part], 2.0, out=scale_rows[part]), size)}

    def futures(kernel, n):  # the parts of fft.in_parts, on the executor
        bounds = [n * i // k // fft.LINES * fft.LINES for i in range(k)] + [n]
        others = [pool.submit(kernel, slice(lo, hi)) for lo, hi in zip(bounds[:-2], bounds[1:-1])]
        kernel(slice(bounds[-2], bounds[-1]))
        for f in others:
            f.result()

    ways = {"locks": lambda kernel, n: fft.in_parts(kernel, n, 1 << 20, align=fft.LINES), "futures": futures}
    out = {}
    for name, (kernel, n) in kernels.items():
        times = {way: [] for way in ways}
        for i in range(2 * repeat):
            way = ("locks", "futures")[i % 2]
            t = time.perf_counter()
            ways[way](kernel, n)
            times[way].append(time.perf_counter() - t)
        out[name] = {way: 1e3 * statistics.median(v[5:]) for way, v in times.items()}
    pool.shutdown()
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", required=True, help="results folder (a new one)")
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--processes", type=int, default=4)
    parser.add_argument("--repeat", type=int, default=300)
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(one_process(args.size, args.repeat)))
        return
    from cases import loadavg, machine, write_whole

    if os.path.exists(args.out):
        raise SystemExit(f"--out {args.out!r} exists: give a new folder")
    rows = []
    for _ in range(args.processes):
        child = subprocess.run([sys.executable, __file__, "--child", "--out", args.out, "--size", str(args.size),
                                "--repeat", str(args.repeat)], capture_output=True, text=True, check=True)
        rows.append(json.loads(child.stdout))
    lines = [f"# {args.size}^2, {args.processes} processes, {args.repeat} calls each way; load {loadavg()}",
             "| kernel | locks [ms] per process | futures [ms] per process |", "|---|---|---|"]
    for name in rows[0]:
        lines.append(f"| {name} | " + ", ".join(f"{r[name]['locks']:.3f}" for r in rows) + " | "
                     + ", ".join(f"{r[name]['futures']:.3f}" for r in rows) + " |")
    os.makedirs(args.out)
    write_whole(os.path.join(args.out, "handover.json"),
                json.dumps(dict(machine=machine(), size=args.size, repeat=args.repeat, processes=rows), indent=1))
    write_whole(os.path.join(args.out, "handover.md"), "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
