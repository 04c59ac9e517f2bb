"""Benchmark: how time and memory grow with the nodes, 1M to 67M (``bem.solve``, fresh process per case).

Problems (:mod:`cases`): the self-affine periodic cell of :mod:`periodic_rough` at mean pressure
``0.01 E*``, smooth (``periodic``) and with its root layer (``periodic-root``), on ``N x N``
cells, default ``N`` = 1024, 2048, 4096, 8192 (1M to 67M nodes); the Hertz sphere of
:mod:`side_by_side` (``hertz``) on half-space regions of the node density of ``N x N`` grids,
default ``N`` = 1024 to 8192; the rough sphere of :mod:`cases` (``rough-sphere``, a callable
gap whose evaluation time is not counted) on the same regions. KKT residual 1e-10.

Each case runs in a fresh process (:func:`memory.measure`): the wall time and the CPU time of
the solve (all threads; per node in microseconds, ``process_time / N``), the iterations, and the
peak resident set of the process (``VmHWM``, interpreter and gap included; per node in bytes)
and of the solve alone, with the 1-minute load before and after.

Resumable: the rows are kept in ``scaling.json`` under ``--out``; a case already there is not
run again unless ``--force``. ``scaling.md`` (the table; cases not yet measured say so) and
``scaling.png`` (time and memory against ``N`` on log axes, with ``N log N`` beside) are
rewritten after every case.

Run: ``python benchmarks/scaling.py --out results/scaling [--problems periodic periodic-root hertz rough-sphere]
[--sizes 1024 2048] [--force]``. The C library's allocator settings in the environment (``MALLOC_*``, such as
``MALLOC_MMAP_THRESHOLD_=4194304``, and ``GLIBC_TUNABLES``) reach the cases' processes and are recorded with
their rows (``docs/performance.md``, "Memory per node and the node guard").
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]

import cases  # noqa: E402
from memory import fresh  # noqa: E402

SIZES = {"periodic": [1024, 2048, 4096, 8192], "periodic-root": [1024, 2048, 4096, 8192],
         "hertz": [1024, 2048, 4096, 8192], "rough-sphere": [1024, 2048, 4096, 8192]}
LABELS = {"periodic": "periodic cell, smooth", "periodic-root": "periodic cell, root layer",
          "hertz": "Hertz, half-space region", "rough-sphere": "rough sphere, half-space region"}


def _load(path):
    if os.path.exists(path):
        with open(path) as f:
            return json.load(f)
    return dict(machine=cases.machine(), rows=[])


def markdown(data):
    m = data["machine"]
    lines = [f"Machine: {m['cpu']}, {m['cores']} cores ({m['affinity']} in the affinity mask), {m['memory_gb']} GB, "
             f"Python {m['python']}, numpy {m['numpy']}.", "",
             "| problem | N | nodes | iterations | wall [s] | CPU [s] | CPU per node [us] | peak RSS [GB] | "
             "peak per node [B] | solve's peak per node [B] | 1-min load before / after |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    done = {(r["problem"], r["n"]): r for r in data["rows"]}
    for problem, sizes in SIZES.items():
        for n in sorted(set(sizes) | {k[1] for k in done if k[0] == problem}):
            r = done.get((problem, n))
            if r is None:
                lines.append(f"| {LABELS[problem]} | {n}^2 | about {n * n / 1e6:.3g}M | not yet measured "
                             "| | | | | | | |")
            elif "error" in r:
                lines.append(f"| {LABELS[problem]} | {n}^2 | - | failed: {r['error']} | | | | | | | |")
            else:
                mark = " (a)" if r.get("allocator") else ""
                lines.append(f"| {LABELS[problem]} | {n}^2{mark} | {r['nodes']:,} | {r['iterations']} | "
                             f"{r['wall_s']:.2f} | {r['cpu_s']:.2f} | {r['cpu_us_per_node']:.2f} | "
                             f"{r['peak_mb'] / 1e3:.2f} | {r['bytes_per_node']:.0f} | "
                             f"{r['solve_bytes_per_node']:.0f} | "
                             f"{r['load_before'][0]:.1f} / {r['load_after'][0]:.1f} |")
    settings = sorted({f"{k}={v}" for r in data["rows"] for k, v in r.get("allocator", {}).items()})
    if settings:
        lines += ["", f"(a): run with the C library's allocator set by the environment: {', '.join(settings)} "
                  "(the other rows with its defaults)."]
    return "\n".join(lines) + "\n"


def allocator_settings():
    """The environment variables that set glibc's allocator (``MALLOC_*``, ``GLIBC_TUNABLES``), which the fresh
    processes of the cases inherit: a row's memory and time depend on them."""
    return {k: v for k, v in sorted(os.environ.items()) if k.startswith("MALLOC_") or k == "GLIBC_TUNABLES"}


