"""Benchmark: contactlab side by side with ASPHER, tamaas and ContactMechanics, in one run.

Problems (:mod:`cases`; ``E* = 1``; every solver to its own residual 1e-10):

- ``periodic``: the self-affine cell of :mod:`periodic_rough`, ``N x N`` nodes (default 1024),
  mean pressure ``0.01 E*``, smooth;
- ``rough-sphere``: the rough sphere on a square region of side 1, the node density of an
  ``N x N`` grid (default 512);
- ``hertz``: the sphere of :mod:`side_by_side` (contact 4 % of the region), default 1024.

The solvers and how each is called: :mod:`peer_solvers` (ASPHER in its default precision and in
``float_then_double``). A peer that is not installed is skipped with a message; install them
with ``pip install "contactlab[peers]"`` (ASPHER builds from source: a C++17 compiler, CMake and
Eigen, Debian ``libeigen3-dev``).

Every solve runs in a fresh process (imports and the gap array outside the clock); the repeats
are interleaved (round ``k`` runs every solver once, the order rotated by ``k``). Each run
records the wall time, the CPU time of the process (all threads), the peak resident set
(``VmHWM``), the 1-, 5-, 15-minute load averages before and after it, and the solver's own
iterations, status and contact fraction. A run longer than ``--timeout`` is stopped and recorded.
``--threads k`` runs every solver on ``k`` threads (``CONTACTLAB_THREADS``, ``OMP_NUM_THREADS``,
the BLAS's); by default each uses its own default (contactlab and the OpenMP of ASPHER and
tamaas: every core).

Writes ``peers.json`` (machine, every run, the table), ``peers.md`` (the table: best and median
wall time per solver) and ``peers.png`` (best wall time and median CPU time per problem and solver, log scale) under
``--out``.

Run: ``python benchmarks/peers.py --out results/peers [--problems periodic rough-sphere hertz]
[--size periodic=1024 rough-sphere=512 hertz=1024] [--repeat 3] [--solvers ...] [--timeout 1800]``
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]

import cases  # noqa: E402

PROBLEMS = {"periodic": 1024, "rough-sphere": 512, "hertz": 1024}
SOLVER_NAMES = ["contactlab", "aspher", "aspher-mixed", "tamaas", "contactmechanics"]
MODULES = {"contactlab": "bem", "aspher": "aspher", "aspher-mixed": "aspher", "tamaas": "tamaas",
           "contactmechanics": "ContactMechanics"}
LABELS = {"periodic": "periodic self-affine cell", "rough-sphere": "rough sphere", "hertz": "Hertz"}
#: how to install a missing peer, for the skip message
INSTALL = dict.fromkeys(("aspher", "aspher-mixed", "tamaas", "contactmechanics"),
                        'pip install "contactlab[peers]" (ASPHER builds from its source: a C++17 compiler, CMake, '
                        "Eigen; Debian: apt-get install libeigen3-dev)")
#: what ``--threads`` sets for every solve: contactlab's FFT threads, OpenMP (ASPHER, tamaas), BLAS
THREAD_VARIABLES = ("CONTACTLAB_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def one(problem, n, solver):
    """Worker: one solve in this process; a JSON line."""
    from peer_solvers import SOLVERS

    out = SOLVERS[solver](problem, n)
    out["peak_rss_mb"] = cases.peak_rss() / 1e6
    return out


def _run(problem, n, solver, timeout, threads=None):
    env = dict(os.environ)
    if threads:
        env.update({k: str(threads) for k in THREAD_VARIABLES})
    load = cases.loadavg()
    t = time.perf_counter()
    try:
        done = subprocess.run([sys.executable, __file__, "--one", problem, str(n), solver], capture_output=True,
                              text=True, timeout=timeout, env=env)
        if done.returncode == 0:
            row = json.loads(done.stdout.strip().splitlines()[-1])
        else:
            row = dict(error=(done.stderr.strip().splitlines() or ["failed"])[-1][:300])
    except subprocess.TimeoutExpired:
        row = dict(error=f"stopped after {timeout} s", wall_s=float(timeout))
    row.update(problem=problem, n=n, solver=solver, load_before=load, load_after=cases.loadavg(),
               process_s=round(time.perf_counter() - t, 2))
    return row


def summarise(runs):
    """One row per (problem, solver): best and median wall time over the repeats that finished."""
    table = []
    for problem in dict.fromkeys(r["problem"] for r in runs):
        for solver in dict.fromkeys(r["solver"] for r in runs if r["problem"] == problem):
            rs = [r for r in runs if r["problem"] == problem and r["solver"] == solver]
            ok = [r for r in rs if "error" not in r]
            row = dict(problem=problem, n=rs[0]["n"], solver=solver, runs=len(rs), finished=len(ok),
                       loads=[r["load_before"][0] for r in rs] + [rs[-1]["load_after"][0]])
            if ok:
                walls = [r["wall_s"] for r in ok]
                last = ok[-1]
                row.update(best_s=min(walls), median_s=statistics.median(walls), walls=[round(w, 3) for w in walls],
                           cpu_s=statistics.median(r["cpu_s"] for r in ok), nodes=last["nodes"],
                           iterations=last.get("iterations"), finest_iterations=last.get("finest_iterations"),
                           status=last.get("status"), residual=last.get("residual"),
                           contact_fraction=last.get("contact_fraction"),
                           peak_rss_mb=max(r["peak_rss_mb"] for r in ok), note=last.get("note", ""))
            else:
                row.update(error=rs[-1]["error"])
            table.append(row)
    return table


def _fmt(v, spec):
    return "-" if v is None else format(v, spec)


def markdown(table, info, skipped):
    lines = [f"Machine: {info['cpu']}, {info['cores']} cores ({info['affinity']} in the affinity mask), "
             f"{info['memory_gb']} GB, Python {info['python']}, numpy {info['numpy']}; threads: {info['threads']}; "
             f"load average "
             f"(1, 5, 15 min) at start {info['load_start']}, at end {info['load_end']}.", ""]
    lines += [f"- {s}: skipped ({why})" for s, why in skipped.items()]
    lines += ["", "| problem | N | solver | best / median wall [s] | CPU [s] | iterations (finest) | status | "
                  "contact | peak RSS [MB] | 1-min load during runs | note |",
              "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in table:
        if "error" in r:
            lines.append(f"| {LABELS[r['problem']]} | {r['n']}^2 | {r['solver']} | {r['error']} | - | - | - | - | - | "
                         f"{min(r['loads']):.1f}-{max(r['loads']):.1f} | |")
            continue
        its = _fmt(r["iterations"], "d") + (f" ({r['finest_iterations']})" if r.get("finest_iterations") else "")
        lines.append(f"| {LABELS[r['problem']]} | {r['n']}^2 | {r['solver']} | "
                     f"{r['best_s']:.2f} / {r['median_s']:.2f} | "
                     f"{r['cpu_s']:.2f} | {its} | {r['status']} | {_fmt(r['contact_fraction'], '.3f')} | "
                     f"{r['peak_rss_mb']:.0f} | {min(r['loads']):.1f}-{max(r['loads']):.1f} | {r['note']} |")
    return "\n".join(lines) + "\n"


def plot(table, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    problems = list(dict.fromkeys(r["problem"] for r in table))
    solvers = [s for s in SOLVER_NAMES if any(r["solver"] == s for r in table)]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6), sharey=True)
    width = 0.8 / max(len(solvers), 1)
    for ax, key, title in ((axes[0], "best_s", "best wall time"), (axes[1], "cpu_s", "median CPU time (all threads)")):
        for j, s in enumerate(solvers):
            xs, ys = [], []
            for i, p in enumerate(problems):
                r = next((r for r in table if r["problem"] == p and r["solver"] == s and "best_s" in r), None)
                if r:
                    xs.append(i + (j - (len(solvers) - 1) / 2) * width)
                    ys.append(r[key])
            bars = ax.bar(xs, ys, width, label=s, color=f"C{j}")
            ax.bar_label(bars, labels=[f"{y:.2g}" for y in ys], fontsize=6, rotation=90, padding=2)
        ax.set_yscale("log")
        ax.set_xticks(range(len(problems)),
                      [f"{LABELS[p]}\n{next(r['n'] for r in table if r['problem'] == p)}^2" for p in problems],
                      fontsize=8)
        ax.set_title(title, fontsize=10)
        ax.margins(y=0.25)
    axes[0].set_ylabel("seconds (log scale)")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="lower center", ncol=len(solvers), fontsize=8)
    fig.suptitle("Each solver to its own residual 1e-10, one fresh process per solve", fontsize=10)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", help="results folder (required)")
    parser.add_argument("--problems", nargs="+", default=list(PROBLEMS), choices=list(PROBLEMS))
    parser.add_argument("--size", nargs="+", default=[], metavar="PROBLEM=N", help="grid side per problem")
    parser.add_argument("--solvers", nargs="+", default=SOLVER_NAMES, choices=SOLVER_NAMES)
    parser.add_argument("--repeat", type=int, default=3, help="interleaved rounds")
    parser.add_argument("--timeout", type=float, default=1800, help="seconds per solve")
    parser.add_argument("--threads", type=int, help="threads of every solver (default: each its own)")
    parser.add_argument("--one", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.one:
        print(json.dumps(one(args.one[0], int(args.one[1]), args.one[2])))
        return
    if not args.out:
        parser.error("--out is required")
    sizes = dict(PROBLEMS, **{k: int(v) for k, v in (s.split("=") for s in args.size)})
    skipped = {s: f"`{MODULES[s]}` is not installed: {INSTALL.get(s, 'pip install -e .')}"
               for s in args.solvers if importlib.util.find_spec(MODULES[s]) is None}
    for s, why in skipped.items():
        print(f"# {s}: skipped ({why})", flush=True)
    solvers = [s for s in args.solvers if s not in skipped]
    info = dict(cases.machine(), load_start=cases.loadavg(), threads=args.threads or "each solver's default")
    print(f"# {info}", flush=True)
    os.makedirs(args.out, exist_ok=True)
    runs = []
    for k in range(args.repeat):
        for problem in args.problems:
            order = solvers[k % len(solvers):] + solvers[:k % len(solvers)]
            for solver in order:
                runs.append(_run(problem, sizes[problem], solver, args.timeout, args.threads))
                print(json.dumps(runs[-1]), flush=True)
    info["load_end"] = cases.loadavg()
    table = summarise(runs)
    cases.write_whole(os.path.join(args.out, "peers.json"),
                      json.dumps(dict(machine=info, skipped=skipped, runs=runs, table=table), indent=1))
    cases.write_whole(os.path.join(args.out, "peers.md"), markdown(table, info, skipped))
    plot(table, os.path.join(args.out, "peers.png"))
    print(markdown(table, info, skipped))


if __name__ == "__main__":
    main()
