"""Benchmark: periodic rough contact (bem.solve_periodic) against an independent periodic Polonsky-Keer.

The surface: a seeded self-affine random surface, Hurst exponent 0.8, isotropic power spectrum
``C(q) ~ q^(-2(1 + H))`` between the roll-off ``q_r = 2 pi 4 / Lx`` (flat below) and the short
cut-off ``q_s = 2 pi 128 / Lx`` (zero above), Gaussian random phases and amplitudes (a seeded
Fourier filter, written here), scaled to an rms slope of 0.1. It is one Fourier series,
evaluated at the nodes of each solver, so both solve the same surface. ``E* = 1``; the gap is
``max(z) - z``.

Cases (``--cases``):

- ``main``: ``N x N`` nodes (default 1024, the cell ``Lx = 1`` by ``Ly = sqrt3/2`` for the
  triangular lattice; a square-indexed ``N x N`` grid on the same rectangle for PK), mean pressure
  ``0.01 E*``, KKT residual ``1e-10``: ours smooth and with a root layer
  ``w = lam sqrt(p)`` (``lam = C_nn sqrt(0.05 E*)``), and the plain periodic PK (point-sampled
  kernel ``2 / (E* |q|)``, CG on the contact set, written here) on the same surface.
- ``ladder``: 20 mean pressures (geometric) from first touch to 50 % contact at ``--ladder-size``
  (default 512), each solve warm-started from the previous pressure (``x0``); total time.
- ``fractions``: iterations and time from 0.1 % to 100 % contact, ours and PK, at
  ``--fraction-size`` (default 512).
- ``rss``: the peak resident set (``ru_maxrss``) of a fresh process that solves ``main``.
- ``products``: the cost of one product ``C p``, one preconditioner application ``M r`` and a
  bare ``rfft2``/``irfft2`` pair of the same number of points, at ``N x N`` (medians of 30).
- ``floor``: the time of one iteration on the finest ``N x N`` cell (the median interval between
  ``callback`` calls of a warm smooth solve) over a bare ``rfft2``/``irfft2`` pair of the cell in
  single and in double precision (medians of 30), with the iterations and the products ``C p``.

Every timed solve includes the build of the periodic kernel unless the row says "warm". Each row
gives the wall time and the CPU time of the process (``time.process_time``, all its threads),
and the 1-minute load average: on a shared machine the wall time grows with the load, the CPU
time much less; compare ratios within a run, not absolute times across runs.

Run: ``python benchmarks/periodic_rough.py [--cases main ladder fractions rss products floor] [--size 1024]``
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time

import numpy as np
import scipy.fft as sfft

import bem
from bem.periodic import PeriodicCell, solve_periodic

HURST, ROLLOFF, CUTOFF, RMS_SLOPE, SEED = 0.8, 4, 128, 0.1, 2026


def _spectrum(lx, ly):
    """Seeded complex amplitudes Z(m, n) of the surface, ``z(x) = Re sum Z exp(i G.x)``."""
    rng = np.random.default_rng(SEED)
    k = CUTOFF + 1
    mm, nn = np.meshgrid(np.arange(-k, k + 1), np.arange(-k, k + 1))
    gx, gy = 2 * math.pi * mm / lx, 2 * math.pi * nn / ly
    g = np.hypot(gx, gy)
    q_r, q_s = 2 * math.pi * ROLLOFF / lx, 2 * math.pi * CUTOFF / lx
    psd = np.where(g < q_r, q_r, np.where(g > 0, g, 1.0)) ** (-2 * (1 + HURST))
    psd[(g > q_s) | (g == 0)] = 0.0
    z = np.sqrt(psd) * (rng.standard_normal(g.shape) + 1j * rng.standard_normal(g.shape))
    slope = math.sqrt(0.5 * np.sum(np.abs(z) ** 2 * g * g))  # rms of grad Re(...) over the plane
    return mm, nn, z * (RMS_SLOPE / slope)


def _on_grid(lx, ly, shape, shift=(0.0, 0.0)):
    """The surface on the grid ``x = shift_x + q lx / n1``, ``y = shift_y + k ly / n0`` by one inverse FFT."""
    n0, n1 = shape
    mm, nn, z = _spectrum(lx, ly)
    grid = np.zeros(shape, dtype=complex)
    phase = np.exp(1j * (2 * math.pi * mm / lx * shift[0] + 2 * math.pi * nn / ly * shift[1]))
    np.add.at(grid, (np.mod(nn, n0), np.mod(mm, n1)), z * phase)
    return np.fft.ifft2(grid).real * (n0 * n1)


def surface_on_cell(cell):
    """Gap at the nodes of a :class:`PeriodicCell` (brick array); odd rows are shifted by (c/2, c sqrt3/2)."""
    lx, ly = cell.size
    half = (cell.n_rows // 2, cell.n_cols)
    z = np.empty(cell.shape)
    z[0::2] = _on_grid(lx, ly, half)
    z[1::2] = _on_grid(lx, ly, half, shift=(cell.step / 2, cell.step * math.sqrt(3) / 2))
    return z.max() - z


def plain_pk(h, size, pbar, rtol=1e-10, maxiter=20000, x0=None):
    """Polonsky & Keer's CG, periodic, point-sampled kernel ``2 / (E* |q|)``, ``E* = 1``; returns a dict."""
    n0, n1 = h.shape
    qy = 2 * math.pi * np.fft.fftfreq(n0, size[1] / n0)[:, None]
    qx = 2 * math.pi * np.fft.rfftfreq(n1, size[0] / n1)[None, :]
    q = np.hypot(qx, qy)
    kernel = np.where(q > 0, 2 / np.where(q > 0, q, 1.0), 0.0)
    workers = bem.fft.threads()

    def conv(v):
        return sfft.irfft2(kernel * sfft.rfft2(v, workers=workers), s=h.shape, workers=workers)

    p = np.full(h.shape, pbar) if x0 is None else x0 * (pbar * h.size / x0.sum())
    t = np.zeros(h.shape)
    g_old, restart = 1.0, True
    for it in range(maxiter):
        u = conv(p)
        s = p > 0
        g = u + h
        g -= g[s].mean()
        scale = float(np.abs(u).max()) or float(np.abs(g).max()) or 1.0  # u = 0 for a uniform start
        kkt = max(np.abs(g[s]).max(), -g[~s].min(initial=0.0)) / scale
        if kkt <= rtol:
            break
        g_norm = float(np.sum(g[s] ** 2))
        t = np.where(s, g + (0.0 if restart else g_norm / g_old) * t, 0.0)
        g_old = g_norm
        r = conv(t)
        r -= r[s].mean()
        tau = float(np.sum(g[s] * t[s]) / np.sum(r[s] * t[s]))
        p = np.where(s, np.maximum(p - tau * t, 0.0), p)
        overlap = (p == 0) & (g < 0)
        restart = bool(overlap.any())
        p[overlap] -= tau * g[overlap]
        p *= pbar * p.size / p.sum()
    return {"iterations": it, "kkt": float(kkt), "fraction": float((p > 0).mean()), "p": p}


