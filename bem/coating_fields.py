"""The field inside a coated body under one Fourier mode of surface pressure, and under an axisymmetric pressure.

Under the pressure mode ``p = P cos(q s)`` on the free surface (``s`` along the wave vector, ``z``
the depth) a coated body (:class:`bem.Coating` of thickness ``t`` bonded to the body's substrate)
deforms in plane strain in ``(s, z)`` (docs/method.md, section 7): ::

    u_s = U(z) sin(q s),      u_z = W(z) cos(q s),
    sigma_zz = Szz(z) cos(q s),   sigma_sz = Ssz(z) sin(q s),
    sigma_ss = Sss(z) cos(q s),   sigma_nn = Snn(z) cos(q s)  (along the crests, ``eps_nn = 0``)

with, in each material (Lame constants ``lam``, ``mu``), ``Szz = lam (q U + W') + 2 mu W'``,
``Ssz = mu (U' - q W)``, ``Sss = lam (q U + W') + 2 mu q U``, ``Snn = lam (q U + W')``. Each material's
``(U, W)`` is a combination of the four solutions of Navier's equations ::

    (U, W) = (1, s) e^(-s q z),   (q z, s q z + k) e^(-s q z),   s = +1, -1,   k = 3 - 4 nu,

two in the substrate (``s = +1``, decaying with depth, written from the interface), four in the
coating. :func:`mode_fields` finds the six amplitudes per mode from the surface conditions
``Szz(0) = -P``, ``Ssz(0) = 0`` and the continuity of ``U, W, Ssz, Szz`` at ``z = t`` (a rigid
substrate: ``U = W = 0`` there). In the coating the growing pair is written from the interface
(``e^(q (z - t))``) where ``q t >= 1``, so that no exponential exceeds 1 and nothing overflows at any
``q t``; below, from the surface, where the two pairs stay distinct. The displacement of the
surface equals :func:`bem.coating.mode_compliance`'s ``2 s(q) / q`` (a test, to 1e-12).

:func:`axisymmetric_stress` sums the modes of an axisymmetric pressure ``p(r)`` by its Hankel
transform: the stresses at given radii and depths, in the coating and in the substrate, and at the
interface from both sides (the traction is continuous there, ``sigma_rr`` and ``sigma_tt`` jump).
"""

from __future__ import annotations

import math

import numpy as np

from .checks import check_range, check_scale
from .coating import Coating
from .materials import NU_MAX, NU_MIN

__all__ = ["mode_fields", "axisymmetric_stress", "von_mises"]

FIELDS = ("U", "W", "Szz", "Ssz", "Sss", "Snn")


def _lame(E, nu):
    """Lame's ``lam, mu`` [pressure] (``nu < 0.5``: :func:`_check` refuses an incompressible material)."""
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def _basis(q, z, s, k, z0):
    """The two solutions of sign ``s`` written from ``z0``: ``U, U', W, W'`` of each, arrays ``(2, 4, ...)``."""
    zeta = q * (z - z0)
    e = np.exp(-s * zeta)
    one = np.ones_like(zeta)
    # (U, W) = (1, s) e^(-s zeta) and (zeta, s zeta + k) e^(-s zeta); d/dz = q d/dzeta
    first = np.stack([one * e, -s * q * e, s * one * e, -q * e])
    second = np.stack([zeta * e, q * (1 - s * zeta) * e, (s * zeta + k) * e, q * (s - s * (s * zeta + k)) * e])
    return np.stack([first, second])


def _stresses(q, parts, lam, mu):
    """``Szz, Ssz, Sss, Snn`` of ``(U, U', W, W')`` in a material of Lame constants ``lam``, ``mu``."""
    U, dU, W, dW = parts
    div = q * U + dW
    return np.stack([lam * div + 2 * mu * dW, mu * (dU - q * W), lam * div + 2 * mu * q * U, lam * div])


def _check(coating, E_substrate, nu_substrate):
    if not isinstance(coating, Coating):
        raise ValueError(f"coating = {coating!r} is not allowed: it must be a bem.Coating")
    nu_s = check_range("nu_substrate", nu_substrate, NU_MIN, NU_MAX, low_open=True)
    rigid = isinstance(E_substrate, (int, float)) and E_substrate == math.inf
    E_s = math.inf if rigid else check_scale("E_substrate", E_substrate)
    for name, nu in (("coating.nu", coating.nu), ("nu_substrate", nu_s)):
        if nu >= 0.5:
            raise ValueError(f"{name} = {nu!r} is not allowed here: the field inside needs nu < 0.5 (an "
                             "incompressible material's stresses need its pressure as an unknown)")
    return E_s, nu_s


