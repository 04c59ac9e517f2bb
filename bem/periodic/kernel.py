"""The periodic template: the displacement of a pyramid and all its periodic images.

In lattice units (step ``c = 1``) the cell of ``n_cols x n_rows`` nodes has the periods
``Lx = n_cols`` and ``Ly = n_rows sqrt3/2`` and the area ``A = Lx Ly``. The displacement
at the node offset ``x`` due to one unit pyramid and all its images is

    W(x) = sum_L w_t(x + L) - (the mean over the cell)
         = (1/A) sum_{G != 0} (2 pi / |G|) hat(G) exp(i G.x),

``G`` over the reciprocal lattice of the periods, ``w_t`` the template of
:func:`bem.template.template` and ``hat`` the Fourier transform of the unit pyramid,
``hat(k) = (sqrt3/2) prod_j sinc(k.a_j / 2)``, ``a_1 = (1, 0)``, ``a_2 = (1/2, sqrt3/2)``,
``a_3 = a_2 - a_1`` (the pyramid is the three-direction box spline of the lattice).
The image sum diverges like the 2-D sum of ``1/r``; the mean displacement of a periodic
half-space is undetermined, and it is fixed here to zero (the ``G = 0`` term is left out).
The nodal mean is then zero too: ``hat`` vanishes at every nonzero vector of the reciprocal
node lattice (the pyramids are a partition of unity), so no alias of ``G = 0`` survives.

Ewald split
    ``1/r = erf(alpha r)/r + erfc(alpha r)/r``; the first part has the 2-D transform
    ``(2 pi / k) erfc(k / (2 alpha))`` and the second decays like a Gaussian. So

        W = W_F + W_R - sqrt(3 pi) / (alpha A),
        W_F(x) = (1/A) sum_{G != 0} (2 pi / |G|) erfc(|G| / (2 alpha)) hat(G) exp(i G.x),
        W_R(x) = sum_L R(x + L),  R(x) = w_t(x) - int hat(xi) erf(alpha |x - xi|) / |x - xi| dxi,

    the constant being the mean of ``W_R`` (``int R = (sqrt3/2) 2 pi / (alpha sqrt pi)``).
    ``W_F`` is summed over ``|G| <= 12.2 alpha`` (``erfc < 1e-17`` beyond), its terms binned onto
    the cell's discrete Fourier modes (on a cell of more than about 70 columns and 14 rows each
    term falls on a mode of its own) and evaluated at the nodes by two inverse FFTs, one per row
    parity; the operator's spectra are made from the binned terms directly
    (:func:`periodic_spectra`). ``R`` is ``w_t`` minus a smooth integral, computed by 10 x 10-point
    collapsed Gauss rules on the six triangles of the pyramid (the integrand is piecewise linear
    times an entire function, so the rule is exact to round-off), once per orbit of the twelve
    symmetries of the hexagon, and is below ``1e-17`` beyond ``|x| = 1 + 6.1 / alpha``.

Accuracy
    The split parameter ``alpha`` is arbitrary: ``alpha = 0.25, 0.4, 0.6`` agree to 4e-16
    relative to the largest entry (``tests/bem/test_periodic_operator.py``), so both sums are
    exact to round-off, and the accuracy floor is that of :func:`bem.template.template`
    (2e-13 relative). The image sum of ``w_t`` over discs of radius ``R`` (with its quadrupole
    tail added) converges to ``W`` like ``R^-2.5`` (the same test).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

__all__ = ["alias_sum", "parity_spectra", "periodic_spectra", "periodic_template", "pyramid_transform"]

_SQRT3 = math.sqrt(3.0)
# Ewald split [1/lattice step]. The Fourier sum of a cell has about 10 alpha^2 terms per node and
# is summed for every cell; the real-space values depend on alpha only and are computed once.
ALPHA = 0.25
_ERFC_ZERO = 6.1  # erfc(z) < 1e-17 for z > 6.1
_GAUSS = 10  # 8 points already agree across alpha = 0.25 .. 0.6 to 2e-16
_HEX = np.array([(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)) for k in range(7)])


def pyramid_transform(kx, ky):
    """Fourier transform ``int pyr(x) exp(-i k.x) dx`` of the unit pyramid (lattice units)."""
    s1 = kx / 2
    s2 = (kx / 2 + ky * (_SQRT3 / 2)) / 2
    s3 = s2 - s1
    return (_SQRT3 / 2) * np.sinc(s1 / np.pi) * np.sinc(s2 / np.pi) * np.sinc(s3 / np.pi)


def _smooth_part(x, y, alpha):
    """``int pyr(xi) erf(alpha |x - xi|) / |x - xi| dxi`` at the points ``(x, y)`` (1-D arrays)."""
    from scipy.special import erf

    g, wg = np.polynomial.legendre.leggauss(_GAUSS)
    g, wg = (g + 1) / 2, wg / 2
    s, t = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    w = (np.outer(wg, wg).ravel()) * s * (1 - s)  # Jacobian s (times twice the area) and pyr = 1 - s
    out = np.zeros(x.size)
    for k in range(6):
        b, c = _HEX[k], _HEX[k + 1]
        area2 = abs(b[0] * c[1] - b[1] * c[0])
        qx = s * ((1 - t) * b[0] + t * c[0])
        qy = s * ((1 - t) * b[1] + t * c[1])
        for lo in range(0, x.size, 512):
            dx = x[lo:lo + 512, None] - qx[None, :]
            dy = y[lo:lo + 512, None] - qy[None, :]
            rho = np.sqrt(dx * dx + dy * dy)
            safe = np.maximum(rho, 1e-300)
            f = np.where(rho > 1e-8, erf(alpha * safe) / safe, 2 * alpha / math.sqrt(math.pi))
            out[lo:lo + 512] += area2 * (f @ w)
    return out


@lru_cache(maxsize=4)
def _real_space_values(alpha):
    """Lattice vectors ``(i, j)`` with ``|i e1 + j e2| <= 1 + 6.1 / alpha`` and ``R`` there (any cell)."""
    from ..template import template

    r_cut = 1.0 + _ERFC_ZERO / alpha
    j_max = int(r_cut / (_SQRT3 / 2)) + 1
    j = np.arange(-j_max, j_max + 1)
    i = np.arange(-int(r_cut) - j_max, int(r_cut) + j_max + 1)
    jj, ii = np.meshgrid(j, i, indexing="ij")
    vx, vy = ii + jj / 2.0, jj * (_SQRT3 / 2)
    near = vx * vx + vy * vy <= r_cut * r_cut
    vx, vy = vx[near], vy[near]
    first, orbit = _orbits(vx, vy)  # R has the twelve symmetries of the hexagon: once per orbit
    values = template(vx[first], vy[first]) - _smooth_part(vx[first], vy[first], alpha)
    return ii[near], jj[near], values[orbit]


def _orbits(x, y):
    """The lattice vectors ``(x, y)`` grouped by the twelve symmetries of the hexagon (which map the lattice and
    the pyramid onto themselves): ``(first, orbit)``, the index of one vector of each orbit and the orbit of each
    vector (``first[orbit]`` a vector of the same orbit). Each vector is reflected into the sector ``0 <= angle <=
    30`` degrees (about the axes, then the lines at 60 and at 30 degrees), where each orbit has one point."""
    x, y = np.abs(x), np.abs(y)
    for angle in (math.pi / 3, math.pi / 6):  # reflect about the line at angle where the vector lies above it
        c, s = math.cos(2 * angle), math.sin(2 * angle)
        above = y * math.cos(angle) > x * math.sin(angle)
        x, y = np.where(above, x * c + y * s, x), np.where(above, x * s - y * c, y)
    key = np.round(x * 2 ** 20) * 2 ** 22 + np.round(y * 2 ** 20)  # the folded point, to well below a lattice step
    _, first, orbit = np.unique(key, return_index=True, return_inverse=True)
    return first, orbit


def _real_part(n_rows, n_cols, alpha):
    """``W_R`` minus its mean at every node of the cell, brick array ``(n_rows, n_cols)``."""
    ii, jj, values = _real_space_values(alpha)
    out = np.zeros((n_rows, n_cols))
    np.add.at(out, (np.mod(jj, n_rows), np.mod(ii + np.floor_divide(jj, 2), n_cols)), values)
    out -= math.sqrt(3 * math.pi) / (alpha * _area(n_rows, n_cols))
    return out


def _sin_over(x):
    """``sin(x) / x`` (1 at 0), the factor of :func:`pyramid_transform` without ``np.sinc``'s scalings."""
    out = np.sin(x)
    nonzero = x != 0
    np.divide(out, x, out=out, where=nonzero)
    out[~nonzero] = 1.0
    return out


