"""The displacement template ``w_t`` of one unit pyramid (paper section 4, eq. 5).

``w_t(x, y) = integral over the unit hexagon of pyr(xi, eta) / rho d(xi) d(eta)``,
``rho = sqrt((x - xi)^2 + (y - eta)^2)``, in lattice units (step ``c = 1``). The
hexagon has side 1, centre 0 and vertices ``v_k = (cos(k pi/3), sin(k pi/3))``;
the pyramid ``pyr`` is 1 at the centre, 0 at the ``v_k`` and linear on the six
triangles ``(0, v_k, v_{k+1})`` (docs/method.md section 2). The influence matrix is
``C[n, m] = c / (pi E*) * w_t((r_n - r_m) / c)`` (eq. 6).

Near field, ``r < R_SWITCH`` -- closed form
    On a triangle the pyramid is ``f(x) + g.(xi - x)``; with
    ``div_xi((xi - x)/rho) = 1/rho`` and ``grad_xi(rho) = (xi - x)/rho`` the area
    integral becomes edge integrals. Summed over the six triangles, all terms
    collapse onto the 12 edges (6 spokes ``0 -> v_k``, 6 outer sides
    ``v_k -> v_{k+1}``) and

        w_t = (1/sqrt3) * [sum_spokes E_e - sum_outer E_e],
        E_e = 2 int_e t^2/rho dt = [t rho]_{t1}^{t2} - d^2 L,
        L   = int_e dt/rho = asinh(t2/|d|) - asinh(t1/|d|),

    with ``t`` the tangential coordinate along the edge measured from the foot of
    the perpendicular from ``x`` and ``d`` the distance of ``x`` to the edge line.
    Check: ``w_t(0, 0) = (3 sqrt3 / 2) ln 3``. Evaluated without cancellation:
    ``[t rho] = rho2 + t1 (t1 + t2)/(rho1 + rho2)`` (edge length 1) and
    ``L = log1p((1 + |t1 + t2|/(rho1 + rho2)) / (t1 + rho1))`` after reflecting
    ``t -> -t`` when ``t1 + t2 < 0``, with ``t1 + rho1 = d^2/(rho1 - t1)`` for
    ``t1 < 0``. Where ``d = 0`` (``x`` on an edge line, at a vertex or at the
    centre) the term ``d^2 L`` is 0 exactly. What is left is the cancellation
    between the O(r) edge terms of a O(1/r) sum: relative error about
    ``12 eps r^2``, measured <= 1.4e-13 just inside ``r = 8``.

Far field, ``r >= R_SWITCH`` -- multipole expansion
    ``1/rho = sum_n |xi|^n / r^(n+1) P_n(cos(theta - phi))``. The pyramid has D6
    symmetry, so odd ``n`` vanish and only the Fourier modes ``cos(6 m theta)``
    of ``P_n`` survive: the six-fold anisotropy first appears at ``n = 6``
    (``1/r^7``), ``cos(12 theta)`` at ``n = 12``. The moments are exact:

        w_t = (1/sqrt3) sum_{n even} sum_{6m <= n} K[n, m] cos(6 m theta) / r^(n+1),
        K[n, m] = sqrt3 * a[n, 6m] * I[n, m],
        a[n, k] = (2 - [k = 0]) 4^-n binom(2j, j) binom(2n - 2j, n - j),  j = (n - k)/2,
        I[n, m] = int pyr |xi|^n cos(6 m phi) dA
                = 6 (-1)^m (sqrt3/2)^(n+2) / ((n+2)(n+3))
                  * int_{-1/sqrt3}^{1/sqrt3} Re((1 + i u)^(6m)) (1 + u^2)^((n-6m)/2) du,

    (Fourier series of ``P_n``; polar coordinates per triangle with ``u = tan``
    of the angle from the side normal), computed in exact rational arithmetic by
    :func:`_multipole_coefficient`: ``K[0,0] = 3/2`` (volume ``sqrt3/2``),
    ``K[2,0] = 3/32``, ``K[4,0] = 27/1280``, ``K[6,1] = 33/4096``, ...
    Kept: ``n <= 10`` (isotropic 0..10, ``cos 6 theta`` at 6, 8, 10).

Error budget (relative, against a 40-digit evaluation of the closed form)
    ``R_SWITCH = 8`` balances the two sides. Multipole: truncation after
    ``n = 10``, first omitted term ``sum_m |K[12, m]| / (sqrt3 V) / 8^12 = 2.6e-14``
    (measured 2.6e-14 at ``r = 8``, 5e-15 at ``r = 9 .. 20``, rounding 3e-16
    beyond). Closed form: measured <= 2.3e-14 for ``r < 4``, 6.3e-14 for
    ``r < 7.5``, 1.4e-13 for ``7.5 <= r < 8``. Bound used in the docs: 2e-13.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from .checks import InputError, check_finite_array, check_positive

__all__ = ["template", "diagonal_coefficient", "lattice_table", "R_SWITCH"]

R_SWITCH = 8.0
"""Offset radius [lattice steps] beyond which the multipole expansion is used."""

_SQRT3 = math.sqrt(3.0)
# centre, v_0 .. v_5 and v_0 again to close the outline (same floats as the lattice nodes)
_VERTS = np.array([(0.0, 0.0), (1.0, 0.0), (0.5, _SQRT3 / 2), (-0.5, _SQRT3 / 2),
                   (-1.0, 0.0), (-0.5, -_SQRT3 / 2), (0.5, -_SQRT3 / 2), (1.0, 0.0)])
_N_MAX = 10  # highest multipole order kept
_TINY = 1e-280
_CHUNK = 8192  # points per block: keeps the temporaries in cache


def _multipole_coefficient(n, m):
    """Exact ``K[n, m]`` (a Fraction) of the far-field term ``K cos(6 m theta) / (sqrt3 r^(n+1))``."""
    k = 6 * m
    j = (n - k) // 2
    a = Fraction(math.comb(2 * j, j) * math.comb(2 * n - 2 * j, n - j), 4**n) * (1 if k == 0 else 2)
    # polynomial Re((1 + i u)^k) * (1 + u^2)^((n - k)/2), coefficients by power of u
    poly = [math.comb(k, i) * (-1) ** (i // 2) if i % 2 == 0 else 0 for i in range(k + 1)]
    for _ in range((n - k) // 2):
        poly = [c + (poly[i - 2] if i >= 2 else 0) for i, c in enumerate(poly + [0, 0])]
    # int_{-u0}^{u0} u^(2i) du = 2 / ((2i + 1) 3^i) / sqrt3 with u0 = 1/sqrt3
    moment = sum(Fraction(2 * c, (i + 1) * 3 ** (i // 2)) for i, c in enumerate(poly) if i % 2 == 0)
    # 6 (-1)^m h^(n+2) / ((n+2)(n+3)), h = sqrt3/2, n even
    pre = Fraction(6 * (-1) ** m * 3 ** ((n + 2) // 2), 2 ** (n + 2) * (n + 2) * (n + 3))
    return a * pre * moment


# Horner coefficients in q = 1/r^2, already divided by sqrt3
_ISO = tuple(float(_multipole_coefficient(n, 0)) / _SQRT3 for n in range(0, _N_MAX + 1, 2))
_ANISO6 = tuple(float(_multipole_coefficient(n, 1)) / _SQRT3 for n in range(6, _N_MAX + 1, 2))


def _horner(coeffs, q):
    acc = coeffs[-1]
    for c in coeffs[-2::-1]:
        acc = acc * q + c
    return acc


def _far(x, y, r2):
    """Multipole expansion (``r >= R_SWITCH``); ``r2 = x^2 + y^2``, may be ``inf``."""
    q = 1.0 / r2
    r_inv = np.sqrt(q)
    c = x * r_inv
    u = c * c  # cos^2(theta)
    cos6 = ((32.0 * u - 48.0) * u + 18.0) * u - 1.0  # T_6(cos theta)
    out = r_inv * (_horner(_ISO, q) + cos6 * (q * q * q) * _horner(_ANISO6, q))
    huge = q == 0.0  # x^2 + y^2 overflowed: only the 1/r term is left
    if huge.any():
        out[huge] = _ISO[0] / np.hypot(x[huge], y[huge])
    return out


def _edge_family(start, tangent):
    """Constants of 6 unit edges ``start -> start + tangent``: columns (6, 1) each."""
    tx, ty = tangent[:, :1], tangent[:, 1:]
    sx, sy = start[:, :1], start[:, 1:]
    return tx, ty, tx * sx + ty * sy, tx * sy - ty * sx


_SPOKE = _edge_family(_VERTS[[0] * 6], _VERTS[1:7])
_SIDE = _edge_family(_VERTS[1:7], _VERTS[2:8] - _VERTS[1:7])


def _edge_sum(family, x, y, rho1, rho2):
    """``sum_e E_e``, ``E_e = 2 int_e t^2/rho dt``, over one family of 6 unit edges.

    ``t1`` is the tangential coordinate of the start (``t2 = t1 + 1``), ``d`` the
    signed distance to the edge line, ``rho1``, ``rho2`` the end distances.
    """
    tx, ty, c_t, c_d = family
    t1 = c_t - (tx * x + ty * y)
    d = c_d - (tx * y - ty * x)
    d2 = d * d
    s = 2.0 * t1 + 1.0  # t1 + t2
    abs_s = np.abs(s)
    rsum = rho1 + rho2  # >= 1
    t_rho = rho2 + t1 * s / rsum  # [t rho] = (t2 - t1) rho2 + t1 (rho2 - rho1), rho2 - rho1 = s/rsum
    # L = int dt/rho = log1p((1 + |s|/rsum) / (a + rho_a)): after reflecting t -> -t
    # when s < 0, a = (|s| - 1)/2 is the lower end and rho_a = min(rho1, rho2)
    a = 0.5 * (abs_s - 1.0)
    big = np.maximum(np.minimum(rho1, rho2) + np.abs(a), _TINY)  # rho_a + |a| > 0
    low = np.where(a >= 0, big, d2 / big)  # a + rho_a, as d^2/(rho_a - a) when a < 0
    # low < _TINY only where d^2 < 1e-276: there d^2 L vanishes in float anyway
    log_term = np.log1p((1.0 + abs_s / rsum) / np.maximum(low, _TINY))
    return (t_rho - d2 * log_term).sum(axis=0)


def _near_block(x, y):
    """Closed form for one block of points (any ``r``)."""
    dx = _VERTS[:, :1] - x  # (8, n): centre, v_0 .. v_5, v_0 again
    dy = _VERTS[:, 1:] - y
    rho = np.sqrt(dx * dx + dy * dy)
    spokes = _edge_sum(_SPOKE, x, y, rho[:1], rho[1:7])
    sides = _edge_sum(_SIDE, x, y, rho[1:7], rho[2:8])
    return (spokes - sides) / _SQRT3


def _block(x, y):
    """``w_t`` on one block of points: closed form inside ``R_SWITCH``, multipole outside."""
    with np.errstate(over="ignore"):
        r2 = x * x + y * y
    far = r2 >= R_SWITCH * R_SWITCH
    if far.all():
        return _far(x, y, r2)
    out = np.empty_like(x)
    near = ~far
    out[near] = _near_block(x[near], y[near])
    if far.any():
        out[far] = _far(x[far], y[far], r2[far])
    return out


def template(x, y):
    """Displacement template ``w_t(x, y)`` of the unit pyramid (eq. 5), lattice units.

    Parameters
    ----------
    x, y : array_like
        Offsets from the pyramid centre [lattice steps, dimensionless], finite,
        broadcastable against each other. Not modified.

    Returns
    -------
    numpy.ndarray or numpy.float64
        ``w_t`` [lattice steps] with the broadcast shape of ``x`` and ``y``
        (a NumPy scalar for scalar input). The displacement of a pyramid of
        height ``p`` on a mesh of step ``c`` is ``c p w_t / (pi E*)``.

    Raises
    ------
    bem.InputError
        If ``x`` or ``y`` holds NaN/inf or the two do not broadcast.

    Notes
    -----
    Closed form for ``r = hypot(x, y) < R_SWITCH = 8`` and a multipole expansion
    with exact moments (through ``1/r^11``, six-fold term from ``1/r^7``)
    beyond; both are derived in the module docstring. Relative error < 2e-13
    everywhere. ``w_t(0, 0) = (3 sqrt3/2) ln 3``; ``w_t -> (sqrt3/2)/r`` with a
    relative correction ``(1/16)/r^2``.
    """
    x = check_finite_array("x", x, min_size=0)
    y = check_finite_array("y", y, min_size=0)
    try:
        xb, yb = np.broadcast_arrays(x, y)
    except ValueError:
        raise InputError(
            f"x has shape {x.shape} and y has shape {y.shape} which is not allowed: "
            "they must broadcast against each other."
        ) from None
    shape = xb.shape
    xf = xb.ravel()
    yf = yb.ravel()
    out = np.empty(xf.size)
    for k in range(0, xf.size, _CHUNK):
        block = slice(k, k + _CHUNK)
        out[block] = _block(xf[block], yf[block])
    return out.reshape(shape)[()]


def diagonal_coefficient(step, E_star):
    """Diagonal influence coefficient ``C_nn = c / (pi E*) w_t(0, 0)`` [length/pressure] (eq. 6).

    The closure of a node under its own unit pyramid; the paper states layer
    compliances in units of it (``lam = 10 C_nn``, Fig. 5).
    """
    return float(lattice_table((1, 0), check_positive("step", step), check_positive("E_star", E_star))[0, 0])


def lattice_table(shape, step, E_star):
    """The influence coefficients of eq. 6 at every lattice offset of a brick array of ``shape`` [length/pressure].

    Entry ``[n, t]`` is ``c / (pi E*) w_t(m / 2, n sqrt3 / 2)``, ``m = 2 t + n mod 2`` (lattice units: ``n`` rows
    and ``m`` half steps apart), shape ``(n_rows, n_cols + 1)``; ``step`` is ``c`` [length], ``E_star`` ``E*``
    [pressure]. The table of :class:`bem.InfluenceOperator`.
    """
    n_rows, n_cols = shape
    n, t = np.arange(n_rows)[:, None], np.arange(n_cols + 1)[None, :]
    table = template((2 * t + n % 2) / 2.0, n * (math.sqrt(3.0) / 2))
    table *= step / (math.pi * E_star)
    return table
