"""Benchmark: the peak memory per node of ``bem.solve``, the basis of the node guard (``bem.checks``).

For each problem of :mod:`cases` and size, in a fresh process: the gap is made, the resident set
read (``VmRSS``: interpreter, libraries and the gap), the peak reset (``/proc/self/clear_refs``),
the problem solved, and the peak resident set read (``VmHWM``). Reported per node: the solve's
own peak, ``(VmHWM - VmRSS before) / N``, and the whole process's, ``VmHWM / N``.

The guard's bytes per node of a domain (``bem.checks.BYTES_PER_NODE``) is the largest solve peak
per node measured on that domain at ``--min-nodes`` nodes or more (where the solve's fixed
allocations no longer count) plus the gap itself (8 bytes a node), times ``--margin``, rounded
up to 10 bytes; the constants printed at the end are that rule applied to the run's rows. The
rough sphere does not enter the rule: its gap is a Python callable (:class:`cases.RoughSphere`)
whose own temporaries are counted in its peak, as a user's callable would add its own.

Run: ``python benchmarks/memory.py [--problems periodic periodic-root hertz hertz-wide rough-sphere]
[--sizes 256 1024 2048] [--margin 1.1] [--min-nodes 1e6] [--out results/memory]``
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]

import cases  # noqa: E402

#: the domain of each problem (the guard's key)
DOMAIN = {"periodic": "periodic cell", "periodic-root": "periodic cell", "hertz": "half-space region",
          "hertz-root": "half-space region", "hertz-wide": "half-space region", "rough-sphere": None}
GAP_BYTES = 8


def measure(problem, n):
    """One solve of ``problem`` at size ``n`` in this process: time, iterations and memory (module docstring)."""
    solve, gap = cases.prepare(problem, n)
    gc.collect()
    before = cases.rss()
    reset = cases.reset_peak()
    load = cases.loadavg()
    t, c = time.perf_counter(), time.process_time()
    res = solve()
    gap_s, gap_cpu = getattr(gap, "seconds", 0.0), getattr(gap, "cpu_seconds", 0.0)
    wall, cpu = time.perf_counter() - t - gap_s, time.process_time() - c - gap_cpu
    peak = cases.peak_rss()
    out = dict(cases.summary(res), problem=problem, n=n, wall_s=wall, cpu_s=cpu, gap_s=gap_s,
               rss_before_mb=before / 1e6, peak_mb=peak / 1e6, peak_reset=reset, load_before=load,
               load_after=cases.loadavg())
    nodes = out["nodes"]
    out.update(solve_bytes_per_node=(peak - before) / nodes if reset else math.nan, bytes_per_node=peak / nodes,
               cpu_us_per_node=cpu / nodes * 1e6)
    return out


def fresh(problem, n, timeout=None):
    """:func:`measure` in a fresh process; a dict (``error`` where it failed)."""
    done = subprocess.run([sys.executable, os.path.join(HERE, "memory.py"), "--one", problem, str(n)],
                          capture_output=True, text=True, timeout=timeout)
    if done.returncode:
        return dict(problem=problem, n=n, error=(done.stderr.strip().splitlines() or ["failed"])[-1][:300])
    return json.loads(done.stdout.strip().splitlines()[-1])


def bytes_per_node(rows, margin, min_nodes):
    """The guard's bytes per node of each domain from ``rows`` (module docstring)."""
    out = {}
    for domain in dict.fromkeys(d for d in DOMAIN.values() if d):
        peaks = [r["solve_bytes_per_node"] for r in rows
                 if DOMAIN[r["problem"]] == domain and "error" not in r and r["nodes"] >= min_nodes]
        if peaks:
            out[domain] = dict(measured=max(peaks), guard=int(10 * math.ceil(margin * (max(peaks) + GAP_BYTES) / 10)))
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--problems", nargs="+", default=list(cases.PROBLEMS), choices=cases.PROBLEMS)
    parser.add_argument("--sizes", nargs="+", type=int, default=[256, 1024, 2048])
    parser.add_argument("--margin", type=float, default=1.1)
    parser.add_argument("--min-nodes", type=float, default=1e6, help="smallest problem the rule reads")
    parser.add_argument("--out", help="folder for memory.json")
    parser.add_argument("--one", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.one:
        print(json.dumps(measure(args.one[0], int(args.one[1]))))
        return
    print(f"# {cases.machine()}, load {cases.loadavg()}")
    print("| problem | N | nodes | iterations | wall [s] | RSS before [MB] | peak [MB] | solve peak [B/node] | "
          "process peak [B/node] | load before / after |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    for problem in args.problems:
        for n in args.sizes:
            r = fresh(problem, n)
            rows.append(r)
            if "error" in r:
                print(f"| {problem} | {n}^2 | failed: {r['error']} |", flush=True)
                continue
            print(f"| {problem} | {n}^2 | {r['nodes']:,} | {r['iterations']} | {r['wall_s']:.2f} | "
                  f"{r['rss_before_mb']:.0f} | {r['peak_mb']:.0f} | {r['solve_bytes_per_node']:.0f} | "
                  f"{r['bytes_per_node']:.0f} | {r['load_before'][0]:.1f} / {r['load_after'][0]:.1f} |", flush=True)
    derived = bytes_per_node(rows, args.margin, args.min_nodes)
    print(f"# bytes per node for the guard (largest solve peak + {GAP_BYTES} B of gap, x {args.margin}): "
          + json.dumps(derived))
    if args.out:
        os.makedirs(args.out, exist_ok=True)
        with open(os.path.join(args.out, "memory.json"), "w") as f:
            json.dump(dict(machine=cases.machine(), rows=rows, derived=derived), f, indent=1)


if __name__ == "__main__":
    main()