def _fourier_terms(n_rows, n_cols, alpha):
    """The Ewald Fourier part's terms binned onto the cell's modes (:func:`_binned`), ``|G| <= 2 alpha 6.1``."""
    from scipy.special import erfc

    def weight(k):  # twice 2 pi / k erfc(k / (2 alpha)) (sqrt3 / 2)
        return (2 * _SQRT3 * math.pi) / k * erfc(k / (2 * alpha))

    return _binned(n_rows, n_cols, None, 2 * alpha * _ERFC_ZERO, weight, 256)


def _fourier_part(n_rows, n_cols, alpha):
    """``W_F`` at every node of the cell, brick array ``(n_rows, n_cols)``."""
    return _at_nodes(_fourier_terms(n_rows, n_cols, alpha), n_rows, n_cols)


def alias_sum(n_rows, n_cols, radial, g_cut, *, weight=None, block=None):
    """``(1/A) sum_{0 < |G| <= g_cut} f(|G|) hat(G) exp(i G.x)`` at every node of the cell (lattice units).

    Parameters
    ----------
    n_rows, n_cols : int
        Rows (even) and columns of the cell.
    radial : callable
        ``f(k)`` on a 1-D array of wavenumbers ``k > 0`` [1/lattice step], real, vectorised.
    g_cut : float
        Largest ``|G|`` summed [1/lattice step].
    weight : callable, optional
        ``sqrt3 f(k)`` in place of ``radial`` (the Ewald part's own rounding).
    block : int, optional
        Rows of ``G`` per block of the sum (default: about 2^20 terms a block).

    Returns
    -------
    ndarray, shape ``(n_rows, n_cols)``
        The sum at the offset of node ``(q, r)`` from node ``(0, 0)``, brick storage: ``G`` over the
        reciprocal lattice of the periods, each term binned onto the cell's discrete Fourier modes
        (:func:`_binned`) and brought to the nodes by two inverse FFTs, one per row parity.
    """
    return _at_nodes(_binned(n_rows, n_cols, radial, g_cut, weight, block), n_rows, n_cols)


