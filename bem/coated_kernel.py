"""Influence coefficients of the pyramid element on coated bodies (the half-space region).

The surface of two bodies, coated or not, closes by ``2 (s1(q) + s2(q)) / q`` per unit pressure
amplitude of the Fourier mode ``q`` (:mod:`bem.coating`). In real space the closure under a point
load is the radial kernel ``K(r) = (1/pi) int_0^inf s(q) J0(q r) dq``, ``s = s1 + s2``. Each coated
body's ``s_i(q)`` is split (docs/method.md section 7.1) into ::

    s_i(q) = s_c,i + Delta_i e^(-q beta_i) + R_i(q),    Delta_i = s_s,i - s_c,i,  beta_i = B t_i,

the coating's half-space compliance ``s_c = (1 - nu_c^2) / E_c``, a long-range part that carries
the substrate's ``s_s = (1 - nu_s^2) / E_s`` at low frequency, and a remainder ``R_i`` that
vanishes at ``q = 0``, is bounded and decays like ``e^(-2 q t)``. Their kernels are ``s_c / (pi r)``
(the homogeneous kernel: the closed-form template :func:`bem.template.template`), ::

    Delta / (pi sqrt(r^2 + beta^2))      (the field of a point load raised by beta; the transform
                                          int_0^inf e^(-beta q) J0(q r) dq = 1 / sqrt(r^2 + beta^2))

and ``k_i(r) / pi``, ``k_i(r) = int_0^inf R_i(q) J0(q r) dq``, tabulated once per body:

* for ``r / t <= rho_sw``: the integral by composite Gauss-Legendre quadrature in ``q t`` at the
  Chebyshev points of panels in ``r / t`` (16 points a panel, panel length 1 up to ``r / t = 4``,
  then a quarter of the panel's start), evaluated by Clenshaw's recurrence;
* beyond: the large-``r`` series ``k = sum_(m even >= 2) a_m g_m / r^(m+1)``,
  ``g_m = 2^m Gamma((m+1)/2) / Gamma((1-m)/2)``, of the Taylor coefficients ``a_m`` of ``R_i``
  (:func:`bem.coating.factor_taylor`); ``rho_sw`` is where its smallest kept term falls below
  ``1e-17 s``, and the two sides are compared at build time (``1e-13 s`` or an error).

The coefficient of the pyramid element at the lattice offset ``x`` is ::

    C(x) = c / pi * [ S_c w_t(x / c) + int pyr(xi) G(|x / c - xi|) dxi ],
    G(r) = sum_i Delta_i / sqrt(r^2 + beta_i^2) + k_i(r)   (lattice units, c = 1),

``S_c`` the sum of the coatings' ``s_c`` and the uncoated bodies' ``(1 - nu^2) / E``. ``G`` is
smooth away from ``r = 0`` (there it varies on the scale ``t``); the element integral is taken by

* polar rules about the offset over the triangles of which the offset is a vertex (the centre and
  the six neighbours): ``xi = x + s e(u)``, Gauss-Legendre in ``u`` and on panels in ``s`` graded
  geometrically from ``s = t / 4`` (the structure of ``G`` at ``r ~ t`` is resolved at any ``t``);
* Gauss-Legendre on each of the six triangles (collapsed square, 24 x 24 points) for the other
  triangles and offsets within 8 steps;
* farther out, the pyramid as the box spline of the three lattice directions ``e1, e2, e3``
  (``pyr(x) = sqrt3/2 * density of a e1 + b e2 + c e3``, ``a, b, c`` uniform in ``[-1/2, 1/2]``:
  its transform is :func:`bem.periodic.kernel.pyramid_transform`), a tensor Gauss rule of 6, 3, 2
  points per direction beyond 8, 40, 200 steps.

Accuracy and cost: ``tests/bem/test_coated_kernel.py``, ``benchmarks/coated_hertz.py``,
``docs/performance.md``.
"""

from __future__ import annotations

import copy
import math
from functools import lru_cache

import numpy as np

from .checks import check_positive
from .coating import Bodies, Coating, coating_factor, factor_taylor, mode_compliance
from .errors import InputError
from .template import template

__all__ = ["box_rule", "coated_table", "point_kernel", "series_reach"]

B_RAISE = 2.0
"""Height of the raised point load per coating thickness, ``beta = B_RAISE t`` [-]."""

