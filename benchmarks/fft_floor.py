"""Benchmark: the FFT floor and our cost per iteration against it (a script, not a test).

The floor at size ``N`` is one zero-padded real FFT pair of an ``N x N`` grid,
``irfft2(rfft2(x, s=(2N, 2N)))``, with the best back end on the machine. Measured
side by side, interleaved, median of ``--repeat``:

* ``scipy.fft`` (pocketfft) with ``workers = bem.fft.threads()``;
* pyFFTW, if installed, with ``FFTW_ESTIMATE`` plans and with ``FFTW_MEASURE``
  plans (planning time reported separately; plans and aligned buffers cached).

Then, on a half-space problem (KKT 1e-10), our cost per conjugate-gradient iteration on the
finest lattice (median interval between ``callback`` calls) and the cost of the products of an
iteration on the converged contact, each divided by the floor: one ``C p`` (double precision), one
preconditioner application ``M r`` as the QP makes it (single precision, over the box of the
contact) and one quadratic form ``t.C t`` (:meth:`bem.InfluenceOperator.quadratic`, the curvature of
an iteration whose contact changes), on the operator the finest level solves on (its candidate
window, :mod:`bem.windows`). ``--problem hertz``: the sphere of ``benchmarks/side_by_side.py``
(contact 3 % of the region); ``--problem rough-sphere``: the rough sphere of :mod:`cases` (contact
28 %, its gap a callable), the problem of ``peers.py``. With ``--threads 1 2`` the solve is
repeated at each thread count (:func:`bem.fft.set_threads`), interleaved: the core-scaling figure.

``--primitives``: instead, the three transforms of :mod:`bem.fft` (the real FFT along the rows, the complex FFT
along the columns, forward and inverse, and the inverse real FFT) of an ``N x N`` cell in the layout of
:meth:`bem.periodic.PeriodicOperator.spectrum`, in single and double precision, one thread, by pocketfft and by
ducc0 where installed (the measurement behind :func:`bem.fft._library`).

Run: ``python benchmarks/fft_floor.py [--sizes 256 512 1024] [--repeat 5] [--problem hertz|rough-sphere]
[--threads 1 2] [--primitives]``
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


def problem(name, n):
    """``(gap, keywords of bem.solve)`` of ``name`` with the node density of an ``n x n`` grid."""
    if name == "hertz":
        step = np.sqrt(2 / np.sqrt(3)) * SIDE / n
        return Paraboloid(RADIUS), dict(E_star=E_STAR, force=FORCE, step=step, extent=SIDE / 2, rtol=1e-10)
    import cases

    step = np.sqrt(2 / np.sqrt(3)) * cases.SIDE / n
    return cases.RoughSphere(), dict(E_star=1.0, force=cases.hertz_force(cases.A_ROUGH), step=step,
                                     extent=cases.SIDE / 2, rtol=cases.RTOL)


def per_iteration(gap, kw):
    """Median time between iterations on the finest lattice, and the solution."""
    stamps = []
    res = bem.solve(gap, **kw, callback=lambda k, p: stamps.append(time.perf_counter()))
    return statistics.median(np.diff(stamps)), res


def finest_operator(gap, res):
    """``(op, p)``: the operator of the finest level's candidate window (the whole lattice without one) and the
    solution on it (a brick array). The window is made with the solution's approach; the solve made it with the
    coarser level's, so the two may differ by a few rows or columns."""
    from bem.windows import candidate_window

    lat = res.lattice
    h = np.where(lat.mask, gap(lat.x, lat.y), 0.0)
    window = candidate_window(lat, h, res.approach)
    p = res.grid()
    if window is None:
        return InfluenceOperator(lat, res.E_star), p
    return InfluenceOperator(window, res.E_star), np.ascontiguousarray(p[window.index])


