"""Subsurface stresses under the computed contact pressure (the strength of the parts).

:func:`subsurface_stress` evaluates the full stress tensor at given depths below the surface of
one body (its own Poisson ratio; for dissimilar bodies call it once per body) under the
piecewise-linear BEM pressure ``sum_m p_m pyr_m``, frictionless: ``sigma(r_n, z) = sum_m p_m
K(r_n - r_m, z)`` with ``K`` the stress influence of one pyramid at depth ``z``
(:mod:`bem.boussinesq`), a discrete convolution on the lattice done by zero-padded FFTs
(:class:`bem.kernel_convolution.SymmetricKernelConvolution`), ``O(N log N)`` per depth, no matrix.

Why a closed-form kernel in real space and not Fourier transfer functions: the Boussinesq
transfer functions give the stresses of a *periodic* pressure; the influence of the periodic
images decays only like ``1/distance^2``, so an exact non-periodic answer needs the kernel
sampled in real space and zero padding, as for the displacements (:mod:`bem.operator`). The
kernel is split as ``K = V (S * G) + C``: ``G`` the Boussinesq point-load stresses (closed form),
``S`` a 43-node lattice stencil that gives the pyramid's moments up to degree 8
(:func:`bem.boussinesq.stencil`), ``C`` a correction on the offsets nearer than 16 steps, where
``K`` itself is integrated semi-analytically (:func:`bem.boussinesq.pyramid_stress_exact`, radial
integrals in closed form). Since ``S`` lives on the lattice, ``K * p = V G * (S * p) + C * p``:
per depth only ``G`` is evaluated on the whole lattice, ``C`` only on the offsets within 16
steps and only at depths below 16 steps. ``K`` agrees with adaptive
quadrature of the point-load stresses over the pyramid to 1e-8 of the local stress at every
depth ``z >= 0`` (tests/bem/test_stress.py); below one step the zero-offset term of ``G``
(which grows like ``1/z^2``) is moved into ``C`` so that nothing large cancels in the FFTs.

References: K. L. Johnson, *Contact Mechanics*, Cambridge 1985, doi:10.1017/CBO9781139171731
(point load, sec. 3.2; Hertz's subsurface stresses, eq. 3.45); A. E. H. Love, Phil. Trans. R.
Soc. A 228 (1929) 377, doi:10.1098/rsta.1929.0009.
"""

from __future__ import annotations

import logging
import math
import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from . import boussinesq as bq
from .checks import InputError, check_finite_array, check_range
from .coating import check_uncoated_body
from .kernel_convolution import SymmetricKernelConvolution
from .result import ContactResult

__all__ = ["subsurface_stress", "SubsurfaceStress", "VOIGT", "principal_stresses", "peak_in_depth", "von_mises_voigt"]

log = logging.getLogger(__name__)

VOIGT = ("xx", "yy", "zz", "yz", "xz", "xy")
"""Order of the stress components in :attr:`SubsurfaceStress.sigma`."""
_GROUPS = ((0, 1, 2), (3,), (4,), (5,))  # components of equal parity (bem.boussinesq.PARITY)
_MARGIN = 4  # rows and columns the stencil reaches
_PARALLEL_NODES = 50_000  # lattices from this size compute their depths in parallel threads
#: Deepest depth [lattice steps]: the kernel agrees with the point force's 1/z^2 decay to 1e60 steps and
#: under- or overflows in float64 beyond about 1e70 (1e308 gives NaN).
Z_MAX_STEPS = 1e12


def _deviator_angle(s):
    """Mean stress ``q``, ``p = sqrt(J2 / 3)`` and the Lode-type angle ``phi`` in [0, pi/3] of Voigt tensors."""
    xx, yy, zz, yz, xz, xy = (s[..., k] for k in range(6))
    q = (xx + yy + zz) / 3.0
    a, b, c = xx - q, yy - q, zz - q
    p = np.sqrt((a * a + b * b + c * c + 2.0 * (yz * yz + xz * xz + xy * xy)) / 6.0)
    safe = np.where(p > 0, p, 1.0)
    det = (a * (b * c - yz * yz) - xy * (xy * c - yz * xz) + xz * (xy * yz - b * xz)) / safe**3
    return q, p, np.arccos(np.clip(0.5 * det, -1.0, 1.0)) / 3.0


