"""Benchmark: whether the threads of a transform run on separate cores (a script, not a test).

The forward transform of a periodic cell in single precision (the layout of
``bem.periodic.PeriodicOperator.spectrum``: a real FFT along the rows of the two row parities, then
a complex one along the columns, in place), made two ways, alternating, in each of ``--processes``
fresh processes:

* ``workers``: ``scipy.fft`` with ``workers = bem.fft.threads()``: pocketfft's own pool, the calling
  thread waiting;
* ``in_parts``: ``bem.fft.rfft_into`` and ``bem.fft.cfft_in_place``: one single-threaded pocketfft
  call per part on the threads of ``bem.fft.in_parts``, the calling thread taking a part.

Between two transforms the process runs ``--gap`` milliseconds of single-threaded NumPy work over the
cell (as a solver's iteration does between its transforms). Per process and way: the median wall
time of a transform and the median CPU time of the process over it (``time.process_time``, all
threads); their ratio is the number of cores the transform kept busy (1 on one core, up to the
thread count).

Run: ``python benchmarks/shared_core.py --out DIR [--size 1024] [--processes 8] [--repeat 60] [--gap 2]``
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


def one_process(size, repeat, gap_ms):
    """``{way: (wall ms, cpu ms)}`` medians of the two ways in this process, alternating."""
    import numpy as np
    import scipy.fft as sfft

    from bem import fft

    x = np.random.default_rng(0).standard_normal((size // 2, 2, size)).astype(np.float32)
    out = np.empty((size // 2, 2, size // 2 + 1), dtype=np.complex64)
    busy = np.random.default_rng(1).standard_normal(size * size)

    def workers():
        sfft.fft(sfft.rfft(x, axis=2, workers=fft.threads()), axis=0, overwrite_x=True, workers=fft.threads())

    def in_parts():
        fft.cfft_in_place(fft.rfft_into(x, out, 2), 0, 2)

    def between():  # single-threaded work over the cell for about gap_ms
        end = time.perf_counter() + gap_ms / 1e3
        while time.perf_counter() < end:
            np.negative(busy, out=busy)

    times = {"workers": [], "in_parts": []}
    for k in range(2 * repeat):
        name, way = (("workers", workers), ("in_parts", in_parts))[k % 2]
        between()
        wall, cpu = time.perf_counter(), time.process_time()
        way()
        times[name].append(((time.perf_counter() - wall) * 1e3, (time.process_time() - cpu) * 1e3))
    return {name: (statistics.median(t[0] for t in v), statistics.median(t[1] for t in v)) for name, v in times.items()}


def run(size, processes, repeat, gap_ms):
    """Rows ``{process, way, wall_ms, cpu_ms, cores}`` from fresh processes."""
    from bem import fft

    rows = []
    for i in range(processes):
        code = ("import json, sys; sys.path[:0] = [%r, %r]; import shared_core; "
                "print(json.dumps(shared_core.one_process(%d, %d, %r)))" % (HERE, ROOT, size, repeat, gap_ms))
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
        for way, (wall, cpu) in json.loads(done.stdout.strip().splitlines()[-1]).items():
            rows.append({"process": i, "way": way, "wall_ms": wall, "cpu_ms": cpu, "cores": cpu / wall})
    return {"size": size, "threads": fft.threads(), "repeat": repeat, "gap_ms": gap_ms,
            "load": list(os.getloadavg()), "rows": rows}


def table(result):
    lines = ["| process | way | wall [ms] | CPU [ms] | cores busy |", "|---|---|---|---|---|"]
    for r in result["rows"]:
        lines.append(f"| {r['process']} | {r['way']} | {r['wall_ms']:.2f} | {r['cpu_ms']:.2f} | {r['cores']:.2f} |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                     epilog="example: python benchmarks/shared_core.py --out /tmp/shared_core")
    parser.add_argument("--out", required=True, help="folder for shared_core.json and shared_core.md")
    parser.add_argument("--size", type=int, default=1024, help="side of the cell (even)")
    parser.add_argument("--processes", type=int, default=8)
    parser.add_argument("--repeat", type=int, default=60, help="transforms per way and process")
    parser.add_argument("--gap", type=float, default=2.0, help="milliseconds of NumPy work between transforms")
    args = parser.parse_args(argv)
    from cases import write_whole

    result = run(args.size, args.processes, args.repeat, args.gap)
    os.makedirs(args.out, exist_ok=True)
    write_whole(os.path.join(args.out, "shared_core.json"), json.dumps(result, indent=1))
    write_whole(os.path.join(args.out, "shared_core.md"), table(result))
    print(table(result))


if __name__ == "__main__":
    main()
