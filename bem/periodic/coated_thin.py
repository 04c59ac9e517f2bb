"""The periodic template of a thin coating in real space: the region's coefficients and their images.

A coated body's part of the periodic template (:mod:`bem.periodic.coated`, lattice units, step
``c = 1``, ``tau = t / c``) is split at the substrate's long-wave compliance ``s0 = s(0)`` instead of
the coating's ``s_inf``::

    W_i(x) = E* s0 W(x) + D(x),   D(x) = (1/A) sum_{G != 0} (2 pi / |G|) E* (s(|G|) - s0) hat(G) exp(i G.x).

By Poisson's summation ``D`` is the sum over the periods ``L`` of the region's coefficient
difference ``d(x) = E* int pyr(xi) k(|x - xi|) dxi``, ``k(r) = int_0^inf (s(q) - s0) J0(q r) dq``,
less a constant (the ``G = 0`` term, removed with the template's mean). ``d`` is the coated
region's template less the substrate's, ``E*`` times ``pi / c`` :func:`bem.coated_kernel.coated_table`
minus ``s0 w_t`` (:func:`bem.template.template`): exact at any ``tau``, local on the scale ``t``, and
beyond :func:`bem.coated_kernel.series_reach` it is its large-``r`` series ::

    k(r) = sum_{m even >= 2} c_m / r^(m+1),   c_m = s_c phi_m tau^m g_m,
    g_m = 2^m Gamma((m+1)/2) / Gamma((1-m)/2)   (g_2 = -1: the tail -s_c phi_2 tau^2 / r^3),

``phi_m`` the Taylor coefficients of the coating factor (:func:`bem.coating.factor_taylor`; the odd
powers of ``q`` give ``delta`` terms, local). So ``D`` at the node offset ``x`` is ``d`` summed over the
images ``x0 + (i Lx, j Ly)``, ``|i| <= I``, ``|j| <= J``, of its minimum image ``x0`` (``|x0| <= (Lx/2,
Ly/2)``), plus the tail summed over the other images, each at least ``R = min((I + 1/2) Lx, (J + 1/2)
Ly) - 1`` away through the pyramid's support (:func:`image_reach`). ``(I, J)`` are the fewest that
put ``R`` beyond the series' reach and 8 steps (so that the split below is smooth on the element's
scale): :func:`reach`, :func:`images_for`; ``(0, 0)`` on a cell longer than twice the reach.

The tail's lattice sum, term by term (``r^(-2 sigma)``, ``sigma = (m+1)/2``), by Ewald's split
``r^(-2 sigma) = Q(sigma, a^2 r^2) r^(-2 sigma) + T(r)``, ``Q`` the regularised upper incomplete
gamma function, ``a = sqrt(z_m) / R`` with ``Q(sigma, z_m) = 1e-17`` (the first part, left out, is
below ``1e-17`` of the term itself at every other image), and the smooth ``T(r) = a^(2 sigma)
P(sigma, a^2 r^2) / (a^2 r^2)^sigma`` whose transform is ``(pi / Gamma(sigma)) a^(2 sigma - 2)
E_sigma(|k|^2 / (4 a^2))`` (``E_sigma`` the exponential integral of order ``sigma``)::

    sum_{L != L0} int pyr(xi) r^(-2 sigma)(x + L - xi) dxi
        = (1/A) sum_G T^(G) hat(G) exp(i G.x) - int pyr(xi) T(|x0 - xi|) dxi.

The Fourier sum stops at ``|G|^2 = 4 a^2 * 42`` (:func:`bem.periodic.kernel.alias_sum`, a few
thousand terms); the element integral of the smooth ``T`` (its scale ``1 / a`` is ``R / 6`` for the
leading term) is a tensor Gauss rule of the pyramid (:func:`bem.coated_kernel.box_rule`) with as
many points a direction as make its error below ``1e-17 s0``, ``T`` itself by Chebyshev panels. The
terms are kept up to the smallest at ``R``, and while above ``1e-20 s0`` there.

Cost: the region's coefficients at about ``(2 I + 1) (2 J + 1) N / 4`` offsets (a quarter of the
kept images' box, by symmetry: :func:`table_size`, at most :data:`MAX_OFFSETS`) and one element
rule an offset; independent of ``tau`` where ``I = J = 0`` (benchmarks/coated_symbol.py).
"""