def primitives(sizes, repeat):
    """The table of ``--primitives`` (module docstring): medians of ``repeat`` interleaved calls [ms]."""
    libraries = {k: lib for k, lib in (("pocketfft", bfft._pocketfft), ("ducc0", bfft._ducc0)) if lib is not None}
    if not libraries:
        print("# neither SciPy's pocketfft entry points nor ducc0: nothing to compare")
        return
    print(f"| N | precision | transform | {' | '.join(f'{k} [ms]' for k in libraries)} | load |")
    print("|---|---|---|" + "---|" * len(libraries) + "---|")
    for n in sizes:
        for real, cplx in ((np.float32, np.complex64), (np.float64, np.complex128)):
            x = np.random.default_rng(0).random((n // 2, 2, n)).astype(real)
            spectrum, back = np.empty((n // 2, 2, n // 2 + 1), cplx), np.empty_like(x)
            # the column transforms in place scaled by 1 / sqrt(N) (unitary): repeated, the data keep their size
            calls = {"r2c rows": lambda lib: lib.r2c(x, (2,), True, 0, spectrum, 1),
                     "c2c columns": lambda lib: lib.c2c(spectrum, (0,), True, 1, spectrum, 1),
                     "c2c columns, inverse": lambda lib: lib.c2c(spectrum, (0,), False, 1, spectrum, 1),
                     "c2r rows": lambda lib: lib.c2r(spectrum, (2,), n, False, 2, back, 1)}
            for name, call in calls.items():
                times = {k: [] for k in libraries}
                for _ in range(repeat):
                    for k, lib in libraries.items():
                        times[k].append(_median(lambda: call(lib), 1))
                cells = " | ".join(f"{1e3 * statistics.median(times[k]):.2f}" for k in libraries)
                print(f"| {n}^2 | {np.dtype(real).name} | {name} | {cells} | {os.getloadavg()[0]:.1f} |", flush=True)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[256, 512, 1024])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--problem", choices=("hertz", "rough-sphere"), default="hertz")
    parser.add_argument("--threads", type=int, nargs="*", default=[], help="core scaling: thread counts to compare")
    parser.add_argument("--primitives", action="store_true", help="the transforms of bem.fft by library, then stop")
    args = parser.parse_args(argv)
    if args.primitives:
        print(f"# {bfft.back_end()}; one thread, load at start {os.getloadavg()[0]:.2f}, median of {args.repeat}")
        primitives(args.sizes, args.repeat)
        return
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
    print(f"\n{args.problem}: the finest lattice's iteration and products, each also over the floor")
    print("| N | floor [ms] | iterations (finest) | per iteration [ms] | / floor | C p [ms] | / floor "
          "| M r [ms] | / floor | t.C t [ms] | / floor | load |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for n in args.sizes:
        gap, kw = problem(args.problem, n)
        bem.solve(gap, **kw)  # warm-up
        its = [per_iteration(gap, kw) for _ in range(args.repeat)]
        it_time, res = statistics.median(t for t, _ in its), its[-1][1]
        op, p = finest_operator(gap, res)
        M = op.preconditioner(single=True)  # as the QP makes it
        r = np.where(p > 0, np.random.default_rng(0).standard_normal(p.shape), 0.0)  # a gap on the contact
        f = floors[n]
        cells = []
        for fn in (lambda: op.matvec(p), lambda: M(r), lambda: op.quadratic(r)):
            t = _median(fn, args.repeat)
            cells.append(f"{1e3 * t:.1f} | {t / f:.2f}")
        print(f"| {n} | {1e3 * f:.1f} | {res.iterations} | {1e3 * it_time:.1f} | {it_time / f:.2f} | "
              + " | ".join(cells) + f" | {os.getloadavg()[0]:.1f} |", flush=True)
    if args.threads:
        print(f"\n| N | threads | {args.problem} solve [s] | load |")
        print("|---|---|---|---|")
        for n in args.sizes:
            gap, kw = problem(args.problem, n)
            times = {k: [] for k in args.threads}
            for _ in range(args.repeat):
                for k in args.threads:
                    previous = bfft.set_threads(k)
                    t0 = time.perf_counter()
                    bem.solve(gap, **kw)
                    times[k].append(time.perf_counter() - t0)
                    bfft.set_threads(previous)
            for k in args.threads:
                print(f"| {n} | {k} | {statistics.median(times[k]):.2f} | {os.getloadavg()[0]:.1f} |", flush=True)


if __name__ == "__main__":
    main()
