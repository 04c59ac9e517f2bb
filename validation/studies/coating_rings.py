"""An axisymmetric contact on uniform-pressure rings: a sphere on a flat that is coated, or carries a Winkler layer.

The interface ``0 <= r <= L`` is cut into ``n`` rings of equal width ``h = L/n`` carrying uniform
pressures ``p_j``; the relative surface displacement is collocated at the ring mid-radii ``r_i``.
A uniform pressure on the disc ``r < b`` displaces the surfaces of two bodies with the combined
mode compliance ``s(k) = s1(k) + s2(k)`` (:func:`bem.coating.mode_compliance`; the surface sinks by
``2 s(k) / k`` per unit amplitude of the mode ``k``) by the Hankel integral ::

    D(r, b) = b integral_0^inf (2 s(k) / k) J1(k b) J0(k r) dk                         (1)

split into the homogeneous part with ``s_inf = s(k -> inf)`` (the coating's own half-space and the
sphere), in closed form (Johnson, Contact Mechanics, 3.4) ::

    D_inf = 4 s_inf b E(r^2/b^2) / pi                                 r <= b
    D_inf = 4 s_inf r [E(b^2/r^2) - (1 - b^2/r^2) K(b^2/r^2)] / pi     r > b

(``K``, ``E`` the complete elliptic integrals of parameter ``m``), and the rest ``s(k) - s_inf``,
which decays as ``exp(-2 k t)`` and is integrated by 16-point Gauss-Legendre panels no wider than
``1/t`` and ``pi/L`` (a period of the Bessel product) up to ``k t = 30``. A ring is the difference
of two discs. ``delta`` is the approach of points far from the contact (a half-space's).

The contact is the disc of the first ``m`` rings (the gap of a sphere rises with ``r``): for a
given ``m`` the rings' equations ``(C + lam I) p = delta - h`` with ``sum(A p) = P`` are solved
directly, and ``m`` is the largest count whose outermost pressure is ``>= 0`` (bisection: that
pressure falls as ``m`` grows). A Winkler layer ``w = lam p`` adds ``lam`` to the diagonal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["ring_compliance", "RingSolution", "solve_rings", "centre_value"]

_GAUSS = np.polynomial.legendre.leggauss(16)
#: the rest of (1) is integrated up to ``k t = _KT_MAX`` (its size there: ``exp(-2 _KT_MAX)``)
_KT_MAX = 30.0


def _disc_homogeneous(r, b):
    """``D_inf(r, b) / s_inf``: the closed form of (1) for a homogeneous pair [length]."""
    from scipy.special import ellipe, ellipk

    r, b = np.broadcast_arrays(np.asarray(r, float), np.asarray(b, float))
    out = np.zeros(r.shape)
    inside = r <= b
    with np.errstate(divide="ignore", invalid="ignore"):
        m_in = np.where(inside & (b > 0), (r / np.where(b > 0, b, 1.0)) ** 2, 0.0)
        m_out = np.where(~inside, (b / np.where(r > 0, r, 1.0)) ** 2, 0.0)
    out[inside] = 4.0 * b[inside] * ellipe(m_in[inside]) / math.pi
    mo = m_out[~inside]
    out[~inside] = 4.0 * r[~inside] * (ellipe(mo) - (1.0 - mo) * ellipk(mo)) / math.pi
    return out


def _disc_rest(r, b, rest, thickness):
    """``b integral_0^inf (2 rest(k) / k) J1(k b) J0(k r) dk`` for every ``(r_i, b_j)`` [length]."""
    from scipy.special import j0, j1

    k_max = _KT_MAX / thickness
    width = min(1.0 / thickness, math.pi / max(r.max(), b.max()))
    edges = np.linspace(0.0, k_max, int(math.ceil(k_max / width)) + 1)
    half = 0.5 * np.diff(edges)[:, None]
    k = (0.5 * (edges[:-1] + edges[1:])[:, None] + half * _GAUSS[0]).ravel()
    w = (half * _GAUSS[1]).ravel() * 2.0 * rest(k) / k
    return (j0(np.outer(r, k)) * w) @ (b[:, None] * j1(np.outer(b, k))).T


def ring_compliance(L, n, *, E1, nu1, E2, nu2, coating2=None):
    """``(r, edges, C)``: ring mid-radii and edges [length] and the collocation matrix ``C`` [length/pressure].

    ``C[i, j]``: the relative displacement at ``r_i`` under a unit pressure on ring ``j`` of the
    ``n`` rings of width ``L/n``; body 1 homogeneous (``E1, nu1``), body 2 the substrate
    ``E2, nu2`` with the coating ``coating2`` (a :class:`bem.coating.Coating`) or none.
    """
    from bem.coating import mode_compliance

    edges = np.linspace(0.0, L, n + 1)
    r = 0.5 * (edges[:-1] + edges[1:])
    if coating2 is None:
        s_inf = (1 - nu1**2) / E1 + (1 - nu2**2) / E2
    else:
        s_inf = (1 - nu1**2) / E1 + (1 - coating2.nu**2) / coating2.E
    discs = s_inf * _disc_homogeneous(r[:, None], edges[None, 1:])
    if coating2 is not None:
        s2_inf = (1 - coating2.nu**2) / coating2.E
        discs += _disc_rest(r, edges[1:], lambda k: mode_compliance(k, E2, nu2, coating2) - s2_inf,
                            coating2.thickness)
    C = discs.copy()
    C[:, 1:] -= discs[:, :-1]
    return r, edges, C


@dataclass
class RingSolution:
    """A ring solution: ``r`` [length] (mid-radii), ``p`` [pressure] per ring, ``overlap`` ``delta - h - u``
    [length] at ``r``, ``approach`` ``delta`` [length], ``p_max`` (:func:`centre_value`) [pressure],
    ``radius`` (edge of the loaded zone, :func:`fem_reference.result.edge_radius`) [length],
    ``n_contact`` (loaded rings), ``converged`` and ``message`` (``False`` when the contact reaches the
    last ring: the rings are too short)."""

    r: np.ndarray
    p: np.ndarray
    overlap: np.ndarray
    approach: float
    p_max: float
    radius: float
    n_contact: int
    converged: bool
    message: str


def centre_value(r, p):
    """``p(0)`` from the first two rings, ``p ~ p0 + c r^2`` [pressure]."""
    r1, r2 = r[0] ** 2, r[1] ** 2
    return float(max((r2 * p[0] - r1 * p[1]) / (r2 - r1), 0.0))


def _contact(C, area, h, force, lam, m):
    """``(p, delta)`` with the first ``m`` rings in contact."""
    A = C[:m, :m] + lam * np.eye(m)
    K = np.zeros((m + 1, m + 1))
    K[:m, :m], K[:m, m], K[m, :m] = A, -1.0, area[:m]
    rhs = np.concatenate([-h[:m], [force]])
    x = np.linalg.solve(K, rhs)
    p = np.zeros(h.size)
    p[:m] = x[:m]
    return p, float(x[m])


def solve_rings(r, edges, C, h, *, force, lam=0.0):
    """The sphere's contact on the rings ``(r, edges, C)`` (:func:`ring_compliance`) under ``force`` [force].

    ``h``: the initial gap at ``r`` [length], rising with ``r``; ``lam``: a Winkler layer
    ``w = lam p`` [length/pressure] (0: none). Returns a :class:`RingSolution`.
    """
    from fem_reference.result import edge_radius

    area = math.pi * (edges[1:] ** 2 - edges[:-1] ** 2)
    lo, hi = 1, r.size  # p_last(lo) >= 0 holds (one ring carries the force)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        p, _ = _contact(C, area, h, force, lam, mid)
        lo, hi = (mid, hi) if p[mid - 1] >= 0 else (lo, mid)
    p_hi, d_hi = _contact(C, area, h, force, lam, hi)
    m = hi if p_hi[hi - 1] >= 0 else lo
    p, delta = _contact(C, area, h, force, lam, m)
    overlap = delta - h - C @ p
    converged = m < r.size
    message = "converged" if converged else f"the contact reaches the last ring (r = {edges[-1]:.4g}): rings too short"
    return RingSolution(r=r, p=p, overlap=overlap, approach=delta, p_max=centre_value(r, p),
                        radius=edge_radius(r, p, overlap, smooth=lam == 0.0), n_contact=m, converged=converged,
                        message=message)
