"""Stresses in an elastic half-space under a normal point load and under one pressure pyramid.

Lattice units throughout: lengths in lattice steps ``c``, the pyramid of unit height on the
unit hexagon of :mod:`bem.template`. The stresses are per unit load (point load) or per unit
nodal pressure (pyramid), tension positive, Voigt order ``xx, yy, zz, yz, xz, xy``; ``z >= 0``
is the depth below the loaded surface and ``(x, y)`` the horizontal offset of the field point
from the load. Stresses are homogeneous of degree -2 in length, so the pyramid's stresses are
the same for every step ``c`` at the same ``(x, y, z) / c``.

Point load (Boussinesq; Johnson 1985, *Contact Mechanics*, section 3.2,
doi:10.1017/CBO9781139171731; Love 1929, doi:10.1098/rsta.1929.0009), ``r^2 = x^2 + y^2``,
``rho^2 = r^2 + z^2``, unit force pressing on the surface::

    sigma_r + sigma_t = ((1 - 2 nu) z / rho^3 - 3 z r^2 / rho^5) / (2 pi)
    (sigma_r - sigma_t) / r^2 = B = ((1 - 2 nu) (2 rho + z) / (rho^3 (rho + z)^2) - 3 z / rho^5) / (2 pi)
    sigma_zz = -3 z^3 / (2 pi rho^5),  sigma_rz = -3 r z^2 / (2 pi rho^5)

so ``sigma_xx, sigma_yy = S +- B (x^2 - y^2) / 2``, ``sigma_xy = B x y``, ``sigma_xz = -3 x z^2 /
(2 pi rho^5)``, ``sigma_yz = -3 y z^2 / (2 pi rho^5)`` with ``S = (sigma_r + sigma_t) / 2``; the
form of ``B`` (from ``(1 - z/rho)/r^2 = 1/(rho (rho + z))``) has no ``0/0`` on the axis.

Pyramid, near the load (:func:`pyramid_stress_exact`): on each of the six triangles the
pressure is linear, ``a + b s`` along a ray from the field point's projection ``P``
(``s`` the distance from ``P``, ``a`` the triangle's linear function at ``P``, ``b`` its slope
along the ray). A triangle is the signed sum of the three triangles (``P``, edge); in polar
coordinates about ``P`` the radial integrals ``int_0^R (a + b s) s f(s) ds`` of every kernel
function ``f`` are elementary (:func:`_radial`), and the angle is integrated numerically
along each edge with the substitution ``u = |h| sinh t`` (``u`` the position along the edge
from the foot of the perpendicular, ``h`` the distance of ``P`` from the edge line), which
turns ``dtheta = h du / (h^2 + u^2)`` into ``dt / cosh t``: a smooth integrand, Gauss-Legendre
with :data:`N_ANGLE` points per edge. Edges whose line passes through ``P`` contribute
nothing. Offsets of lattice nodes lie on an edge line or at least ``sqrt(3)/2`` from it, which
keeps the angular integrand smooth at every depth, ``z = 0`` included; the constant
``-2 ln(2 z)`` of one radial integral multiplies ``cos 2 theta`` or ``sin 2 theta`` and
integrates to zero over the closed hexagon (where the pyramid is continuous), so it is left out,
which keeps the limit ``z -> 0`` finite.

Pyramid, far from the load (:func:`pyramid_stress`): a lattice stencil of point loads,
``V sum_j w_j G(d - x_j)`` (``V = sqrt(3)/2`` the pyramid volume, ``x_j`` the lattice nodes
with ``|x_j|^2 in {0, 1, 3, 4, 7, 9, 12}``, one weight per shell) whose weights reproduce the
pyramid's moments of every polynomial up to degree 8 (:data:`STENCIL`), so the error is
``O(|d|^-10)`` relative: below 4e-10 of the local stress beyond :data:`R_NEAR` = 16 steps
(``|d|^2 + z^2 >= R_NEAR^2``). Because the stencil sits on lattice nodes, the far field of a
pressure distribution is the point-load kernel convolved with the stencil-filtered pressures.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

__all__ = ["point_load_stress", "pyramid_stress_exact", "pyramid_stress", "far_stress", "stencil", "filter_pressure",
           "point_load_quadrants", "near_correction", "R_NEAR", "N_ANGLE", "VOLUME", "PARITY"]

R_NEAR = 16.0
"""Distance [lattice steps], ``sqrt(r^2 + z^2)``, below which the pyramid is integrated exactly."""
N_ANGLE = 16
"""Gauss-Legendre points per triangle edge of the angular integral."""
VOLUME = math.sqrt(3.0) / 2
"""Volume of the unit pyramid [lattice steps^2]."""
#: (odd in x, odd in y) of each Voigt component xx, yy, zz, yz, xz, xy
PARITY = ((False, False), (False, False), (False, False), (False, True), (True, False), (True, True))

_SQRT3 = math.sqrt(3.0)
_VERTS = np.array([(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)) for k in range(7)])
_VERTS[6] = _VERTS[0]


def point_load_stress(x, y, z, nu):
    """Stresses of a unit normal point load on the half-space (Boussinesq), Voigt order, tension positive.

    Parameters
    ----------
    x, y : array_like
        Horizontal offset of the field point from the load [length], broadcastable.
    z : float or array_like
        Depth [length], ``> 0`` (at ``z = 0`` only ``r > 0`` is finite).
    nu : float
        Poisson's ratio.

    Returns
    -------
    ndarray, shape (..., 6)
        ``xx, yy, zz, yz, xz, xy`` [1/length^2] for a unit force.
    """
    return np.moveaxis(_point_load_components(x, y, z, nu), 0, -1)


def _point_load_components(x, y, z, nu):
    """:func:`point_load_stress` with the components first: shape (6, ...), contiguous."""
    x, y, z = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float), np.asarray(z, float))
    out = np.empty((6,) + x.shape)
    r2 = x * x + y * y
    rho2 = r2 + z * z
    rho = np.sqrt(rho2)
    inv3 = 1.0 / (rho2 * rho)
    inv5 = inv3 / rho2
    k = 1.0 - 2.0 * nu
    s = (k * z * inv3 - 3.0 * z * r2 * inv5) / (4.0 * math.pi)
    b = (k * (2.0 * rho + z) * inv3 / (rho + z) ** 2 - 3.0 * z * inv5) / (2.0 * math.pi)
    d = 0.5 * (x * x - y * y) * b
    shear = -3.0 * z * z * inv5 / (2.0 * math.pi)
    np.add(s, d, out=out[0, ...])
    np.subtract(s, d, out=out[1, ...])
    np.multiply(shear, z, out=out[2, ...])
    np.multiply(shear, y, out=out[3, ...])
    np.multiply(shear, x, out=out[4, ...])
    np.multiply(b * x, y, out=out[5, ...])
    return out


def _radial(R, z):
    """``int_0^R s f ds`` and ``int_0^R s^2 f ds`` of the five radial kernel functions.

    ``a = z/rho^3``, ``b = z s^2/rho^5``, ``c = z^3/rho^5``, ``d = z^2 s/rho^5``,
    ``e = 2/(rho (rho + z)) - z/rho^3`` (``rho^2 = s^2 + z^2``); for ``e`` the constant
    ``-2 ln(2 z)`` of the first moment is left out (see the module docstring).
    """
    rho = np.sqrt(R * R + z * z)
    zr = z / rho
    zr3 = zr**3
    ash = z * np.arcsinh(R / z) if z > 0 else np.zeros_like(R)
    r_rho = R / rho
    return {
        "a": (1.0 - zr, ash - z * r_rho),
        "b": (2.0 / 3.0 - zr + zr3 / 3.0,
              ash - 2.0 * z * r_rho + z * r_rho * (2.0 * R * R + 3.0 * z * z) / (3.0 * rho * rho)),
        "c": ((1.0 - zr3) / 3.0, z * r_rho**3 / 3.0),
        "d": (r_rho**3 / 3.0, 2.0 * z / 3.0 - z * zr + z * zr3 / 3.0),
        "e": (2.0 * np.log(rho + z) - 1.0 + zr, 2.0 * R - 3.0 * ash + z * r_rho),
    }


@lru_cache(maxsize=4)
def _gauss(n):
    t, w = np.polynomial.legendre.leggauss(n)
    return t, w


def _edge(px, py, a, grad, start, end, z, nu):
    """Signed contribution of the triangle (P, start, end) for a linear load ``a + grad.(xi - P)``."""
    t0, w0 = _gauss(N_ANGLE)
    ex, ey = end[0] - start[0], end[1] - start[1]
    length = math.hypot(ex, ey)
    ex, ey = ex / length, ey / length
    ax, ay = start[0] - px, start[1] - py
    h = ax * ey - ay * ex
    u_a = ax * ex + ay * ey
    ok = np.abs(h) > 1e-12
    hh = np.where(ok, np.abs(h), 1.0)
    ta = np.arcsinh(u_a / hh)
    tb = np.arcsinh((u_a + length) / hh)
    t = 0.5 * (ta[:, None] * (1.0 - t0) + tb[:, None] * (1.0 + t0))
    ch, sh = np.cosh(t), np.sinh(t)
    mx = ((ax - u_a * ex) / hh)[:, None]
    my = ((ay - u_a * ey) / hh)[:, None]
    wx = (mx + sh * ex) / ch  # direction of the ray from P
    wy = (my + sh * ey) / ch
    J = _radial(hh[:, None] * ch, z)
    b = grad[0] * wx + grad[1] * wy
    a = a[:, None]

    def mom(key):
        return a * J[key][0] + b * J[key][1]

    k = 1.0 - 2.0 * nu
    mb = mom("b")
    s = (k * mom("a") - 3.0 * mb) / (4.0 * math.pi)
    bb = (k * mom("e") - 3.0 * mb) / (2.0 * math.pi)
    c2 = 0.5 * bb * (wx * wx - wy * wy)
    dd = 3.0 * mom("d") / (2.0 * math.pi)
    comp = np.stack([s + c2, s - c2, -3.0 * mom("c") / (2.0 * math.pi), dd * wy, dd * wx, bb * wx * wy])
    weight = np.where(ok, np.sign(h), 0.0)[:, None] * (0.5 * (tb - ta))[:, None] * w0 / ch
    return np.einsum("mn,cmn->mc", weight, comp)


def pyramid_stress_exact(x, y, z, nu):
    """Stresses under the unit pyramid by semi-analytic integration (module docstring), lattice units.

    Parameters
    ----------
    x, y : array_like
        Offsets of the field points from the pyramid's centre [lattice steps]; accurate to
        about 1e-14 (relative) at lattice-node offsets (tested against adaptive quadrature).
    z : float
        Depth [lattice steps], ``>= 0``.
    nu : float
        Poisson's ratio.

    Returns
    -------
    ndarray, shape (..., 6)
        Stress per unit nodal pressure (dimensionless), Voigt order, tension positive.
    """
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    shape = x.shape
    px, py = x.ravel(), y.ravel()
    out = np.zeros((px.size, 6))
    for k in range(6):
        v1, v2 = _VERTS[k], _VERTS[k + 1]
        normal = 0.5 * (v1 + v2) / math.hypot(*(0.5 * (v1 + v2)))
        grad = -(2.0 / _SQRT3) * normal
        a = 1.0 + grad[0] * px + grad[1] * py
        origin = np.zeros(2)
        for start, end in ((origin, v1), (v1, v2), (v2, origin)):
            out += _edge(px, py, a, grad, start, end, float(z), nu)
    return out.reshape(shape + (6,))


def _invariants(x, y, degree):
    """The D6-invariant polynomials ``r^(2n) Re((x + i y)^(6m))`` up to ``degree``, stacked."""
    zeta = x + 1j * y
    r2 = x * x + y * y
    return np.array([r2 ** ((d - 6 * m) // 2) * np.real(zeta ** (6 * m))
                     for d in range(0, degree + 1, 2) for m in range(d // 6 + 1)])


@lru_cache(maxsize=1)
def stencil():
    """The far-field stencil: sheared lattice offsets ``(i, j)`` (node ``i e1 + j e2``), positions and weights.

    The weights (one per shell ``i^2 + i j + j^2`` in {0, 1, 3, 4, 7, 9, 12}) solve
    ``sum_j w_j q(x_j) = int pyr q dA / V`` for the seven D6-invariant polynomials ``q`` of
    degree <= 8 (the moments by a Gauss rule exact for these polynomials); the non-invariant
    moments match by symmetry. ``sum w = 1``.

    Returns
    -------
    (i, j, x, y, w) : ndarrays of shape (43,)
    """
    degree = 8
    t, wt = _gauss(degree // 2 + 4)
    t, wt = 0.5 * (t + 1.0), 0.5 * wt
    u, v = np.meshgrid(t, t, indexing="ij")
    weight = np.outer(wt, wt) * (1.0 - u) * u * VOLUME  # (1 - u): the pyramid; 2 area u = (sqrt(3)/2) u: the Jacobian
    moments = 0.0
    for k in range(6):
        v1, v2 = _VERTS[k], _VERTS[k + 1]
        xi = u * (v1[0] + v * (v2[0] - v1[0]))
        eta = u * (v1[1] + v * (v2[1] - v1[1]))
        moments = moments + (_invariants(xi, eta, degree) * weight).sum(axis=(1, 2))
    moments = moments / VOLUME
    i, j = (a.ravel() for a in np.meshgrid(np.arange(-4, 5), np.arange(-4, 5), indexing="ij"))
    n2 = i * i + i * j + j * j
    shells = (0, 1, 3, 4, 7, 9, 12)
    keep = np.isin(n2, shells)
    i, j, n2 = i[keep], j[keep], n2[keep]
    x, y = i + 0.5 * j, 0.5 * _SQRT3 * j
    values = _invariants(x, y, degree)
    matrix = np.array([values[:, n2 == s].sum(axis=1) for s in shells]).T
    w_shell = np.linalg.solve(matrix, moments)
    w = w_shell[np.searchsorted(shells, n2)]
    return i, j, x, y, w


def far_stress(x, y, z, nu):
    """``V sum_j w_j G(d - x_j)``: the stencil's stresses, shape (..., 6) (lattice units)."""
    _, _, sx, sy, w = stencil()
    x = np.asarray(x, float)[..., None]
    y = np.asarray(y, float)[..., None]
    g = point_load_stress(x - sx, y - sy, z, nu)
    return VOLUME * np.einsum("...jc,j->...c", g, w)