def _load():
    return os.getloadavg()[0]


def _ours(h, cell, pbar, **kw):
    t, c = time.perf_counter(), time.process_time()
    res = solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=pbar, rtol=1e-10, **kw)
    return res, time.perf_counter() - t, time.process_time() - c


def _pk(n, cell, pbar, **kw):
    lx, ly = cell.size
    h = _on_grid(lx, ly, (n, n))
    h = h.max() - h
    t, c = time.perf_counter(), time.process_time()
    out = plain_pk(h, cell.size, pbar, **kw)
    return out, time.perf_counter() - t, time.process_time() - c


def _root(cell):
    return bem.layers.Root(bem.diagonal_coefficient(cell.step, 1.0) * math.sqrt(0.05))


def case_main(n, pk=True):
    cell = PeriodicCell(1.0 / n, n, n)
    h = surface_on_cell(cell)
    rows = []
    for name, kw in (("ours", {}), ("ours warm", {}), ("ours root layer", {"layer": _root(cell)})):
        res, wall, cpu = _ours(h, cell, 0.01, **kw)
        rows.append(dict(solver=name, n=n, wall_s=round(wall, 2), cpu_s=round(cpu, 2), iterations=res.iterations,
                         n_matvec=res.n_matvec, kkt=res.kkt_residual, fraction=round(res.contact_fraction, 4),
                         converged=res.converged, load=_load()))
        print(json.dumps(rows[-1]), flush=True)
    if pk:
        out, wall, cpu = _pk(n, cell, 0.01)
        rows.append(dict(solver="plain PK", n=n, wall_s=round(wall, 2), cpu_s=round(cpu, 2),
                         iterations=out["iterations"], kkt=out["kkt"], fraction=round(out["fraction"], 4),
                         load=_load()))
        print(json.dumps(rows[-1]), flush=True)
    return rows


def _full_contact_pressure(cell, h):
    """Mean pressure above which the contact is full: minus the lowest full-contact pressure fluctuation."""
    op = bem.PeriodicOperator(cell, 1.0)
    fluct = op.preconditioner()(-(h - h.mean()))  # (C)^-1 exactly on zero-mean vectors
    return float(-fluct.min())