def mode_fields(q, z, coating, E_substrate, nu_substrate, *, side="coating"):
    """The field of the pressure mode ``P cos(q s)``, ``P = 1``, at depths ``z`` in a coated body.

    Parameters
    ----------
    q : array_like
        Wavenumbers [1/length], ``> 0``; 1-D.
    z : array_like
        Depths below the surface [length], ``>= 0``; 1-D. ``z < t`` lies in the coating, ``z > t`` in
        the substrate; ``z = t`` on the side named by ``side``.
    coating : bem.Coating
        The coating (``t``, ``E_c``, ``nu_c``; ``nu_c < 0.5``).
    E_substrate, nu_substrate : float
        The substrate's Young's modulus [pressure] (``math.inf``: rigid) and Poisson's ratio [-].
    side : {"coating", "substrate"}
        The material whose stresses are given at ``z = t`` exactly.

    Returns
    -------
    dict of numpy.ndarray
        ``U``, ``W`` [length/pressure] and ``Szz``, ``Ssz``, ``Sss``, ``Snn`` [-], each of shape
        ``(len(q), len(z))`` (the amplitudes defined in the module docstring).
    """
    E_s, nu_s = _check(coating, E_substrate, nu_substrate)
    if side not in ("coating", "substrate"):
        raise ValueError(f"side = {side!r} is not allowed: it must be 'coating' or 'substrate'")
    q = np.asarray(q, dtype=float).reshape(-1)
    z = np.asarray(z, dtype=float).reshape(-1)
    if not (np.all(q > 0) and np.all(np.isfinite(q))):
        raise ValueError("q must be finite and > 0")
    if not (np.all(z >= 0) and np.all(np.isfinite(z))):
        raise ValueError("z must be finite and >= 0")
    t = coating.thickness
    lam_c, mu_c = _lame(coating.E, coating.nu)
    k_c = 3 - 4 * coating.nu
    rigid = math.isinf(E_s)
    lam_s, mu_s = (None, None) if rigid else _lame(E_s, nu_s)
    k_s = 3 - 4 * nu_s
    thick = q * t >= 1.0  # the growing pair written from the interface
    z0_grow = np.where(thick, t, 0.0)

    def coating_parts(zz):  # (4 solutions, 4 of U U' W W', n_q) at the depths zz (one per q)
        decay = _basis(q, zz, 1.0, k_c, 0.0)
        grow = _basis(q, zz, -1.0, k_c, z0_grow)
        return np.concatenate([decay, grow])

    def state(parts, lam, mu):  # (U, W, Ssz, Szz) of each solution
        s = _stresses(q, parts.transpose(1, 0, 2), lam, mu)  # (4 stresses, n_sol, n_q)
        return np.stack([parts[:, 0], parts[:, 2], s[1], s[0]], axis=1)  # (n_sol, 4, n_q)

    top = state(coating_parts(np.zeros_like(q)), lam_c, mu_c)
    bottom = state(coating_parts(np.full_like(q, t)), lam_c, mu_c)
    n = q.size
    # rows: Szz(0) = -1, Ssz(0) = 0 (scaled by 1/mu_c), then the interface conditions
    scale = np.stack([q, q, np.full_like(q, 1.0 / mu_c), np.full_like(q, 1.0 / mu_c)])  # (4 rows, n_q)
    if rigid:
        A = np.zeros((n, 4, 4))
        b = np.zeros((n, 4))
        A[:, 0, :] = (top[:, 3] / mu_c).T
        A[:, 1, :] = (top[:, 2] / mu_c).T
        A[:, 2, :] = bottom[:, 0].T * q[:, None]
        A[:, 3, :] = bottom[:, 1].T * q[:, None]
        b[:, 0] = -1.0 / mu_c
    else:
        sub = state(_basis(q, np.full_like(q, t), 1.0, k_s, t), lam_s, mu_s)  # (2, 4, n_q)
        A = np.zeros((n, 6, 6))
        b = np.zeros((n, 6))
        A[:, 0, :4] = (top[:, 3] / mu_c).T
        A[:, 1, :4] = (top[:, 2] / mu_c).T
        rows = bottom * scale[None]  # (4 solutions, 4 rows, n_q)
        subr = sub * scale[None]
        A[:, 2:, :4] = rows.transpose(2, 1, 0)
        A[:, 2:, 4:] = -subr.transpose(2, 1, 0)
        b[:, 0] = -1.0 / mu_c
    amp = np.linalg.solve(A, b[..., None])[..., 0]  # (n_q, 6 or 4)
    out = {name: np.empty((n, z.size)) for name in FIELDS}
    in_coating = (z < t) | ((z == t) & (side == "coating"))
    for j, zj in enumerate(z):
        zz = np.full_like(q, zj)
        if in_coating[j]:
            parts = coating_parts(zz)  # (4, 4, n_q)
            a = amp[:, :4].T
            lam, mu = lam_c, mu_c
        elif rigid:
            for name in FIELDS:
                out[name][:, j] = 0.0 if name in ("U", "W") else np.nan
            continue
        else:
            parts = _basis(q, zz, 1.0, k_s, t)
            a = amp[:, 4:].T
            lam, mu = lam_s, mu_s
        field = np.einsum("sn,skn->kn", a, parts)  # U U' W W'
        S = _stresses(q, field, lam, mu)
        for name, value in zip(FIELDS, (field[0], field[2], S[0], S[1], S[2], S[3])):
            out[name][:, j] = value
    return out


