"""Benchmark: the 1M-node solves on 1, 2, 4, 8, 16 FFT threads (a script, not a test).

The benchmark sphere of ``benchmarks/side_by_side.py``: sphere ``R = 1`` on a flat,
``E* = 1``, square candidate region of side 1, Hertz radius 0.1, the node density of a
1024 x 1024 grid (1,048,703 lattice nodes), KKT residual 1e-10; ``hertz`` (no layer) and
``root`` (``w = 0.04 sqrt(p)``, Newton). Each thread count runs in its own subprocess with
``CONTACTLAB_THREADS`` set (:func:`bem.fft.threads`); inside it one untimed warm-up, then the
median of ``--repeat`` solves. Thread counts above the CPUs of this process's affinity mask
are listed as not measured. The 1-minute load average is printed per row: on a shared
machine compare ratios, not absolute times.

Run: ``python benchmarks/threads.py [--threads 1 2 4 8 16] [--n 1024] [--repeat 3]``
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

CHILD = r"""
import json, math, statistics, sys, time
import bem
from bem.gaps import Paraboloid

n, repeat = int(sys.argv[1]), int(sys.argv[2])
step = math.sqrt(2 / math.sqrt(3)) / n  # sqrt(3)/2 c^2 = (1/n)^2


def one(case):
    layer = bem.layers.Root(0.04) if case == "root" else None
    t0 = time.perf_counter()
    res = bem.solve(Paraboloid(1.0), E_star=1.0, force=4 * 0.1**3 / 3, step=step, extent=0.5, rtol=1e-10,
                    layer=layer)
    return time.perf_counter() - t0, res


out = {"threads": bem.fft.threads()}
for case in ("hertz", "root"):
    one(case)  # warm-up: FFT plans, page faults
    times = []
    for _ in range(repeat):
        t, res = one(case)
        times.append(t)
    out[case] = {"time_s": statistics.median(times), "iterations": res.iterations, "kkt": res.kkt_residual,
                 "nodes": res.p.size, "converged": res.converged}
print(json.dumps(out))
"""


def _cpus():
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2, 4, 8, 16])
    parser.add_argument("--n", type=int, default=1024, help="grid density n x n over the unit square")
    parser.add_argument("--repeat", type=int, default=3, help="timed solves per case (median reported)")
    args = parser.parse_args(argv)
    cpus = _cpus()
    print(f"CPUs in the affinity mask: {cpus}")
    print("| threads | nodes | Hertz [s] | Hertz iterations | root layer [s] | root layer Newton steps | load |")
    print("|---|---|---|---|---|---|---|")
    for k in args.threads:
        if k > cpus:
            print(f"| {k} | not measured: {cpus} CPUs in the affinity mask | | | | | |", flush=True)
            continue
        env = dict(os.environ, CONTACTLAB_THREADS=str(k), OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
        env["PYTHONPATH"] = os.pathsep.join([os.path.dirname(HERE), env.get("PYTHONPATH", "")])
        out = subprocess.run([sys.executable, "-c", CHILD, str(args.n), str(args.repeat)], env=env,
                             capture_output=True, text=True, check=True)
        row = json.loads(out.stdout.strip().splitlines()[-1])
        h, r = row["hertz"], row["root"]
        print(f"| {row['threads']} | {h['nodes']:,} | {h['time_s']:.2f} | {h['iterations']} | {r['time_s']:.2f} | "
              f"{r['iterations']} | {os.getloadavg()[0]:.1f} |", flush=True)


if __name__ == "__main__":
    main()