def plot(data, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    rows = [r for r in data["rows"] if "error" not in r]
    if not rows:
        return
    fig, (ax_t, ax_m) = plt.subplots(1, 2, figsize=(11, 6))
    for k, problem in enumerate(SIZES):
        rs = sorted((r for r in rows if r["problem"] == problem), key=lambda r: r["nodes"])
        if not rs:
            continue
        n = np.array([r["nodes"] for r in rs], float)
        color = f"C{k}"
        ax_t.plot(n, [r["wall_s"] for r in rs], "o-", color=color, label=f"{LABELS[problem]}: wall")
        ax_t.plot(n, [r["cpu_s"] for r in rs], "s--", color=color, mfc="none", label=f"{LABELS[problem]}: CPU")
        ax_m.plot(n, [r["peak_mb"] / 1e3 for r in rs], "o-", color=color, label=LABELS[problem])
    last = max(rows, key=lambda r: r["nodes"])  # the references pass through the largest case
    n_last = float(last["nodes"])
    grid = np.geomspace(min(r["nodes"] for r in rows), n_last, 50)
    for ax, y in ((ax_t, last["wall_s"]), (ax_m, last["peak_mb"] / 1e3)):
        ax.plot(grid, y * grid * np.log(grid) / (n_last * math.log(n_last)), ":", color="0.3",
                label="N log N (through the largest case)")
        ax.plot(grid, y * grid / n_last, "-.", color="0.6", label="N")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("nodes N")
        ax.grid(True, which="both", alpha=0.3)
    ax_t.set_ylabel("time of the solve [s]")
    ax_m.set_ylabel("peak resident set of the process [GB]")
    for ax in (ax_t, ax_m):  # below the axes: the lines cross the whole panel
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
    fig.suptitle("bem.solve, KKT 1e-10, one fresh process per case", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="results folder (scaling.json is read and extended)")
    parser.add_argument("--problems", nargs="+", default=list(SIZES), choices=list(SIZES))
    parser.add_argument("--sizes", nargs="+", type=int, help="grid sides to run (default: each problem's own)")
    parser.add_argument("--force", action="store_true", help="run cases already in scaling.json again")
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, "scaling.json")
    data = _load(path)
    for problem in args.problems:
        for n in args.sizes or SIZES[problem]:
            old = [r for r in data["rows"] if r["problem"] == problem and r["n"] == n]
            if old and "error" not in old[0] and not args.force:
                print(f"# {problem} {n}^2: in {path}, not run again (--force runs it)", flush=True)
                continue
            row = fresh(problem, n)
            if settings := allocator_settings():
                row["allocator"] = settings
            print(json.dumps(row), flush=True)
            data["rows"] = [r for r in data["rows"] if not (r["problem"] == problem and r["n"] == n)] + [row]
            cases.write_whole(path, json.dumps(data, indent=1))
            cases.write_whole(os.path.join(args.out, "scaling.md"), markdown(data))
            plot(data, os.path.join(args.out, "scaling.png"))
    cases.write_whole(os.path.join(args.out, "scaling.md"), markdown(data))
    plot(data, os.path.join(args.out, "scaling.png"))
    print(markdown(data))


if __name__ == "__main__":
    main()