def axisymmetric_stress(p, r_max, r, z, coating, E_substrate, nu_substrate, *, side="coating", n_q=4096,
                        q_max=None):
    """Stresses inside a coated body under an axisymmetric surface pressure ``p(r)`` [pressure].

    Parameters
    ----------
    p : callable
        ``p(r)`` [pressure], vectorised, zero beyond ``r_max``.
    r_max : float
        Radius of the loaded disc [length].
    r, z : array_like
        Radii [length] and depths [length] of the points (1-D each; a grid ``(len(r), len(z))``).
    coating, E_substrate, nu_substrate
        As for :func:`mode_fields`.
    side : {"coating", "substrate"}
        The material at ``z = t``.
    n_q : int
        Wavenumber nodes of the Hankel integrals (Gauss-Legendre on panels).
    q_max : float, optional
        Upper wavenumber [1/length]; default ``400 / min(r_max, positive z)``.

    Returns
    -------
    dict of numpy.ndarray
        ``szz``, ``srz``, ``srr``, ``stt`` [pressure] and ``uz`` [length] at the points, shape
        ``(len(r), len(z))``: e.g. ``sigma_zz = int P(q) Szz(q, z) J0(q r) q dq`` with ``P(q)`` the
        Hankel transform of ``p`` (Gauss-Legendre panels graded towards ``r_max``); compression is
        negative. The Hankel integrals converge for ``z > 0``: at the surface itself use ``p``. The radial
        panels are no wider than the shallowest depth; the wavenumber panels are geometric, which resolves
        the oscillation of ``P(q)`` (period ``2 pi / r_max``) up to ``q ~ 1/z`` less well the shallower the
        point (Hertz on the axis with ``n_q = 2048``: 2.4e-5 at ``z = r_max/50``, 1.7e-3 at ``r_max/100``;
        with the default ``n_q``, 2.6e-3 at ``r_max/400``): shallower points need a larger ``n_q``.
    """
    from scipy.special import j0, j1

    r = np.asarray(r, dtype=float).reshape(-1)
    z = np.asarray(z, dtype=float).reshape(-1)
    # the Hankel transform P(q) = int_0^r_max p(r) J0(q r) r dr
    xg, wg = np.polynomial.legendre.leggauss(16)
    depth = z[z > 0].min() if np.any(z > 0) else r_max
    # panels no wider than the shallowest depth (P(q) is needed up to q ~ 1/depth) and graded geometrically
    # towards r_max, where a contact pressure has its square-root edge
    uniform = np.linspace(0.0, 1.0, max(32, math.ceil(r_max / depth)) + 1)
    edges = r_max * np.unique(np.concatenate([uniform, 1.0 - 0.5 ** np.arange(1, 41)]))
    rr = (0.5 * (edges[1:] - edges[:-1])[:, None] * (xg + 1) + edges[:-1, None]).ravel()
    wr = (0.5 * (edges[1:] - edges[:-1])[:, None] * wg).ravel()
    top = q_max if q_max is not None else 400.0 / min(r_max, depth)
    qe = np.concatenate([[0.0], np.geomspace(1e-3 / r_max, top, n_q // 16)])
    qq = (0.5 * (qe[1:] - qe[:-1])[:, None] * (xg + 1) + qe[:-1, None]).ravel()
    wq = (0.5 * (qe[1:] - qe[:-1])[:, None] * wg).ravel()
    load = p(rr) * rr * wr
    chunk = max(1, 2**22 // rr.size)  # rows of J0(q r) at a time: at most 4M entries
    P = np.concatenate([j0(np.outer(qq[i:i + chunk], rr)) @ load for i in range(0, qq.size, chunk)])
    f = mode_fields(qq, z, coating, E_substrate, nu_substrate, side=side)
    w = (P * qq * wq)[:, None, None]
    qr = np.outer(qq, r)[:, :, None]  # (n_q, n_r, 1)
    J0, J1 = j0(qr), j1(qr)
    J1x = np.where(qr > 0, J1 / np.where(qr > 0, qr, 1.0), 0.5)
    Sss, Snn = f["Sss"][:, None, :], f["Snn"][:, None, :]
    # a mode cos(q.x) summed over directions: sigma_rr takes Sss along the radius, Snn across it
    out = {
        "szz": np.sum(w * f["Szz"][:, None, :] * J0, axis=0),
        "srz": np.sum(w * f["Ssz"][:, None, :] * J1, axis=0),
        "srr": np.sum(w * (Sss * (J0 - J1x) + Snn * J1x), axis=0),
        "stt": np.sum(w * (Sss * J1x + Snn * (J0 - J1x)), axis=0),
        "uz": np.sum(w * f["W"][:, None, :] * J0, axis=0),
    }
    return out


def von_mises(srr, stt, szz, srz):
    """The von Mises stress of an axisymmetric state [pressure]."""
    return np.sqrt(0.5 * ((srr - stt) ** 2 + (stt - szz) ** 2 + (szz - srr) ** 2) + 3.0 * srz ** 2)
