"""Stresses of a pyramid pressure on a periodic cell of the triangular lattice from per-mode transfer functions.

A pressure ``p = sum_m p_m pyr(x - x_m)`` on a cell of ``n_cols x n_rows`` nodes (lattice units, step
1; the layout of :class:`bem.periodic.PeriodicCell`, area ``A = n_cols n_rows sqrt3/2``) has the
Fourier coefficients ``p_G = hat(G) D(G) / A`` on the reciprocal lattice of the cell, ``hat`` the
pyramid's transform (:func:`bem.periodic.kernel.pyramid_transform`) and ``D(G) = sum_m p_m
exp(-i G.x_m)`` periodic over the reciprocal lattice of the nodes. A linear field with the transfer
function ``T(G)`` (the stress component of the unit mode ``exp(i G.x)``) is, at the nodes, ::

    sigma(x_n) = sum_G p_G T(G) exp(i G.x_n),

every ``G`` and its aliases folded onto the cell's discrete modes: with the nodes split by row
parity ``s`` (two rectangular lattices of ``n_rows/2 x n_cols``), ``D`` is the sum of the parities'
2-D FFTs times the phases ``exp(-i pi s (m / n_cols + 2 n / n_rows))`` of ``G = 2 pi (m / Lx,
n / Ly)``, and the folded symbol is a 2 x 2 block per mode (as in :mod:`bem.periodic.influence`).
The sum over ``G`` is cut at ``|G| <= g_cut``; the caller picks ``g_cut`` from the decay of ``T``.

A Fourier mode of wave vector ``G = |G| (cos a, sin a)`` loads the body in plane strain along
``e_s = (cos a, sin a)`` (:mod:`bem.coating_fields`: amplitudes ``Szz, Ssz, Sss, Snn`` of
``P cos(q s)``); rotated into ``x, y`` the unit complex mode ``exp(i G.x)`` gives ::

    T_xx = Sss cos^2 a + Snn sin^2 a,   T_yy = Sss sin^2 a + Snn cos^2 a,   T_xy = (Sss - Snn) cos a sin a,
    T_zz = Szz,   T_xz = -i Ssz cos a,   T_yz = -i Ssz sin a

(``sin(q s) = Re(-i exp(i q s))``; ``sigma_nz = 0``).
"""

from __future__ import annotations

import math

import numpy as np

from .periodic.kernel import pyramid_transform

__all__ = ["mode_stress", "rotated_modes"]

_SQRT3 = math.sqrt(3.0)
_BLOCK = 1 << 20  # terms of the sum over G per block


def rotated_modes(S, cos_a, sin_a):
    """The six Voigt transfer functions ``xx, yy, zz, yz, xz, xy`` of the modes (module docstring).

    ``S`` maps ``Szz, Ssz, Sss, Snn`` to arrays like ``cos_a``; returns complex ``(6, ...)``.
    """
    c2, s2, cs = cos_a * cos_a, sin_a * sin_a, cos_a * sin_a
    sss, snn, ssz = S["Sss"], S["Snn"], S["Ssz"]
    return np.stack([sss * c2 + snn * s2, sss * s2 + snn * c2, S["Szz"] + 0j, -1j * ssz * sin_a,
                     -1j * ssz * cos_a, (sss - snn) * cs + 0j])


def mode_stress(grid, radial, g_cut, *, zero=None):
    """The six stress components at the nodes of a cell under the pyramid pressure ``grid``.

    Parameters
    ----------
    grid : ndarray, shape (n_rows, n_cols)
        Nodal pressures [pressure], brick layout of :class:`bem.periodic.PeriodicCell` (``n_rows``
        even).
    radial : callable
        ``radial(k)`` -> dict of ``Szz, Ssz, Sss, Snn`` [-] at the wavenumbers ``k > 0`` [1/step]
        (1-D array), each of ``k``'s shape.
    g_cut : float
        Largest ``|G|`` summed [1/step].
    zero : array_like, shape (6,), optional
        The Voigt field of the uniform unit pressure (the mode ``G = 0``); default none (zero).

    Returns
    -------
    ndarray, shape (6, n_rows, n_cols)
        Voigt ``xx, yy, zz, yz, xz, xy`` [pressure] at the nodes.
    """
    import scipy.fft as sfft

    from . import fft

    n_rows, n_cols = grid.shape
    half = n_rows // 2
    lx, ly = float(n_cols), n_rows * _SQRT3 / 2
    m_max, n_max = int(g_cut * lx / (2 * math.pi)) + 1, int(g_cut * ly / (2 * math.pi)) + 1
    m = np.arange(-m_max, m_max + 1)
    gx = 2 * math.pi * m / lx
    # the radial functions on the quarter |m|, |n| (they depend on |G| only)
    ma, na = np.arange(m_max + 1), np.arange(n_max + 1)
    kq = np.hypot(2 * math.pi * ma[None, :] / lx, 2 * math.pi * na[:, None] / ly)
    inside = (kq <= g_cut) & (kq > 0)
    table = {name: np.zeros(kq.shape) for name in ("Szz", "Ssz", "Sss", "Snn")}
    if inside.any():
        values = radial(kq[inside])
        for name in table:
            table[name][inside] = values[name]
    sym = np.zeros((3, 6, half * n_cols), dtype=complex)  # S_00 (= S_11), S_10, S_01
    rows_per_block = max(1, _BLOCK // m.size)
    for n0 in range(-n_max, n_max + 1, rows_per_block):
        n = np.arange(n0, min(n0 + rows_per_block, n_max + 1))
        gy = 2 * math.pi * n / ly
        k = np.hypot(gx[None, :], gy[:, None])
        rr, cc = np.nonzero((k <= g_cut) & (k > 0))
        kk = k[rr, cc]
        S = {name: t[np.abs(n[rr]), np.abs(m[cc])] for name, t in table.items()}
        w = rotated_modes(S, gx[cc] / kk, gy[rr] / kk) * pyramid_transform(gx[cc], gy[rr])
        phase = np.exp(1j * math.pi * (m[cc] / n_cols + 2 * n[rr] / n_rows))
        index = np.mod(n[rr], half) * n_cols + np.mod(m[cc], n_cols)
        for b, factor in enumerate((1.0, phase, np.conj(phase))):
            wb = w * factor
            for comp in range(6):
                sym[b, comp].real += np.bincount(index, weights=wb[comp].real, minlength=half * n_cols)
                sym[b, comp].imag += np.bincount(index, weights=wb[comp].imag, minlength=half * n_cols)
    if zero is not None:  # G = 0: hat(0) = sqrt3/2, phase 1
        sym[:, :, 0] += (_SQRT3 / 2) * np.asarray(zero, dtype=float)[None, :]
    workers = fft.threads()
    spectra = sfft.fft2(np.stack([grid[0::2], grid[1::2]]), axes=(-2, -1), workers=workers)
    f0, f1 = (s.reshape(-1) for s in spectra)
    out = np.empty((6, n_rows, n_cols))
    scale = half * n_cols / (lx * ly)
    s00, s10, s01 = sym
    for parity, (a, b) in enumerate(((s00, s01), (s10, s00))):  # out_s' = S_s'0 F_0 + S_s'1 F_1
        mixed = (a * f0 + b * f1).reshape(6, half, n_cols)
        out[:, parity::2] = sfft.ifft2(mixed, axes=(-2, -1), workers=workers).real * scale
    return out
