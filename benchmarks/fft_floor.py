"""Benchmark: the FFT floor and our cost per iteration against it (a script, not a test).

The floor at size ``N`` is one zero-padded real FFT pair of an ``N x N`` grid,
``irfft2(rfft2(x, s=(2N, 2N)))``, with the best back end on the machine. Measured
side by side, interleaved, median of ``--repeat``:

* ``scipy.fft`` (pocketfft) with ``workers = bem.fft.threads()``;
* pyFFTW, if installed, with ``FFTW_ESTIMATE`` plans and with ``FFTW_MEASURE``
  plans (planning time reported separately; plans and aligned buffers cached).

Then, on the problem of ``benchmarks/side_by_side.py`` (Hertz, KKT 1e-10), our
cost per conjugate-gradient iteration on the finest lattice (median interval
between ``callback`` calls) and the cost of one ``C p`` and one preconditioner
application on the converged contact, each divided by the floor. With
``--threads 1 2`` the solve is repeated at each thread count
(:func:`bem.fft.set_threads`), interleaved: the core-scaling figure.

Run: ``python benchmarks/fft_floor.py [--sizes 256 512 1024] [--repeat 5] [--threads 1 2]``
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np
import scipy.fft as sfft

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]

import bem  # noqa: E402
from bem import fft as bfft  # noqa: E402
from bem.gaps import Paraboloid  # noqa: E402
from bem.operator import InfluenceOperator  # noqa: E402
from side_by_side import E_STAR, FORCE, RADIUS, SIDE  # noqa: E402


def _median(fn, repeat):
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def floor_candidates(n):
    """Callables doing one padded real FFT pair of an n x n grid, by back end; planning times."""
    x = np.random.default_rng(0).random((n, n))
    s = (2 * n, 2 * n)
    cands, planning = {}, {}

    def scipy_pair():
        sfft.irfft2(sfft.rfft2(x, s=s, workers=bfft.threads()), s=s, workers=bfft.threads(), overwrite_x=True)

    cands["scipy"] = scipy_pair
    try:
        import pyfftw
    except ImportError:
        return cands, planning
    for flag in ("FFTW_ESTIMATE", "FFTW_MEASURE"):
        a = pyfftw.empty_aligned(s)
        b = pyfftw.empty_aligned((s[0], s[1] // 2 + 1), dtype=complex)
        t0 = time.perf_counter()
        fw = pyfftw.FFTW(a, b, axes=(0, 1), threads=bfft.threads(), flags=(flag,))
        bw = pyfftw.FFTW(b, a, axes=(0, 1), direction="FFTW_BACKWARD", threads=bfft.threads(),
                         flags=(flag, "FFTW_DESTROY_INPUT"))
        planning[flag] = time.perf_counter() - t0

        def pair(a=a, fw=fw, bw=bw):
            a[:] = 0.0
            a[:n, :n] = x
            fw()
            bw()

        cands["pyfftw " + flag[5:].lower()] = pair
    return cands, planning


def solve_kw(n):
    step = np.sqrt(2 / np.sqrt(3)) * SIDE / n
    return dict(E_star=E_STAR, force=FORCE, step=step, extent=SIDE / 2, rtol=1e-10)


def per_iteration(n):
    """Median time between iterations on the finest lattice, and the solution."""
    stamps = []
    res = bem.solve(Paraboloid(RADIUS), **solve_kw(n), callback=lambda k, p: stamps.append(time.perf_counter()))
    return statistics.median(np.diff(stamps)), res


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[256, 512, 1024])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--threads", type=int, nargs="*", default=[], help="core scaling: thread counts to compare")
    args = parser.parse_args(argv)
    print(f"# threads {bfft.threads()} (affinity), load at start {os.getloadavg()[0]:.2f}, median of {args.repeat}")
    print("| N | padded | back end | pair [ms] | planning [s] | load |")
    print("|---|---|---|---|---|---|")
    floors = {}
    for n in args.sizes:
        cands, planning = floor_candidates(n)
        times = {k: [] for k in cands}
        for _ in range(args.repeat):  # interleaved
            for k, fn in cands.items():
                times[k].append(_median(fn, 1))
        for k in cands:
            t = statistics.median(times[k])
            plan = planning.get("FFTW_" + k.split()[-1].upper(), 0.0) if k != "scipy" else 0.0
            print(f"| {n} | {2 * n}^2 | {k} | {1e3 * t:.1f} | {plan:.2f} | {os.getloadavg()[0]:.1f} |", flush=True)
        floors[n] = min(statistics.median(v) for v in times.values())
    print("\n| N | floor [ms] | per iteration [ms] | / floor | C p [ms] | / floor | M r [ms] | / floor | load |")
    print("|---|---|---|---|---|---|---|---|---|")
    for n in args.sizes:
        bem.solve(Paraboloid(RADIUS), **solve_kw(n))  # warm-up
        its = [per_iteration(n) for _ in range(args.repeat)]
        it_time, res = statistics.median(t for t, _ in its), its[-1][1]
        op = InfluenceOperator(res.lattice, E_STAR)
        p = res.grid()
        M = op.preconditioner()
        t_mv = _median(lambda: op.matvec(p), args.repeat)
        t_m = _median(lambda: M(p), args.repeat)
        f = floors[n]
        print(f"| {n} | {1e3 * f:.1f} | {1e3 * it_time:.1f} | {it_time / f:.2f} | {1e3 * t_mv:.1f} | {t_mv / f:.2f} | "
              f"{1e3 * t_m:.1f} | {t_m / f:.2f} | {os.getloadavg()[0]:.1f} |", flush=True)
    if args.threads:
        print("\n| N | threads | Hertz solve [s] | load |")
        print("|---|---|---|---|")
        for n in args.sizes:
            times = {k: [] for k in args.threads}
            for _ in range(args.repeat):
                for k in args.threads:
                    previous = bfft.set_threads(k)
                    t0 = time.perf_counter()
                    bem.solve(Paraboloid(RADIUS), **solve_kw(n))
                    times[k].append(time.perf_counter() - t0)
                    bfft.set_threads(previous)
            for k in args.threads:
                print(f"| {n} | {k} | {statistics.median(times[k]):.2f} | {os.getloadavg()[0]:.1f} |", flush=True)


if __name__ == "__main__":
    main()