_ORDER = 40  # Taylor coefficients of R kept for the large-r series
_CHEB = 16  # Chebyshev points per panel in r / t
_GAUSS_X = 16  # Gauss-Legendre points per panel in q t
_SQRT3 = math.sqrt(3.0)
_HEX = np.array([(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)) for k in range(7)])
_HEX[[0, 6]] = (1.0, 0.0)
_NEAR = 8.0  # offsets [steps] within which the element is integrated triangle by triangle
_FAR = ((8.0, 6), (40.0, 3), (200.0, 2))  # (from radius, Gauss points per direction) of the box rule
_CHUNK = 1 << 21  # kernel evaluations per block


@lru_cache(maxsize=16)
def _legendre(n):
    return np.polynomial.legendre.leggauss(n)


def _gauss(n, a=0.0, b=1.0):
    x, w = _legendre(n)
    return a + (b - a) * (x + 1) / 2, w * (b - a) / 2


class _Remainder:
    """``k(r) = int_0^inf R(q) J0(q r) dq`` of one coated body, in lattice units (``c = 1``).

    ``R(q) = s(q) - s_c - Delta e^(-B q t)``; in ``x = q t`` and ``rho = r / t``,
    ``k(r) = kt(r / t) / t`` with ``kt(rho) = int_0^inf R(x / t) J0(x rho) dx``.
    """

    def __init__(self, E, nu, coating, tau):
        self.tau = tau
        self._coating, self._substrate = coating, (E, nu)
        self.s_c = (1.0 - coating.nu ** 2) / coating.E
        self.delta = float(mode_compliance(0.0, E, nu)) - self.s_c
        s_max = max(abs(self.s_c), abs(self.delta + self.s_c))
        phi, radius = factor_taylor(coating, E, nu, order=_ORDER)
        m = np.arange(_ORDER + 1)
        a = self.s_c * phi - self.delta * (-B_RAISE) ** m / np.array([math.factorial(int(k)) for k in m])
        a[0] -= self.s_c
        from scipy.special import gamma

        even = m[2::2]
        self._series = a[2::2] * 2.0 ** even * gamma((even + 1) / 2) / gamma((1 - even) / 2)
        # switch where the smallest term of the series is below 1e-17 s_max and 32 / r0 beyond (the
        # series misses terms like e^(-rho r0) < 1e-14 beyond 32 / r0, r0 the distance of the nearest pole of phi)
        rho = 32.0 / (radius / 0.6)
        while rho < 1e6:
            terms = np.abs(self._series) * rho ** -(even + 1.0)
            if terms.max() < 1e-17 * s_max or (terms.min() < 1e-17 * s_max and np.argmin(terms) > 2):
                break
            rho *= 1.25
        grid = np.arange(0.0, 80.0, 0.05)
        big = np.abs(self._r(grid)) > 1e-15 * s_max  # above the rounding of phi - 1
        self._x_max = grid[np.flatnonzero(big)[-1]] + 1.0 if big.any() else 1.0
        self._nodes = {}
        for _ in range(6):
            self._build(rho, radius)
            err = self.series_error() / s_max
            if err <= 1e-13:
                return
            rho *= 1.5
        raise ArithmeticError(f"the remainder kernel's large-r series misses its integral by {err:.1e} s")

    def _build(self, rho, radius):
        """The Chebyshev panels on ``[0, rho]``, each filled by a quadrature in ``x = q t`` fine enough
        for its largest ``rho``."""
        self.rho_sw, self._radius = rho, radius
        even = np.arange(2, _ORDER + 1, 2)
        self._keep = int(np.argmin(np.abs(self._series) * rho ** -(even + 1.0))) + 1
        bounds = [0.0]
        while bounds[-1] < rho:
            bounds.append(min(rho, bounds[-1] + max(1.0, bounds[-1] / 4)))
        self._bounds = np.array(bounds)
        nodes = np.cos(np.pi * (np.arange(_CHEB) + 0.5) / _CHEB)  # Chebyshev points of the first kind
        lo, hi = self._bounds[:-1, None], self._bounds[1:, None]
        points = (lo + hi) / 2 + (hi - lo) / 2 * nodes
        values = np.stack([self.direct(row) for row in points])
        T = np.cos(np.outer(np.arccos(nodes), np.arange(_CHEB)))  # T_k at the nodes
        self._cheb = values @ T * (2.0 / _CHEB)
        self._cheb[:, 0] /= 2

    def series_error(self):
        """Largest difference of the large-``r`` series and the quadrature at ``rho_sw`` .. 1.5 ``rho_sw``."""
        check = self.rho_sw * np.array([1.0, 1.2, 1.5])
        return float(np.max(np.abs(self._asymptotic(check) - self.direct(check))))

    def _r(self, x):
        """``R`` at ``x = q t`` [1/pressure]."""
        return self.s_c * (coating_factor(x, self._coating, *self._substrate) - 1.0) - self.delta * np.exp(-B_RAISE * x)

    def _quadrature(self, rho_max):
        """Composite Gauss-Legendre nodes ``x`` and weights times ``R`` on ``[0, x_max]``, two periods
        of ``J0(x rho_max)`` a panel (cached per panel length)."""
        h = min(self._radius / 2, 4 * math.pi / max(rho_max, 1e-300), 0.5)
        n = int(math.ceil(self._x_max / h))
        if n not in self._nodes:
            edges = np.linspace(0.0, self._x_max, n + 1)
            g, wg = _legendre(_GAUSS_X)
            half = np.diff(edges)[:, None] / 2
            x = ((edges[:-1, None] + half) + half * g).ravel()
            self._nodes[n] = x, (half * wg).ravel() * self._r(x)
        return self._nodes[n]

    def direct(self, rho):
        """``kt`` at ``rho`` by the quadrature in ``x`` (a 1-D array)."""
        from scipy.special import j0

        x, wr = self._quadrature(float(np.max(rho)))
        out = np.empty(rho.size)
        rows = max(1, _CHUNK // x.size)
        for i in range(0, rho.size, rows):
            out[i:i + rows] = j0(np.outer(rho[i:i + rows], x)) @ wr
        return out

    def _asymptotic(self, rho):
        u = 1.0 / (rho * rho)
        acc = np.zeros_like(rho)
        for c in self._series[: self._keep][::-1]:
            acc = acc * u + c
        return acc * u / rho

    def __call__(self, r):
        """``k(r)`` [1/pressure] at distances ``r`` [lattice steps], a 1-D array."""
        rho = r / self.tau
        out = np.empty_like(rho)
        far = rho > self.rho_sw
        out[far] = self._asymptotic(rho[far])
        near = ~far
        if near.any():
            p = np.clip(np.searchsorted(self._bounds, rho[near], side="right") - 1, 0, self._bounds.size - 2)
            lo, hi = self._bounds[p], self._bounds[p + 1]
            y = (2 * rho[near] - lo - hi) / (hi - lo)
            b1, b2 = np.zeros_like(y), np.zeros_like(y)
            for k in range(_CHEB - 1, 0, -1):  # Clenshaw
                b1, b2 = 2 * y * b1 - b2 + self._cheb[p, k], b1
            out[near] = y * b1 - b2 + self._cheb[p, 0]
        return out / self.tau


class _Kernel:
    """``G(r)`` of the module docstring and ``S_c`` for a pair of bodies at a lattice step."""

    def __init__(self, bodies, step):
        self.S_c = 0.0
        self.parts = []
        for E, nu, coating in ((bodies.E1, bodies.nu1, bodies.coating1), (bodies.E2, bodies.nu2, bodies.coating2)):
            if coating is None or (coating.E == E and coating.nu == nu):
                self.S_c += float(mode_compliance(0.0, E, nu))
                continue
            rem = copy.copy(_remainder(E, nu, coating.E, coating.nu))
            rem.tau = coating.thickness / step
            self.S_c += rem.s_c
            self.parts.append(rem)

    def __call__(self, r):
        out = np.zeros_like(r)
        for rem in self.parts:
            beta = B_RAISE * rem.tau
            out += rem.delta / np.sqrt(r * r + beta * beta) + rem(r)
        return out


@lru_cache(maxsize=8)
def _remainder(E, nu, E_c, nu_c):
    """The tabulated remainder of a coating on its substrate, in ``r / t`` (any thickness and step: set ``tau``)."""
    return _Remainder(E, nu, Coating(1.0, E_c, nu_c), 1.0)


@lru_cache(maxsize=8)
def _kernel(bodies, step):
    return _Kernel(bodies, step)


def series_reach(bodies, step):
    """Distance [steps] beyond which each coated body's remainder kernel is its large-``r`` series (``rho_sw t / c``)."""
    return max((rem.rho_sw * rem.tau for rem in _kernel(bodies, check_positive("step", step)).parts), default=0.0)


def point_kernel(r, bodies, *, step=1.0):
    """Surface closure under a unit point load, ``K(r) = (1/pi) int_0^inf s(q) J0(q r) dq`` [1/length].

    Parameters
    ----------
    r : array_like
        Distances [length], ``> 0``.
    bodies : bem.Bodies
        The two bodies.
    step : float
        Length unit of the tabulation [length] (the lattice step; any positive length).

    Returns
    -------
    numpy.ndarray
        ``K`` times the force gives the closure [length per force = 1/(pressure length)]; the
        homogeneous body gives ``(s1 + s2) / (pi r)``.
    """
    if not isinstance(bodies, Bodies):
        raise InputError(f"bodies = {bodies!r} is not allowed: it must be a bem.Bodies.")
    r = np.asarray(r, dtype=float)
    kernel = _kernel(bodies, check_positive("step", step))
    rl = r.ravel() / step
    return ((kernel.S_c / rl + kernel(rl)) / (math.pi * step)).reshape(r.shape)


# -- quadrature rules over the pyramid element: points xi and weights (pyr included) --------------

def _triangle_rule(n):
    """Collapsed Gauss rule on the six triangles from the centre; ``(points (N, 2), weights (N,))``."""
    s, ws = _gauss(n)
    u, wu = _gauss(n)
    S, U = (a.ravel() for a in np.meshgrid(s, u, indexing="ij"))
    W = np.outer(ws, wu).ravel() * S * (1 - S) * (_SQRT3 / 2)
    pts, wts = [], []
    for k in range(6):
        e = (1 - U)[:, None] * _HEX[k] + U[:, None] * _HEX[k + 1]
        pts.append(S[:, None] * e)
        wts.append(W)
    return np.concatenate(pts), np.concatenate(wts), np.repeat(np.arange(6), S.size)


def _polar_rule(apex, p1, p2, f, grade, n_s=16, n_u=32):
    """Rule on the triangle ``(apex, p1, p2)`` in polar form about ``apex``; ``f`` the pyramid's values
    there; ``s`` panels graded geometrically from ``grade``."""
    edges = [0.0]
    e = max(grade, 1e-300)
    while e < 1.0:
        edges.append(e)
        e *= 2.0
    edges.append(1.0)
    s = np.concatenate([_gauss(n_s, a, b)[0] for a, b in zip(edges[:-1], edges[1:])])
    ws = np.concatenate([_gauss(n_s, a, b)[1] for a, b in zip(edges[:-1], edges[1:])])
    u, wu = _gauss(n_u)
    S, U = (a.ravel() for a in np.meshgrid(s, u, indexing="ij"))
    d1, d2 = p1 - apex, p2 - apex
    e = (1 - U)[:, None] * d1 + U[:, None] * d2
    pyr = (1 - S) * f[0] + S * ((1 - U) * f[1] + U * f[2])
    W = np.outer(ws, wu).ravel() * S * abs(d1[0] * d2[1] - d1[1] * d2[0]) * pyr
    return apex + S[:, None] * e, W


def box_rule(n):
    """Tensor Gauss rule (``n`` a direction) of the pyramid as the box spline ``a e1 + b e2 + c e3``; ``(points, weights)``."""
    g, w = _gauss(n, -0.5, 0.5)
    A, Bb, C = (a.ravel() for a in np.meshgrid(g, g, g, indexing="ij"))
    W = np.einsum("i,j,k->ijk", w, w, w).ravel() * (_SQRT3 / 2)
    pts = A[:, None] * np.array([1.0, 0.0]) + Bb[:, None] * np.array([0.5, _SQRT3 / 2]) + C[:, None] * np.array([-0.5, _SQRT3 / 2])
    return pts, W


def _apply(kernel, x, y, pts, wts):
    """``sum_j w_j G(|(x, y) - xi_j|)`` for each offset (1-D arrays), in blocks."""
    out = np.empty(x.size)
    rows = max(1, _CHUNK // max(1, wts.size))
    for i in range(0, x.size, rows):
        dx = x[i:i + rows, None] - pts[None, :, 0]
        dy = y[i:i + rows, None] - pts[None, :, 1]
        out[i:i + rows] = kernel(np.sqrt(dx * dx + dy * dy).ravel()).reshape(dx.shape) @ wts
    return out


def _element(kernel, x, y, grade):
    """``int pyr(xi) G(|(x, y) - xi|) dxi`` at the offsets ``(x, y)`` [lattice steps] (1-D arrays)."""
    r = np.hypot(x, y)
    out = np.empty(x.size)
    near = r < _NEAR
    vertex = near & (np.abs(r - np.round(r)) < 1e-9) & (np.round(r) <= 1)
    tri, twt, tid = _triangle_rule(24)
    plain = near & ~vertex
    if plain.any():
        out[plain] = _apply(kernel, x[plain], y[plain], tri, twt)
    for i in np.flatnonzero(vertex):
        p = np.array([x[i], y[i]])
        if r[i] < 0.5:  # the centre: every triangle has it as a vertex
            parts = [_polar_rule(_HEX[0] * 0, _HEX[k], _HEX[k + 1], (1.0, 0.0, 0.0), grade) for k in range(6)]
            others = np.zeros(6, bool)
        else:
            j = int(np.argmin(np.hypot(*(_HEX[:6] - p).T)))
            centre = np.zeros(2)
            parts = [_polar_rule(_HEX[j], centre, _HEX[(j + 1) % 6], (0.0, 1.0, 0.0), grade),
                     _polar_rule(_HEX[j], centre, _HEX[(j - 1) % 6], (0.0, 1.0, 0.0), grade)]
            others = ~np.isin(np.arange(6), (j, (j - 1) % 6))
        pts = np.concatenate([q for q, _ in parts] + [tri[others[tid]]])
        wts = np.concatenate([w for _, w in parts] + [twt[others[tid]]])
        out[i] = _apply(kernel, x[i:i + 1], y[i:i + 1], pts, wts)[0]
    lower = _NEAR
    for k, (radius, n) in enumerate(_FAR):
        upper = _FAR[k + 1][0] if k + 1 < len(_FAR) else math.inf
        band = (r >= lower) & (r < upper)
        if band.any():
            out[band] = _apply(kernel, x[band], y[band], *box_rule(n))
        lower = upper
    return out


@lru_cache(maxsize=4)
def _table(step, n_rows, n_cols, bodies):
    kernel = _kernel(bodies, step)
    n = np.arange(n_rows)[:, None]
    t = np.arange(n_cols + 1)[None, :]
    x, y = (2 * t + n % 2) / 2.0 + 0.0 * n, n * (_SQRT3 / 2) + 0.0 * t
    table = kernel.S_c * template(x, y)
    if kernel.parts:
        grade = min(rem.tau for rem in kernel.parts) / 4
        table += _element(kernel, x.ravel(), y.ravel(), grade).reshape(x.shape)
    table *= step / math.pi
    table.flags.writeable = False
    return table


def coated_table(step, shape, bodies):
    """Influence coefficients of the unit pyramid on two (coated) bodies at every lattice offset.

    Parameters
    ----------
    step : float
        Lattice step ``c`` [length].
    shape : tuple of int
        ``(n_rows, n_cols)`` of the brick arrays; the table covers ``n_rows x (n_cols + 1)`` offsets
        ``x = (2 t + n mod 2) c / 2``, ``y = n sqrt3 / 2 c`` (row ``n``, column ``t``).
    bodies : bem.Bodies
        The two bodies (coated or not).

    Returns
    -------
    numpy.ndarray
        ``C`` [length/pressure], read-only, cached per ``(step, shape, bodies)`` (the last four);
        for homogeneous bodies ``c / (pi E*) w_t`` (:class:`bem.operator.InfluenceOperator`).
    """
    if not isinstance(bodies, Bodies):
        raise InputError(f"bodies = {bodies!r} is not allowed: it must be a bem.Bodies.")
    n_rows, n_cols = (int(v) for v in shape)
    if n_rows < 1 or n_cols < 1:
        raise InputError(f"shape = {tuple(shape)} is not allowed: both sizes must be >= 1.")
    return _table(check_positive("step", step), n_rows, n_cols, bodies)