def case_ladder(n):
    cell = PeriodicCell(1.0 / n, n, n)
    h = surface_on_cell(cell)
    first, half = 1e-5, 0.13 * _full_contact_pressure(cell, h)  # 50 % contact at 512^2
    loads = np.geomspace(first, half, 20)
    t, c = time.perf_counter(), time.process_time()
    p, iters, fractions = None, 0, []
    for pbar in loads:
        res = solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=pbar, rtol=1e-10, x0=p)
        p = res.grid()
        iters += res.iterations
        fractions.append(round(res.contact_fraction, 4))
        assert res.converged, res.message
    row = dict(case="ladder", n=n, loads=len(loads), wall_s=round(time.perf_counter() - t, 2),
               cpu_s=round(time.process_time() - c, 2), iterations=iters,
               first=first, last=float(half), fractions=fractions, load=_load())
    print(json.dumps(row), flush=True)


def case_fractions(n):
    cell = PeriodicCell(1.0 / n, n, n)
    h = surface_on_cell(cell)
    full = _full_contact_pressure(cell, h)
    for ratio in (1e-4, 1e-3, 0.01, 0.1, 0.3, 0.6, 0.9, 1.1):
        res, wall, _ = _ours(h, cell, ratio * full)
        out, wall_pk, _ = _pk(n, cell, ratio * full)
        print(json.dumps(dict(case="fractions", n=n, pbar_over_full=ratio, fraction=round(res.contact_fraction, 5),
                              iterations=res.iterations, wall_s=round(wall, 2), pk_iterations=out["iterations"],
                              pk_fraction=round(out["fraction"], 5), pk_wall_s=round(wall_pk, 2),
                              load=_load())), flush=True)


def case_rss(n):
    code = ("import resource, sys; sys.path.insert(0, 'benchmarks'); import periodic_rough as b; "
            f"b.case_main({n}, pk=False); "
            "print('peak RSS MB', resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    print(out.stdout.strip().splitlines()[-1], flush=True)


def _median_times(f, repeat):
    """Median wall and CPU time of ``repeat`` calls of ``f()`` [s]."""
    times = []
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        f()
        times.append((time.perf_counter() - t, time.process_time() - c))
    return np.median(times, axis=0)


def _pair(v):
    """A bare ``rfft2`` + ``irfft2`` pair of ``v`` (in its precision), on the FFT threads of ``bem``."""
    workers = bem.fft.threads()
    return sfft.irfft2(sfft.rfft2(v, workers=workers), s=v.shape, workers=workers)


def case_products(n, repeat=30):
    cell = PeriodicCell(1.0 / n, n, n)
    op = bem.PeriodicOperator(cell, 1.0)
    precondition = op.preconditioner()
    v = np.random.default_rng(SEED).standard_normal(cell.shape)
    for name, f in (("C p", lambda: op.matvec(v)), ("M r", lambda: precondition(v)), ("rfft2 + irfft2", lambda: _pair(v))):
        wall, cpu = _median_times(f, repeat) * 1e3
        print(json.dumps(dict(case="products", n=n, what=name, wall_ms=round(wall, 2), cpu_ms=round(cpu, 2),
                              load=_load())), flush=True)


def case_floor(n, repeat=30):
    """The time of an iteration on the finest cell against one transform pair of the cell (single and double
    precision): the median interval between callbacks of a warm solve, over the median pair."""
    cell = PeriodicCell(1.0 / n, n, n)
    h = surface_on_cell(cell)
    _ours(h, cell, 0.01)  # the kernel and the plans made
    stamps = []
    res, wall, _ = _ours(h, cell, 0.01, callback=lambda k, p: stamps.append(time.perf_counter()))
    per_iteration = float(np.median(np.diff(stamps)))
    v = np.random.default_rng(SEED).standard_normal(cell.shape)
    pairs = {}
    for dtype in (np.float32, np.float64):
        x = v.astype(dtype)  # outside the clock
        pairs[np.dtype(dtype).name] = float(_median_times(lambda: _pair(x), repeat)[0])
    print(json.dumps(dict(case="floor", n=n, iterations=res.iterations, products=res.n_matvec,
                          transforms=res.n_transforms, wall_s=round(wall, 3),
                          iteration_ms=round(per_iteration * 1e3, 2),
                          pair_ms={k: round(v * 1e3, 2) for k, v in pairs.items()},
                          iteration_over_pair={k: round(per_iteration / v, 2) for k, v in pairs.items()},
                          load=_load())), flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="+", default=["main", "ladder", "fractions", "rss", "products", "floor"])
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--ladder-size", type=int, default=512)
    parser.add_argument("--fraction-size", type=int, default=512)
    args = parser.parse_args()
    with open("/proc/loadavg") as f:
        print(f"# {os.cpu_count()} CPUs, bem.fft.threads() = {bem.fft.threads()}, load {f.read().strip()}")
    for case in args.cases:
        {"main": lambda: case_main(args.size), "ladder": lambda: case_ladder(args.ladder_size),
         "fractions": lambda: case_fractions(args.fraction_size), "rss": lambda: case_rss(args.size),
         "products": lambda: case_products(args.size), "floor": lambda: case_floor(args.size)}[case]()


if __name__ == "__main__":
    main()