def _at_nodes(sums, n_rows, n_cols):
    """The sum of :func:`alias_sum` at the nodes from its binned terms ``sums`` (consumed)."""
    import scipy.fft as sfft

    from .. import fft

    # W_F(s)[k, q] = (1/A) sum A_s(n0, m0) exp(2 pi i (m0 q / n_cols + n0 k / half))
    nodes = sfft.ifft2(sums, axes=(-2, -1), overwrite_x=True, workers=fft.threads()).real
    nodes *= sums.shape[1] * n_cols / _area(n_rows, n_cols)
    out = np.empty((n_rows, n_cols))
    out[0::2], out[1::2] = nodes[0], nodes[1]
    return out


def _area(n_rows, n_cols):
    """The area of the cell in lattice units, ``Lx Ly``."""
    return n_cols * n_rows * _SQRT3 / 2


def _binned(n_rows, n_cols, radial, g_cut, weight, block):
    """The terms of :func:`alias_sum` binned onto the discrete Fourier modes of each row parity: ``A_s(n0, m0)``,
    complex, shape ``(2, n_rows/2, n_cols)`` (the real part of their inverse DFT is the sum, up to ``1/A``). Where each
    term has a mode of its own the blocks of rows of ``G`` are made on the FFT threads (:func:`bem.fft.in_parts`), each
    block into its own rows of modes: the same numbers as one after the other."""
    half = n_rows // 2
    lx, ly = float(n_cols), n_rows * _SQRT3 / 2
    m_max, n_max = int(g_cut * lx / (2 * math.pi)) + 1, int(g_cut * ly / (2 * math.pi)) + 1
    m = np.arange(-m_max, m_max + 1)
    gx = 2 * math.pi * m / lx
    sinc_x = np.sinc(gx / (2 * math.pi))  # the factor of pyramid_transform that depends on m only
    phase_x = np.exp(1j * math.pi * m / n_cols)
    sums = np.zeros((2, half, n_cols), dtype=complex)
    # the terms of G and -G are complex conjugates (the summand is even in G, the parity phase
    # conjugates), and only the real part of the sum is kept: half the plane (n > 0, or n = 0 and
    # m > 0), counted twice
    block = max(1, 2 ** 20 // m.size) if block is None else block  # rows per block: small temporaries
    starts = range(0, n_max + 1, block)

    def keep_of(n0):  # the block's rows of G, gy, |G| and the terms kept
        n = np.arange(n0, min(n0 + block, n_max + 1))[:, None]
        gy = 2 * math.pi * n / ly
        k = np.sqrt(gx * gx + gy * gy)
        return n, gy, k, (k <= g_cut) & ((n > 0) | (m > 0))

    def distinct_blocks(part):  # the terms on whole blocks of G, 0 where not kept, written onto their own modes
        for n0 in starts[part]:
            n, gy, k, keep = keep_of(n0)
            f = _terms(gx, gy, sinc_x, np.where(keep, k, g_cut), radial, weight)
            f[~keep] = 0.0
            odd = f * (phase_x * np.exp(2j * math.pi * n / n_rows))
            for s, values in ((0, f), (1, odd)):  # m >= 0 on columns m, m < 0 on columns n_cols + m
                sums[s, n0:n0 + n.size, :m_max + 1] += values[:, m_max:]
                sums[s, n0:n0 + n.size, n_cols - m_max:] += values[:, :m_max]

    if 2 * m_max + 1 <= n_cols and n_max < half:  # every term a mode of its own, each block its own rows: in parts
        from .. import fft

        fft.in_parts(distinct_blocks, len(starts), sums.size)
        return sums
    for n0 in starts:
        n, gy, k, keep = keep_of(n0)
        rows, cols = np.nonzero(keep)
        f = _terms(gx[cols], gy[rows, 0], sinc_x[cols], k[keep], radial, weight)
        # node of parity s = 1: phase exp(i pi (m / n_cols + 2 n / n_rows)) relative to parity 0
        phase = phase_x[cols] * np.exp(2j * math.pi * n[:, 0] / n_rows)[rows]
        index = np.mod(n[rows, 0], half) * n_cols + np.mod(m[cols], n_cols)
        odd = f * phase
        flat = sums.reshape(2, half * n_cols)
        flat[0].real += np.bincount(index, weights=f, minlength=flat.shape[1])
        flat[1].real += np.bincount(index, weights=odd.real, minlength=flat.shape[1])
        flat[1].imag += np.bincount(index, weights=odd.imag, minlength=flat.shape[1])
    return sums


def _terms(gx, gy, sinc_x, k, radial, weight):
    """``sqrt3 f(|G|) hat(G)`` (``weight(|G|) hat(G)`` where given) at ``G = (gx, gy)``, ``sinc_x`` the factor of
    ``hat`` that depends on ``gx`` only, ``k = |G|``: arrays that broadcast."""
    s2 = (gx / 2 + gy * (_SQRT3 / 2)) / 2  # pyramid_transform by its three factors
    hat = sinc_x * _sin_over(s2) * _sin_over(s2 - gx / 2)
    return (_SQRT3 * radial(k) if weight is None else weight(k)) * hat  # twice f(k) (sqrt3 / 2) hat


def parity_spectra(w):
    """The spectra of ``K_00 = K_11`` and ``K_01`` of a cell's kernel ``w`` (a real brick array, the kernel from node
    ``(0, 0)``), stacked: the real FFTs of its even rows and of its odd rows shifted by a row and a column
    (``np.roll(odd, (1, 1))``, the kernel of the even rows on the odd ones); ``K_10``'s is the conjugate of ``K_01``'s.
    Complex, shape ``(2, n_rows/2, n_cols/2 + 1)``, made a parity at a time (the temporaries of half the spectra);
    the ``1/N`` of the inverse FFT is applied there."""
    import scipy.fft as sfft

    from .. import fft

    out = np.empty((2, w.shape[0] // 2, w.shape[1] // 2 + 1), dtype=complex)
    out[0] = sfft.rfft2(w[0::2], workers=fft.threads())
    out[1] = sfft.rfft2(np.roll(w[1::2], (1, 1), axis=(0, 1)), workers=fft.threads())
    return out


def periodic_spectra(n_rows, n_cols, alpha=ALPHA):
    """The spectra of ``W`` (:func:`periodic_template`) that the cell's operator keeps: ``K_00``'s and ``K_01``'s.

    :func:`parity_spectra` of ``W``, made from the Fourier sum's binned terms directly, without the inverse FFT to
    the nodes and the forward FFT back: the spectrum of the real part of ``Z = ifft2(A)`` is ``(A_j + conj(A_-j)) /
    2``, and a shift by a row and a column multiplies it by ``exp(-2 pi i (j / half + l / n_cols))``; the real-space
    part is transformed as it is, and the mean over the cell taken out of the frequency 0 of both (as
    :func:`periodic_template` takes it out at the nodes). The same numbers as the FFTs of the template's rows, to
    round-off.
    """
    half, n_half = n_rows // 2, n_cols // 2 + 1
    out = parity_spectra(_real_part(n_rows, n_cols, alpha))
    sums = _fourier_terms(n_rows, n_cols, alpha)
    shift = np.exp(-2j * math.pi * np.arange(half) / half)[:, None], np.exp(-2j * math.pi * np.arange(n_half) / n_cols)
    for parity, a in enumerate(sums):  # (A_j + conj(A_-j)) / 2, A_-j at the rows (-j) % half, columns (-l) % n_cols
        fourier = np.empty((half, n_half), dtype=complex)
        fourier[:1, :1], fourier[:1, 1:] = a[:1, :1], a[:1, :n_cols - n_half:-1]
        fourier[1:, :1], fourier[1:, 1:] = a[:0:-1, :1], a[:0:-1, :n_cols - n_half:-1]
        np.conjugate(fourier, out=fourier)
        fourier += a[:, :n_half]
        fourier *= 0.5 * half * n_cols / _area(n_rows, n_cols)
        if parity:  # the shift by a row and a column
            fourier *= shift[0]
            fourier *= shift[1]
        out[parity] += fourier
    mean = (out[0, 0, 0] + out[1, 0, 0]).real / (n_rows * n_cols)
    out[:, 0, 0] -= mean * half * n_cols
    return out


def _template(n_rows, n_cols, alpha):
    w = _fourier_part(n_rows, n_cols, alpha) + _real_part(n_rows, n_cols, alpha)
    w -= w.mean()  # zero to round-off already (see the module docstring)
    w.setflags(write=False)
    return w


_cached = lru_cache(maxsize=8)(_template)


def periodic_template(n_rows, n_cols, alpha=ALPHA, *, cache=True):
    """``W`` at every node of a cell of ``n_cols x n_rows`` nodes, lattice units.

    Parameters
    ----------
    n_rows, n_cols : int
        Rows (even) and columns of the cell.
    alpha : float
        Ewald split parameter [1/lattice step]; the result does not depend on it
        (to the accuracy stated in the module docstring).
    cache : bool
        Keep the result for the next call on the same cell (the last 8 cells). ``False``: computed
        and not kept (the homogeneous :class:`bem.periodic.PeriodicOperator` keeps its symbol instead).

    Returns
    -------
    ndarray, shape ``(n_rows, n_cols)``, read-only
        ``W`` at the offset of node ``(q, r)`` from node ``(0, 0)``, brick storage. The
        displacement of a pyramid of height ``p`` on a lattice of step ``c`` is ``c p W / (pi E*)``.
    """
    return (_cached if cache else _template)(int(n_rows), int(n_cols), float(alpha))