from __future__ import annotations

import math

import numpy as np

from ..coated_kernel import box_rule, coated_table, series_reach
from ..coating import Bodies, factor_taylor, mode_compliance
from ..template import template
from .kernel import alias_sum

__all__ = ["admits", "image_reach", "images_for", "reach", "refusal", "table_size", "thin_part", "MAX_OFFSETS",
           "MIN_REACH"]

_SQRT3 = math.sqrt(3.0)
#: Steps: the nearest other image at least this far (the split's scale ``1/a >= R/9`` against the element).
MIN_REACH = 8.0
#: The most region coefficients one real-space template tabulates (memory and time bound).
MAX_OFFSETS = 16_000_000
_ORDER = 40  # Taylor coefficients of phi kept for the tail
_Q_FLOOR = 1e-17  # the real-space part of the split, relative to the term, at the nearest other image
_CHEB = 16  # Chebyshev points a panel of the smooth part
_Z_CUT = 42.0  # the Fourier part stops at |k|^2 / (4 a^2) = 42 (e^-42 = 6e-19)


def image_reach(n_rows, n_cols, images):
    """``R = min((I + 1/2) Lx, (J + 1/2) Ly) - 1`` [steps]: the images ``(i Lx, j Ly)`` with ``|i| <= I``,
    ``|j| <= J`` around the nearest kept, every other is this far from any point of the pyramid at a
    node offset."""
    I, J = images
    return min((I + 0.5) * n_cols, (J + 0.5) * n_rows * _SQRT3 / 2) - 1.0


def images_for(n_rows, n_cols, need):
    """The fewest ``(I, J)`` with :func:`image_reach` at least ``need`` [steps]."""
    return tuple(max(0, math.ceil((need + 1.0) / period - 0.5)) for period in (n_cols, n_rows * _SQRT3 / 2))


