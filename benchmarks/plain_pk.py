"""An independent Polonsky-Keer solver, the yardstick of ``benchmarks/side_by_side.py``.

Written from the algorithm of Polonsky & Keer 1999 (doi:10.1016/S0043-1648(99)00113-1),
independently of ``bem``: an ``N x N`` square grid of side ``L``, piecewise-constant
pressure on the cells, the Love (1929) influence coefficients, the convolution by a
zero-padded ``2N x 2N`` real FFT (``scipy.fft``, all cores of the affinity mask),
force control. Conjugate gradients on the contact set with the mean-zero force
projection; nodes with pressure 0 and negative gap re-enter with ``-tau g`` and
restart the conjugacy. With a layer law ``w(p)`` the gradient is
``g = K p + w(p) + h - delta``, the direction is Jacobi-preconditioned with
``1 / (K_00 + w'(p))`` and the step is an exact line search (a few secant steps on
the directional derivative, ``K t`` reused), i.e. a preconditioned nonlinear PK.

Stopping rule: the KKT residual of ``bem.kkt`` computed here from scratch,
``max(max_{p>0} |g|, max_{p=0} (-g)_+) / max |K p + w(p)| <= rtol`` with the exact
``K p`` of the iteration (force balance holds to round-off by rescaling).
"""

from __future__ import annotations

import os

import numpy as np
import scipy.fft as sfft


def _workers():
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def love_spectrum(n, h, e_star):
    """rfft2 of the Love coefficients of ``h x h`` cells at every offset, padded to ``2n``."""
    k = np.r_[0:n, -n:0] * h  # offsets; index n (offset -n h) is unused padding
    x, y = k[:, None], k[None, :]

    def log_sum(a, b, r):  # ln(a + r) without cancellation for a < 0 (b != 0)
        return np.where(a > 0, np.log(np.abs(a) + r), np.log(b * b / (r + np.abs(a))))

    def f(a, b):  # antiderivative of 1/r = 1/sqrt(a^2 + b^2): a ln(b + r) + b ln(a + r); a, b never 0 here
        r = np.hypot(a, b)
        return a * log_sum(b, a, r) + b * log_sum(a, b, r)

    c = h / 2
    kern = (f(x + c, y + c) - f(x + c, y - c) - f(x - c, y + c) + f(x - c, y - c)) / (np.pi * e_star)
    kern[n, :] = 0.0
    kern[:, n] = 0.0
    return sfft.rfft2(kern, workers=_workers()), float(kern[0, 0])


def solve_pk(n, *, side=1.0, radius=1.0, e_star=1.0, force, layer=None, rtol=1e-10, maxiter=5000, gap=None):
    """Contact of a sphere (paraboloid ``r^2 / 2R``), or of the ``n x n`` array ``gap`` at the cell centres,
    on an ``n x n`` grid; returns a dict."""
    h = side / n
    if gap is None:
        x = (np.arange(n) - (n - 1) / 2) * h
        gap = (x[:, None] ** 2 + x[None, :] ** 2) / (2 * radius)
    spec, k00 = love_spectrum(n, h, e_star)
    workers = _workers()

    def conv(v):
        return sfft.irfft2(sfft.rfft2(v, s=(2 * n, 2 * n), workers=workers) * spec, s=(2 * n, 2 * n),
                           workers=workers)[:n, :n]

    # layer = (w, w', w^-1) as vectorised callables
    w = (lambda q: np.zeros_like(q)) if layer is None else layer[0]
    dw = (lambda q: np.zeros_like(q)) if layer is None else layer[1]
    area, target = h * h, force / (h * h)
    p = np.full((n, n), target / n**2)
    t = np.zeros_like(p)
    g_old, restart, kkt = 1.0, True, np.inf
    for it in range(1, maxiter + 1):
        u = conv(p)
        wp = w(p)
        c = p > 0
        g = u + wp + gap
        g -= g[c].mean()
        kkt = max(np.abs(g[c]).max(), max(0.0, -g[~c].min(initial=0.0))) / np.abs(u + wp).max()
        if kkt <= rtol:
            break
        z = np.where(c, g / (k00 + np.where(c, dw(np.where(c, p, 1.0)), 0.0)), 0.0)
        z[c] -= z[c].mean()
        gz = float(np.sum(g[c] * z[c]))
        t = np.where(c, z + (0.0 if restart else gz / g_old) * t, 0.0)
        t[c] -= t[c].mean()
        g_old = gz
        r = conv(t)
        tr = float(np.sum(t[c] * r[c]))
        tau = gz / tr
        if layer is not None:  # exact line search: root of s(tau) = t.(g - tau r + w(p - tau t) - w(p))
            pc, tc, gc, rc, wc = p[c], t[c], g[c], r[c], wp[c]

            def slope(s):  # s(tau) and s'(tau) (decreasing: the functional is convex)
                q = np.maximum(pc - s * tc, 0.0)
                return (float(np.dot(tc, gc - s * rc + w(q) - wc)),
                        -tr - float(np.dot(tc * tc, np.where(q > 0, dw(np.where(q > 0, q, 1.0)), 0.0))))

            lo, hi, s0 = 0.0, np.inf, slope(0.0)[0]
            for _ in range(50):  # Newton, safeguarded by the bracket [lo, hi]
                val, der = slope(tau)
                lo, hi = (tau, hi) if val > 0 else (lo, tau)
                if abs(val) <= 1e-12 * abs(s0) or hi - lo <= 1e-14 * hi:
                    break
                step = tau - val / der if der < 0 else np.inf
                tau = step if lo < step < hi else (0.5 * (lo + hi) if np.isfinite(hi) else 2 * tau)
        p = np.where(c, np.maximum(p - tau * t, 0.0), 0.0)
        enter = ~c & (g < 0)  # PK's -tau_PK g with tau_PK = tau / K_00 (z = g / K_00 here), and for a
        p[enter] = -tau * g[enter] / k00  # layer at most the pressure the layer alone carries at that gap
        if layer is not None:
            p[enter] = np.minimum(p[enter], layer[2](-g[enter]))
        restart = bool(enter.any())
        p *= target / p.sum()
    return {"iterations": it, "kkt": float(kkt), "p": p, "contact_nodes": int((p > 0).sum()), "area": area}