def principal_stresses(sigma):
    """Principal stresses of Voigt tensors, largest first (closed-form roots of the characteristic cubic).

    Parameters
    ----------
    sigma : array_like, shape (..., 6)
        ``xx, yy, zz, yz, xz, xy`` [pressure].

    Returns
    -------
    ndarray, shape (..., 3)
        ``s1 >= s2 >= s3`` [pressure].
    """
    q, p, phi = _deviator_angle(np.asarray(sigma, dtype=float))
    s1 = q + 2.0 * p * np.cos(phi)
    s3 = q + 2.0 * p * np.cos(phi + 2.0 * math.pi / 3.0)
    s2 = np.clip(3.0 * q - s1 - s3, s3, s1)  # s3 <= s2 <= s1 up to rounding
    return np.stack([s1, s2, s3], axis=-1)


def von_mises_voigt(s, axis=-1):
    """The von Mises stress [pressure] of Voigt tensors ``s`` (``xx, yy, zz, yz, xz, xy`` along ``axis``)."""
    xx, yy, zz, yz, xz, xy = np.moveaxis(s, axis, 0)
    return np.sqrt(0.5 * ((xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2) + 3.0 * (yz * yz + xz * xz + xy * xy))


def _tresca(s, block=1 << 15):
    """``(s1 - s3) / 2 = sqrt(3) p sin(phi + pi/3)`` of Voigt tensors ``s`` (..., 6), in cache-sized blocks."""
    flat = s.reshape(-1, 6)
    out = np.empty(flat.shape[0])
    for start in range(0, flat.shape[0], block):
        _, p, phi = _deviator_angle(flat[start: start + block])
        out[start: start + block] = math.sqrt(3.0) * p * np.sin(phi + math.pi / 3.0)
    return out.reshape(s.shape[:-1])


def peak_in_depth(field, z):
    """Maximum of ``field`` (n_z, M): value, depth and point index, refined in depth by a parabola.

    The parabola goes through the sampled maximum and its neighbours in depth at the same point
    (when the maximum is not at the smallest or largest depth); the refined depth is clamped to
    the bracket of depths.
    """
    k, n = np.unravel_index(int(np.argmax(field)), field.shape)
    value, depth = float(field[k, n]), float(z[k])
    order = np.argsort(z, kind="stable")
    pos = int(np.flatnonzero(order == k)[0])
    if 0 < pos < len(z) - 1:
        ks = order[pos - 1: pos + 2]
        z0, z1, z2 = (float(v) for v in z[ks])
        f0, f1, f2 = (float(v) for v in field[ks, n])
        if z0 < z1 < z2:
            d01, d12 = (f1 - f0) / (z1 - z0), (f2 - f1) / (z2 - z1)
            curv = (d12 - d01) / (z2 - z0)
            if curv < 0:
                top = min(max(0.5 * (z0 + z1) - d01 / (2.0 * curv), z0), z2)
                depth = float(top)
                value = max(value, f0 + d01 * (top - z0) + curv * (top - z0) * (top - z1))
    return value, depth, int(n)


@dataclass
class SubsurfaceStress:
    """Stresses in one body below the contact (result of :func:`subsurface_stress`).

    Attributes
    ----------
    x, y : ndarray, shape (M,)
        Horizontal positions of the points [length] (the candidate nodes unless given).
    z : ndarray, shape (n_z,)
        Depths below the surface [length], as given.
    sigma : ndarray, shape (n_z, M, 6)
        Stress tensor [pressure], Voigt order :data:`VOIGT` (``xx, yy, zz, yz, xz, xy``), tension
        positive (compression negative), in the body's frame: ``z`` points into the body. A view
        of component-major storage: ``sigma[..., k]`` is contiguous.
    von_mises : ndarray, shape (n_z, M)
        ``sqrt(3 J2)`` [pressure].
    nu : float
        Poisson's ratio of the body.
    max_von_mises, depth_of_max : float
        Largest von Mises stress [pressure] and its depth [length].
    location_of_max : tuple of float
        ``(x, y, z)`` of that maximum [length].
    max_tresca, depth_of_max_tresca : float
        Largest maximum shear stress ``(s1 - s3) / 2`` [pressure] and its depth [length].
    location_of_max_tresca : tuple of float
        ``(x, y, z)`` of that maximum [length].
    on_nodes : bool
        Whether the points are the candidate nodes (exact convolution values); otherwise the
        values are interpolated linearly between the nodes of each depth.
    wall_time_s : float
        Time of the computation [s].
    meta : dict
        ``step`` (lattice step [length]) and ``n_nodes`` (candidate nodes) of the solution.

    Notes
    -----
    The maxima are those of the sampled field, refined in depth by a parabola through the
    largest sample and its two neighbours in depth (same point).
    """

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    sigma: np.ndarray
    von_mises: np.ndarray
    nu: float
    max_von_mises: float
    depth_of_max: float
    location_of_max: tuple
    max_tresca: float
    depth_of_max_tresca: float
    location_of_max_tresca: tuple
    on_nodes: bool
    wall_time_s: float
    meta: dict = field(default_factory=dict)

    @cached_property
    def tresca(self):
        """Maximum shear stress ``(s1 - s3) / 2`` [pressure], shape (n_z, M) (computed on first use)."""
        return np.stack([_tresca(layer) for layer in self.sigma])

    def principal(self):
        """Principal stresses, largest first [pressure], shape (n_z, M, 3)."""
        return principal_stresses(self.sigma)

    def nearest(self, x0=0.0, y0=0.0):
        """Index of the point nearest to ``(x0, y0)`` [length] (e.g. the axis of the contact)."""
        return int(np.argmin((self.x - x0) ** 2 + (self.y - y0) ** 2))

    def section(self, y0=0.0):
        """Indices of the points in the row nearest to ``y = y0``, sorted by x (an x-z section)."""
        y_row = self.y[int(np.argmin(np.abs(self.y - y0)))]
        row = np.flatnonzero(np.abs(self.y - y_row) <= 1e-9 * max(1.0, abs(float(y_row))))
        return row[np.argsort(self.x[row], kind="stable")]

    def summary(self):
        """Scalars as a JSON-ready dict (lengths and stresses in the result's units)."""
        return {"nu": float(self.nu), "max_von_mises": self.max_von_mises, "depth_of_max": self.depth_of_max,
                "location_of_max": [float(v) for v in self.location_of_max], "max_tresca": self.max_tresca,
                "depth_of_max_tresca": self.depth_of_max_tresca,
                "location_of_max_tresca": [float(v) for v in self.location_of_max_tresca],
                "n_depths": int(self.z.size), "n_points": int(self.x.size), "wall_time_s": self.wall_time_s}


def _gather(fields, lattice, out):
    """``fields[:, lattice.mask]`` into ``out`` (row by row: faster than a mask or an index array)."""
    n_cols = lattice.shape[1]
    pos = 0
    for row, parity in enumerate(lattice.parity.tolist()):
        width = n_cols - parity  # the last node of an odd row lies outside the region
        out[:, pos: pos + width] = fields[:, row, :width]
        pos += width


def _check_points(lattice, x, y):
    if (x is None) != (y is None):
        raise InputError(f"x = {x!r}, y = {y!r} is not allowed: give both x and y or neither.")
    x = check_finite_array("x", x, ndim=1)
    y = check_finite_array("y", y, ndim=1)
    if x.shape != y.shape:
        raise InputError(f"x has shape {x.shape} and y has shape {y.shape} which is not allowed: "
                         "they must have the same shape.")
    ex = lattice.half_cols * lattice.step * (1 + 1e-12)
    ey = lattice.half_rows * lattice.step * math.sqrt(3.0) / 2 * (1 + 1e-12)
    bad = np.flatnonzero((np.abs(x) > ex) | (np.abs(y) > ey))
    if bad.size:
        i = int(bad[0])
        raise InputError(f"x[{i}], y[{i}] = ({float(x[i])!r}, {float(y[i])!r}) is not allowed: the points must "
                         f"lie in the candidate region |x| <= {ex:.6g}, |y| <= {ey:.6g}.")
    return x, y


def _convolve_depths(lattice, grid, loaded, depths, nu, x, y, on_nodes, store, vm, backend):
    """Fill ``store[k]`` (6, M) and ``vm[k]`` for every depth (lattice units), depths in parallel threads."""
    (r0, q0), (r1, q1) = loaded.min(axis=0), loaded.max(axis=0)
    p_box = grid[r0: r1 + 1, q0: q1 + 1]
    m = _MARGIN
    cores = max(1, os.cpu_count() or 1)
    threads = min(cores, len(depths)) if grid.size >= _PARALLEL_NODES and backend.is_numpy else 1
    conv = SymmetricKernelConvolution(lattice, (r0 - m, r1 + m), (q0 - m, q1 + m), workers=max(1, cores // threads))
    filtered = conv.transform(bq.filter_pressure(lattice, p_box, r0, m))
    direct = conv.transform(np.pad(p_box, m)) if (depths < bq.R_NEAR).any() else None
    offsets = conv.offsets()
    if not backend.is_numpy:  # the pressure spectra go to the device once
        def move(spectra):
            return None if spectra is None else tuple(backend.asarray(v, dtype=backend.xp.complex128) for v in spectra)

        filtered, direct = move(filtered), move(direct)

    def one(k):
        depth = float(depths[k])
        spike = depth < 1.0
        near = depth < bq.R_NEAR
        g00, g01 = bq.point_load_quadrants(offsets, depth, nu, spike)
        if near:
            c00, c01 = bq.near_correction(offsets, depth, nu, spike)
        fields = np.empty((6,) + lattice.shape)
        for comps in _GROUPS:
            odd_x, odd_y = bq.PARITY[comps[0]]
            sl = slice(comps[0], comps[-1] + 1)
            terms = [(conv.spectrum(g00[sl], g01[sl], odd_x=odd_x, odd_y=odd_y), filtered)]
            if near:
                terms.append((conv.spectrum(c00[sl], c01[sl], odd_x=odd_x, odd_y=odd_y), direct))
            fields[sl] = conv.apply(terms, backend)
        if on_nodes:
            _gather(fields, lattice, store[k])
        else:
            for comp in range(6):
                store[k, comp] = lattice.interpolate(fields[comp], x, y)
        vm[k] = von_mises_voigt(store[k], axis=0)

    if threads == 1:
        for k in range(len(depths)):
            one(k)
    else:
        with ThreadPoolExecutor(max_workers=threads) as pool:
            list(pool.map(one, range(len(depths))))


def subsurface_stress(result, z, *, nu, x=None, y=None, body=None, device="cpu"):
    """Stress tensor at depths ``z`` below the surface of a body under the computed contact pressure.

    Parameters
    ----------
    result : bem.ContactResult
        A solution of :func:`bem.solve`; its nodal pressures (pyramid amplitudes) are the load.
    z : float or array_like, shape (n_z,)
        Depths below the surface [length], ``>= 0`` and at most :data:`Z_MAX_STEPS` lattice
        steps, any order.
    nu : float
        Poisson's ratio of the body, in ``(-1, 0.5]``. For dissimilar bodies call once per body:
        frictionless, each body carries the same pressure and its stresses depend only on its
        own ``nu`` (not on ``E``). A coated body's stresses: :func:`bem.coated_stress`.
    x, y : array_like, shape (M,), optional
        Horizontal points [length] inside the candidate region; default: every candidate node
        (``result.x``, ``result.y``). Values between nodes are interpolated linearly.
    body : {1, 2}, optional
        The (uncoated) body, named where ``result`` has a coated one (:func:`bem.coated_stress`).
    device : {"cpu", "cuda"} or module
        Where the convolutions run (:mod:`bem.backend`). The kernel samples and their
        cosine/sine transforms (not in the array API standard) are computed on the host and
        copied to the device per depth; the products with the pressure spectra and the inverse
        FFTs run on the device, and each depth's fields come back to the host. The result's
        arrays are NumPy arrays for every device.

    Returns
    -------
    SubsurfaceStress
        ``sigma`` (Voigt ``xx, yy, zz, yz, xz, xy``, compression negative) [pressure],
        ``von_mises``, ``tresca`` (maximum shear), their maxima, depths and locations.

    Raises
    ------
    bem.InputError
        ``result`` is not a ContactResult or is a periodic cell's (:func:`bem.solve_periodic`),
        ``nu`` out of range, a depth negative, not finite or deeper than :data:`Z_MAX_STEPS`
        lattice steps, ``x``/``y`` of unequal shapes or outside the candidate region.

    Notes
    -----
    ``sigma(r_n, z) = sum_m p_m K(r_n - r_m, z)``, ``K`` the stresses under one pyramid: the
    point-load (Boussinesq) stresses convolved with a lattice stencil plus a near-field
    correction integrated semi-analytically (module docstring and :mod:`bem.boussinesq`);
    one FFT convolution per depth and stress component, ``O(N log N)``. Body frame: ``z``
    points into the body; in a frame whose z axis points up into the upper body, the lower
    body's shear stresses ``xz`` and ``yz`` change sign.
    """
    from .backend import get_backend

    t0 = time.perf_counter()
    backend = get_backend(device)
    if not isinstance(result, ContactResult):
        raise InputError(f"result = {type(result).__name__} is not allowed: it must be a bem.ContactResult "
                         "(the return value of bem.solve).")
    from .periodic import PeriodicContactResult

    if isinstance(result, PeriodicContactResult):
        raise InputError("result = PeriodicContactResult is not allowed: it must be a bounded contact of bem.solve; "
                         "the stresses below a periodic cell need the images of every other cell, which this "
                         "sum over one candidate region does not hold.")
    check_uncoated_body(result, body)
    nu = check_range("nu", nu, -1.0, 0.5, low_open=True)
    z = check_finite_array("z", z)
    if z.ndim > 1:
        raise InputError(f"z has shape {z.shape} which is not allowed: it must be a number or a 1-D array of depths.")
    name = "z" if z.ndim == 0 else "z[{}]"
    z = np.atleast_1d(z).copy()
    if (z < 0).any():
        k = int(np.flatnonzero(z < 0)[0])
        raise InputError(f"{name.format(k)} = {float(z[k])!r} is not allowed: depths must be >= 0 (below the surface).")
    lattice = result.lattice
    deep = z > Z_MAX_STEPS * lattice.step
    if deep.any():
        k = int(np.flatnonzero(deep)[0])
        raise InputError(f"{name.format(k)} = {float(z[k])!r} is not allowed: depths must be at most {Z_MAX_STEPS:g} "
                         f"lattice steps ({Z_MAX_STEPS * lattice.step:.6g}), where the stresses are those of a point "
                         "force; far deeper the kernel's float64 arithmetic over- or underflows.")
    on_nodes = x is None and y is None
    if not on_nodes:
        x, y = _check_points(lattice, x, y)
    else:
        x, y = np.array(result.x, dtype=float), np.array(result.y, dtype=float)
    c = lattice.step
    grid = result.grid()
    store = np.zeros((z.size, 6, x.size))  # component-major: contiguous per component
    vm = np.zeros((z.size, x.size))
    loaded = np.argwhere(grid != 0)
    if loaded.size:
        _convolve_depths(lattice, grid, loaded, z / c, nu, x, y, on_nodes, store, vm, backend)
    sigma = np.moveaxis(store, 1, 2)  # (n_z, M, 6), a view
    vmax, vdepth, vn = peak_in_depth(vm, z)
    # the largest maximum shear lies where von Mises >= (sqrt(3)/2) max von Mises (since
    # vm / 2 <= tresca <= vm / sqrt(3)): principal stresses only there, then along the depth
    # of the largest one (for the refinement)
    tres = np.zeros_like(vm)
    cand = vm >= (math.sqrt(3.0) / 2) * vm.max() * (1 - 1e-12)
    tres[cand] = _tresca(sigma[cand])
    n_top = np.unravel_index(int(np.argmax(tres)), tres.shape)[1]
    tres[:, n_top] = _tresca(sigma[:, n_top])
    tmax, tdepth, tn = peak_in_depth(tres, z)
    out = SubsurfaceStress(
        x=x, y=y, z=z, sigma=sigma, von_mises=vm, nu=nu, max_von_mises=vmax, depth_of_max=vdepth,
        location_of_max=(float(x[vn]), float(y[vn]), vdepth), max_tresca=tmax, depth_of_max_tresca=tdepth,
        location_of_max_tresca=(float(x[tn]), float(y[tn]), tdepth), on_nodes=on_nodes,
        wall_time_s=time.perf_counter() - t0, meta={"step": c, "n_nodes": int(result.p.size)})
    log.debug("subsurface stress: %d depths x %d points in %.2f s", z.size, x.size, out.wall_time_s)
    return out