def table_size(n_rows, n_cols, images):
    """Region coefficients the route tabulates for ``images = (I, J)``: about ``(2 I + 1) (2 J + 1) N / 4``."""
    I, J = images
    return ((2 * J + 1) * n_rows // 2 + 1) * ((2 * I + 1) * n_cols // 2 + 1)


def _one(bodies, i):
    """The bodies with only body ``i``'s coating (the other's, if any, taken off)."""
    c1, c2 = (bodies.coating1, None) if i == 1 else (None, bodies.coating2)
    return Bodies(bodies.E1, bodies.nu1, bodies.E2, bodies.nu2, c1, c2)


def reach(bodies, i, step):
    """The smallest :func:`image_reach` [steps] at which body ``i``'s coating takes the real-space route."""
    return max(MIN_REACH, series_reach(_one(bodies, i), step))


def refusal(n_rows, n_cols, step, bodies, i):
    """The clause of a refusal that names what the route would tabulate for body ``i``."""
    r = reach(bodies, i, step)
    return (f"its real-space route would tabulate {table_size(n_rows, n_cols, images_for(n_rows, n_cols, r)):.2g} "
            f"region coefficients (at most {MAX_OFFSETS:.0e}: the images within {r * step:.3g} of a node)")


def admits(n_rows, n_cols, step, bodies, i):
    """Whether body ``i``'s coating can take the real-space route on this cell: the images within its
    :func:`reach` tabulated at :data:`MAX_OFFSETS` region coefficients at most."""
    return table_size(n_rows, n_cols, images_for(n_rows, n_cols, reach(bodies, i, step))) <= MAX_OFFSETS


def _tail(bodies, which, step, r_min, s_scale):
    """``(c_m, sigma_m)`` of the tail of the bodies ``which``, kept up to the smallest term at ``r_min`` and
    while the terms there are above ``1e-20 s0`` (with ``Q`` and the Fourier part, a term's smooth parts
    are up to ``z_m^sigma / Gamma(sigma + 1)`` times the term: no more of them than needed)."""
    from scipy.special import gamma

    m = np.arange(2, _ORDER + 1, 2)
    g = 2.0 ** m * gamma((m + 1) / 2) / gamma((1 - m) / 2)
    c = np.zeros(m.size)
    for i in which:
        E, nu, coating = ((bodies.E1, bodies.nu1, bodies.coating1) if i == 1
                          else (bodies.E2, bodies.nu2, bodies.coating2))
        phi, _ = factor_taylor(coating, E, nu, order=_ORDER)
        tau = coating.thickness / step
        c += (1.0 - coating.nu ** 2) / coating.E * phi[m] * tau ** m * g
    size = np.abs(c) * r_min ** -(m + 1.0)
    size[c == 0] = np.inf
    keep = min(int(np.argmin(size)) + 1, int(np.count_nonzero(np.cumprod(size >= 1e-20 * s_scale))) + 1)
    return c[:keep], (m[:keep] + 1) / 2.0


def _exp_integral(sigma, z):
    """``E_sigma(z) = int_1^inf e^(-z u) u^(-sigma) du`` for a half-integer ``sigma >= 3/2``: below ``z = 2`` by
    the recurrence ``s E_(s+1) = e^-z - z E_s`` from ``E_(1/2)(z) = sqrt(pi / z) erfc(sqrt z)`` (no growth
    of rounding there), above by its continued fraction (modified Lentz, 60 levels: converged from ``z = 2``)."""
    from scipy.special import erfc

    out = np.empty_like(z)
    low = z < 2.0
    zl = z[low]
    e, order = np.sqrt(math.pi / zl) * erfc(np.sqrt(zl)), 0.5
    while order < sigma:
        e = (np.exp(-zl) - zl * e) / order
        order += 1.0
    out[low] = e
    zh = z[~low]
    b = zh + sigma
    c, d = np.full_like(zh, 1e300), 1.0 / b
    h = d
    for i in range(1, 61):
        an = -i * (sigma - 1.0 + i)
        b = b + 2.0
        d = 1.0 / (an * d + b)
        c = b + an / c
        h = h * c * d
    out[~low] = h * np.exp(-zh)
    return out


def _smooth(sigma, a, r2):
    """``T(r) = a^(2 sigma) P(sigma, a^2 r^2) / (a^2 r^2)^sigma`` at ``r2 = r^2`` (regular at 0)."""
    from scipy.special import gamma, gammainc

    z = a * a * r2
    out = np.empty_like(z)
    small = z < 1e-3
    zs = z[small]
    series = np.zeros_like(zs)
    term = np.ones_like(zs)
    for k in range(8):  # P(s, z) / z^s = sum_k (-z)^k / (k! (s + k) Gamma(s))
        series += term / (sigma + k)
        term = term * -zs / (k + 1)
    out[small] = series / gamma(sigma)
    big = ~small
    out[big] = gammainc(sigma, z[big]) / z[big] ** sigma
    return out * a ** (2 * sigma)


def _rule_size(c, sigmas, alphas, scale):
    """Gauss points a direction of the pyramid's rule: its error ``(n!)^3 / ((2n+1) (2n)!^2) a^(2n)`` of each
    smooth part (at most ``|c_m| a^(2 sigma) / Gamma(sigma + 1)``) below ``1e-17 scale``."""
    from scipy.special import gamma

    size = np.abs(c) * alphas ** (2 * sigmas) / gamma(sigmas + 1)
    for n in range(2, 16):
        bound = math.factorial(n) ** 3 / ((2 * n + 1) * math.factorial(2 * n) ** 2)
        if np.all(size * bound * alphas ** (2 * n) < 1e-17 * scale):
            return n
    return 16


class _Smooth:
    """``sum_m c_m T_m(r)`` on ``[0, r_max]``, by Chebyshev interpolation on panels of ``1 / (2 a_max)``."""

    def __init__(self, c, sigmas, alphas, r_max):
        self.h = 0.5 / alphas.max()
        panels = int(math.ceil(r_max / self.h)) + 1
        nodes = np.cos(np.pi * (np.arange(_CHEB) + 0.5) / _CHEB)
        r = (np.arange(panels)[:, None] + 0.5 + nodes / 2) * self.h
        values = sum(cm * _smooth(s, a, r * r) for cm, s, a in zip(c, sigmas, alphas))
        T = np.cos(np.outer(np.arccos(nodes), np.arange(_CHEB)))
        self.cheb = values @ T * (2.0 / _CHEB)
        self.cheb[:, 0] /= 2

    def __call__(self, r):
        p = (r / self.h).astype(int)
        y = 2 * (r / self.h - p) - 1
        b1, b2 = np.zeros_like(y), np.zeros_like(y)
        for k in range(_CHEB - 1, 0, -1):  # Clenshaw
            b1, b2 = 2 * y * b1 - b2 + self.cheb[p, k], b1
        return y * b1 - b2 + self.cheb[p, 0]


def _offsets(n_rows, n_cols, images):
    """Offsets ``(x, y)`` [steps] of the quarter table (``x = (2 t + n mod 2) / 2``, ``y = n sqrt3/2``, rows
    ``n <= (2 J + 1) n_rows / 2``, columns ``t <= (2 I + 1) n_cols / 2``) and, for each kept image, the
    index in it of every node's offset ``x0 + (i Lx, j Ly)``, ``x0`` the minimum image."""
    I, J = images
    n = np.arange((2 * J + 1) * n_rows // 2 + 1)[:, None]
    t = np.arange((2 * I + 1) * n_cols // 2 + 1)[None, :]
    x, y = (2 * t + n % 2) / 2.0 + 0.0 * n, n * (_SQRT3 / 2) + 0.0 * t
    q = np.arange(n_rows)[:, None]
    r = np.arange(n_cols)[None, :]
    row0 = np.where(q <= n_rows // 2, q, q - n_rows) + 0 * r  # signed minimum-image row
    x2 = 2 * r + q % 2  # twice the minimum-image x, in (-n_cols, n_cols]
    x2 = np.where(x2 > n_cols, x2 - 2 * n_cols, x2)
    index = [(np.abs(row0 + j * n_rows), (np.abs(x2 + 2 * i * n_cols) - q % 2) // 2)
             for i in range(-I, I + 1) for j in range(-J, J + 1)]
    return x, y, index


def thin_part(n_rows, n_cols, step, bodies, which):
    """``E* sum_i (W_i - s0_i W)`` of the bodies ``which`` at every node of the cell, up to a constant.

    Parameters
    ----------
    n_rows, n_cols : int
        Rows (even) and columns of the cell.
    step : float
        Lattice step ``c`` [length].
    bodies : bem.Bodies
        The two bodies.
    which : tuple of int
        The coated bodies (1, 2) that take this route (the images kept: :func:`images_for` the
        largest :func:`reach`).

    Returns
    -------
    ndarray, shape ``(n_rows, n_cols)``, read-only
        Brick storage, in the units of the periodic template (``C = c / (pi E*) W_c``), its mean not
        removed.
    """
    E_star = bodies.E_star
    images = images_for(n_rows, n_cols, max(reach(bodies, i, step) for i in which))
    x, y, index = _offsets(n_rows, n_cols, images)
    quarter = np.zeros(x.shape)
    s_scale = 1.0 / E_star
    for i in which:
        one = _one(bodies, i)
        s0 = float(mode_compliance(0.0, one.E1, one.nu1) + mode_compliance(0.0, one.E2, one.nu2))
        table = coated_table(step, (x.shape[0], x.shape[1] - 1), one)
        quarter += table * (math.pi / step) - s0 * template(x, y)
    r_min = image_reach(n_rows, n_cols, images)
    c, sigmas = _tail(bodies, which, step, r_min, s_scale)
    from scipy.special import gamma, gammainccinv

    alphas = np.array([math.sqrt(gammainccinv(s, _Q_FLOOR)) / r_min for s in sigmas])
    points, weights = box_rule(_rule_size(c, sigmas, alphas, s_scale))
    smooth = _Smooth(c, sigmas, alphas, math.hypot(x[-1, -1], y[-1, -1]) + 1.0)
    xs, ys, flat = x.ravel(), y.ravel(), quarter.reshape(-1)
    rows = max(1, (1 << 20) // weights.size)
    for lo in range(0, xs.size, rows):
        dx = xs[lo:lo + rows, None] - points[None, :, 0]
        dy = ys[lo:lo + rows, None] - points[None, :, 1]
        flat[lo:lo + rows] -= smooth(np.sqrt(dx * dx + dy * dy)) @ weights

    def radial(k):
        out = np.zeros_like(k)
        for cm, s, a in zip(c, sigmas, alphas):
            z = k * k / (4 * a * a)
            out += cm * math.pi / gamma(s) * a ** (2 * s - 2) * _exp_integral(s, z)
        return out

    fourier = alias_sum(n_rows, n_cols, radial, 2 * alphas.max() * math.sqrt(_Z_CUT))
    w = E_star * (sum(quarter[row, col] for row, col in index) + fourier)
    w.setflags(write=False)
    return w