def pyramid_stress(x, y, z, nu):
    """The stress influence of one pyramid as the convolution uses it, lattice units, shape (..., 6).

    Exact (:func:`pyramid_stress_exact`) where ``x^2 + y^2 + z^2 < R_NEAR^2``, the point-load
    stencil (:func:`far_stress`) beyond; within 1e-8 of the local stress magnitude everywhere.
    """
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    out = np.empty(x.shape + (6,))
    near = x * x + y * y + z * z < R_NEAR**2
    if near.any():
        out[near] = pyramid_stress_exact(x[near], y[near], z, nu)
    if (~near).any():
        out[~near] = far_stress(x[~near], y[~near], z, nu)
    return out


def filter_pressure(lattice, p, r0, margin=4):
    """``S * p`` (the stencil of :func:`bem.boussinesq.stencil`) on ``p``'s box grown by ``margin`` (>= 4) each way.

    ``p`` holds the brick rows ``r0..`` (and some columns) of ``lattice``; node ``(r, q)`` takes
    ``w_j p`` from the node at ``r_n - x_j`` (``x_j = i e1 + j e2``): row ``r - j`` and, in the brick
    columns, ``q - i - j/2`` for even ``j`` and ``q - i - (j + 1)/2 + (r's parity)`` for odd ``j``.
    """
    si, sj, _, _, w = stencil()
    nr, nc = p.shape
    m = margin
    out = np.zeros((nr + 2 * m, nc + 2 * m))
    par = (np.arange(r0 - m, r0 + nr + m) - lattice.half_rows) % 2
    rows = [np.flatnonzero(par == a) for a in (0, 1)]
    for i, j, wk in zip(si.tolist(), sj.tolist(), w.tolist()):
        for parity in (0, 1):
            shift = j // 2 if j % 2 == 0 else (j + 1) // 2 - parity
            t = rows[parity]
            src = t - m - j
            ok = (src >= 0) & (src < nr)
            u0 = m + i + shift
            out[t[ok], u0: u0 + nc] += wk * p[src[ok]]
    return out


def point_load_quadrants(offsets, z, nu, spike):
    """``V G_sur`` at the offsets, one (6, ...) array per ``(x, y)`` pair (lattice units).

    ``G_sur`` is the point-load kernel ``G``, except that its zero-offset term is 0 when ``spike``
    (depths below one step, where it grows like ``1/z^2``); :func:`near_correction` with the
    same ``spike`` puts it back exactly.
    """
    out = []
    for ox, oy in offsets:
        with np.errstate(divide="ignore", invalid="ignore"):
            g = _point_load_components(ox, oy, z, nu)
        g *= VOLUME
        if spike:
            g[:, (ox == 0) & (oy == 0)] = 0.0
        out.append(g)
    return out


def near_correction(offsets, z, nu, spike):
    """``C = K - V S * G_sur`` at the offsets nearer than ``R_NEAR`` (0 beyond), one (6, ...) array per offset set.

    ``offsets``: pairs ``(x, y)`` of arrays [lattice steps]; ``G_sur`` is ``G`` without its
    zero-offset term when ``spike`` (see :func:`point_load_quadrants`).
    """
    out = []
    _, _, sx, sy, w = stencil()
    for ox, oy in offsets:
        c = np.zeros((6,) + ox.shape)
        near = ox * ox + oy * oy + z * z < R_NEAR**2
        if near.any():
            px, py = ox[near], oy[near]
            exact = pyramid_stress_exact(px, py, z, nu)
            dx, dy = px[:, None] - sx, py[:, None] - sy
            hit = (dx * dx + dy * dy < 1e-18) if spike else np.zeros(dx.shape, dtype=bool)
            with np.errstate(divide="ignore", invalid="ignore"):
                g = point_load_stress(np.where(hit, 1.0, dx), np.where(hit, 1.0, dy), z, nu)
            g[hit] = 0.0
            c[:, near] = (exact - VOLUME * np.einsum("mjc,j->mc", g, w)).T
        out.append(c)
    return out
