"""Rough surfaces on one periodic cell: statistics, the cell of a patch, self-affine synthesis, sums.

Needs the optional package SurfaceTopography (``pip install "contactlab[rough]"``), imported
inside the functions; without it they raise :class:`bem.InputError` naming ``contactlab[rough]``.
It detrends, computes the statistics and synthesises self-affine surfaces; measured surfaces
come from :func:`bem.rough.read_surface` (instrument files) or :func:`from_heights` (arrays,
e.g. from the core readers of :mod:`bem.gaps.measured`, which do not need it).

A :class:`RoughSurface` holds ``z[i, j]`` at ``(x, y) = (i Lx/nx, j Ly/ny)`` (x first, the
order of SurfaceTopography and of :func:`bem.gaps.measured.read_heights`), heights measured
outwards from the body (towards the other one; summits positive), in the length unit of the
solve after ``scale``.

**The periodic cell of a measured patch.** A patch is not periodic. Its cell is the detrended
patch (``detrend``: the plane of least rms height by default, SurfaceTopography's
``"height"``) repeated with the period ``(Lx, Ly) = (nx dx, ny dy)``: the last column of
nodes is followed by the first. The repetition puts a seam at the cell's edges, measured by
the rms height difference between opposite edges and by the rms difference of neighbouring
points inside the grid, along the same directions:

    edge_jump^2  = ( sum_j (z[0, j] - z[-1, j])^2 + sum_i (z[i, 0] - z[i, -1])^2 ) / (nx + ny),
    grid_step^2  = ( ny mean (z[i+1, j] - z[i, j])^2 + nx mean (z[i, j+1] - z[i, j])^2 ) / (nx + ny).

On one period of a periodic surface the seam is an ordinary grid step, ``edge_jump ~
grid_step``; a patch adds a step the surface does not have. The seam is flagged when its
excess over a grid step is large against the rms height,

    sqrt(max(edge_jump^2 - grid_step^2, 0)) > EDGE_JUMP_LIMIT * rms_height,

:data:`EDGE_JUMP_LIMIT` = 0.5 (uncorrelated opposite edges give about ``sqrt(2) rms_height``):
a warning is logged and :attr:`SurfaceStats.edge_jump_large` is set. The statistics are those
of the patch as measured (SurfaceTopography's non-periodic estimates), not of the cell with
its seam.

**Two rough surfaces.** The contact of two rough surfaces is that of their sum,
:func:`combined`, against a flat: ``z = z1 + z2``, each measured outwards, both in the common
``(x, y)`` frame (a map of body 2 taken face up is mirrored, one axis reversed, before adding).
"""

from __future__ import annotations

import logging
import warnings
from dataclasses import asdict, dataclass

import numpy as np

from ..checks import (InputError, check_choice, check_finite_array, check_int, check_node_count,
                      check_range, check_scale, fail)
from .lattice_heights import to_lattice

__all__ = ["RoughSurface", "SurfaceStats", "self_affine", "from_heights", "combined", "DETRENDS", "EDGE_JUMP_LIMIT",
           "MIN_POINTS"]

log = logging.getLogger(__name__)

#: the ``detrend`` modes (SurfaceTopography's): mean, plane of least rms height, plane of least
#: rms slope, second-order polynomial of least rms height
DETRENDS = ("center", "height", "slope", "curvature")
#: excess of the seam over a grid step, per rms height, above which a periodic cell is flagged (module docstring)
EDGE_JUMP_LIMIT = 0.5
#: fewest grid points per axis of a surface
MIN_POINTS = 8


def _surface_topography():
    """The SurfaceTopography package, or the error naming the extra."""
    try:
        with warnings.catch_warnings():  # its MPI layer warns that it runs serially, which is what is wanted
            warnings.simplefilter("ignore", ImportWarning)
            import SurfaceTopography
    except ImportError:
        raise InputError('rough surfaces need the optional package SurfaceTopography (not installed): install '
                         'contactlab[rough] (pip install "contactlab[rough]").') from None
    return SurfaceTopography


@dataclass(frozen=True)
class SurfaceStats:
    """Statistics of a rough surface, for reports (:meth:`as_dict`).

    Attributes
    ----------
    rms_height : float
        ``Sq``, rms of ``z - mean z`` [length].
    rms_slope : float
        rms of ``|grad z|`` from finite differences (SurfaceTopography ``rms_gradient``) [-].
    rms_curvature : float
        rms of the mean curvature ``laplacian(z)/2`` (SurfaceTopography
        ``rms_curvature_from_area``) [1/length].
    size : (float, float)
        ``(Lx, Ly)`` of the cell [length].
    grid : (int, int)
        ``(nx, ny)`` points.
    edge_jump : float
        rms height difference between opposite edges of the cell [length] (module docstring).
    grid_step : float
        rms height difference of neighbouring grid points [length], what ``edge_jump`` is on a
        periodic surface.
    edge_jump_large : bool
        ``sqrt(edge_jump^2 - grid_step^2) > EDGE_JUMP_LIMIT * rms_height``: the periodic cell
        has a seam the surface does not have.
    periodic : bool
        The data is one period of a periodic surface (synthetic), not a patch.
    source : str
        The file, or how the surface was made.
    unit : str or None
        The length unit the file states (or the one given for a file that states none); the
        lengths here are converted from it (:func:`bem.rough.read_surface`).
    detrend : str or None
        The ``detrend`` mode applied (:data:`DETRENDS`), ``None`` for none.
    filled : int
        Missing points of the file filled by interpolation (:func:`bem.rough.read_surface`).
    fill : str or None
        How they were filled (``"harmonic"``), ``None`` when none were.
    length_unit : str or None
        The unit of the lengths here (``"m"`` from :func:`bem.rough.read_surface` by default);
        ``None`` where it is not known (arrays, synthetic surfaces: the caller's unit).
    """

    rms_height: float
    rms_slope: float
    rms_curvature: float
    size: tuple
    grid: tuple
    edge_jump: float
    grid_step: float
    edge_jump_large: bool
    periodic: bool
    source: str
    unit: str | None = None
    detrend: str | None = None
    filled: int = 0
    fill: str | None = None
    length_unit: str | None = None

    @property
    def pixel(self):
        """The data's grid spacing ``(dx, dy) = (Lx/nx, Ly/ny)`` [length]."""
        return self.size[0] / self.grid[0], self.size[1] / self.grid[1]

    def as_dict(self):
        """The fields as plain JSON values (tuples as lists)."""
        return {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(self).items()}


@dataclass(frozen=True)
class RoughSurface:
    """A rough surface on one periodic cell: heights, cell size and statistics.

    Attributes
    ----------
    heights : ndarray
        ``z[i, j]`` at ``(i Lx/nx, j Ly/ny)`` [length], shape ``(nx, ny)``, read-only.
    size : (float, float)
        The cell ``(Lx, Ly)`` [length].
    stats : SurfaceStats
        Its statistics.
    """

    heights: np.ndarray
    size: tuple
    stats: SurfaceStats

    def topography(self):
        """The heights as a SurfaceTopography ``Topography`` (for its other analyses)."""
        st = _surface_topography()
        return st.Topography(np.array(self.heights), self.size, periodic=self.stats.periodic)

    def power_spectrum(self):
        """Radially averaged PSD ``(q [1/length], C(q) [length^4])``, SurfaceTopography's
        ``power_spectrum_from_area`` (bins without data dropped)."""
        q, c = self.topography().power_spectrum_from_area()
        ok = ~(np.ma.getmaskarray(q) | np.ma.getmaskarray(c)) & np.isfinite(np.ma.filled(c, np.nan))
        return np.ma.getdata(q)[ok], np.ma.getdata(c)[ok]

    def to_lattice(self, n_cols=None):
        """The heights on the periodic triangular lattice, :func:`bem.rough.to_lattice`
        (``n_cols`` default: :meth:`default_n_cols`)."""
        return to_lattice(self.heights, self.size, self.default_n_cols() if n_cols is None else n_cols)

    def default_n_cols(self):
        """Lattice nodes along x whose step is the data's coarser spacing, ``Lx / max(dx, dy)``.

        On square pixels that is ``nx``; on pixels longer along y the lattice does not
        oversample the data along y (its rows are ``sqrt(3)/2`` steps apart, the spacing of
        a square-pixel grid's rows times 0.87), which a step of ``dx`` would by ``dy/dx``.
        """
        return max(MIN_POINTS, int(round(self.size[0] / max(self.stats.pixel))))


def _pair(name, value):
    """A cell's size ``(Lx, Ly)``: two lengths, each a physical scale (:func:`bem.checks.check_scale`)."""
    if not isinstance(value, (list, tuple, np.ndarray)) or len(value) != 2:
        fail(name, value, "a pair (Lx, Ly) of lengths")
    return check_scale(f"{name}[0]", value[0]), check_scale(f"{name}[1]", value[1])


def _edge_jump(z):
    """``(edge_jump, grid_step)`` of the periodic cell of ``z`` (module docstring)."""
    nx, ny = z.shape
    jumps = np.concatenate([z[0, :] - z[-1, :], z[:, 0] - z[:, -1]])
    steps = (ny * np.mean(np.diff(z, axis=0) ** 2) + nx * np.mean(np.diff(z, axis=1) ** 2)) / (nx + ny)
    return float(np.sqrt(np.mean(jumps**2))), float(np.sqrt(steps))


def _surface(z, size, *, periodic, source, unit=None, detrend=None, filled=0, fill=None, length_unit=None):
    """A :class:`RoughSurface` of the finite grid ``z`` (owned), statistics by SurfaceTopography."""
    st = _surface_topography()
    topo = st.Topography(z, size, periodic=periodic)
    rms_height = float(topo.Sq())
    jump, step = _edge_jump(z)
    excess = np.sqrt(max(jump**2 - step**2, 0.0))
    large = excess > EDGE_JUMP_LIMIT * rms_height
    if large:
        log.warning("%s: the periodic cell has an edge jump of %.4g against a grid step of %.4g, an excess of %.2f "
                    "times its rms height %.4g (> %g): its repetition has a step at the cell's edges", source, jump,
                    step, excess / rms_height, rms_height, EDGE_JUMP_LIMIT)
    stats = SurfaceStats(rms_height, float(topo.rms_gradient()), float(topo.rms_curvature_from_area()),
                         (float(size[0]), float(size[1])), tuple(int(n) for n in z.shape), jump, step, bool(large),
                         bool(periodic), source, unit, detrend, int(filled), fill, length_unit)
    z.flags.writeable = False
    return RoughSurface(z, stats.size, stats)


def _grid_shape(name, shape):
    if len(shape) != 2 or min(shape) < MIN_POINTS:
        fail(name, tuple(int(n) for n in shape), f"a 2-D grid of at least {MIN_POINTS} x {MIN_POINTS} points")


def from_heights(heights, size, *, periodic=False, detrend=None, source="heights"):
    """A :class:`RoughSurface` from a height grid (e.g. read by :func:`bem.gaps.measured.read_heights`).

    Parameters
    ----------
    heights : array_like
        ``z[i, j]`` at ``(i Lx/nx, j Ly/ny)`` [length], finite, at least ``8 x 8``. Not modified.
    size : (float, float)
        ``(Lx, Ly) = (nx dx, ny dy)`` [length], the cell (module docstring).
    periodic : bool
        The grid is one period of a periodic surface (no detrending then beyond ``"center"``).
    detrend : str or None
        One of :data:`DETRENDS` (``"height"`` forms a measured patch's cell as :func:`read_surface`
        does), or ``None`` to keep the heights.
    source : str
        What the statistics call the surface.
    """
    z = check_finite_array("heights", heights, ndim=2)
    _grid_shape("heights.shape", z.shape)
    size = _pair("size", size)
    if detrend is not None:
        check_choice("detrend", detrend, DETRENDS)
    if periodic and detrend not in (None, "center"):
        fail("detrend", detrend, "None or 'center' for a periodic surface (a plane would break its periodicity)")
    z = np.array(z, dtype=float)
    if detrend is not None:
        st = _surface_topography()
        z = np.array(st.Topography(z, size, periodic=periodic).detrend(detrend).heights(), dtype=float)
    return _surface(z, size, periodic=bool(periodic), source=str(source), detrend=detrend)


def self_affine(grid, size, *, hurst, rms_height=None, rms_slope=None, long_cutoff=None, short_cutoff=None,
                rolloff=1.0, seed):
    """A seeded, periodic, self-affine surface (SurfaceTopography's ``fourier_synthesis``).

    Its PSD is ``C(q) = C0 q^(-2-2H)`` between the roll-off wave number ``2 pi/long_cutoff``
    (below it ``rolloff^2 C(q_L)``) and the cut-off ``2 pi/short_cutoff`` (above it zero),
    with random phases and normal amplitudes from ``seed``. The realisation is scaled so that
    its :class:`SurfaceStats` ``rms_height`` (or ``rms_slope``) is exactly the one asked for.

    Parameters
    ----------
    grid : (int, int)
        ``(nx, ny)`` points, each ``>= 8``, ``nx ny`` at most :func:`bem.checks.max_nodes`.
    size : (float, float)
        The period ``(Lx, Ly)`` [length]; each length here is a physical scale, in
        :data:`bem.checks.SCALE_RANGE`.
    hurst : float
        Hurst exponent ``H``, ``0 < H <= 1``.
    rms_height, rms_slope : float
        Exactly one: rms height [length] or rms slope [-], in :data:`bem.checks.SCALE_RANGE`.
    long_cutoff : float, optional
        Roll-off wavelength ``lambda_L`` [length], ``> short_cutoff``; default: none (power law
        down to the longest wavelength of the cell).
    short_cutoff : float, optional
        Short cut-off wavelength ``lambda_s`` [length]; default: twice the grid spacing.
    rolloff : float
        PSD amplitude below ``q_L`` relative to ``C(q_L)``, ``0 <= rolloff <= 1``.
    seed : int
        Seed of the random numbers, ``>= 0``: the same seed gives the same surface.
    """
    _surface_topography()
    from SurfaceTopography.Generation import fourier_synthesis

    if not isinstance(grid, (list, tuple, np.ndarray)) or len(grid) != 2:
        fail("grid", grid, "a pair (nx, ny) of integers")
    grid = (check_int("grid[0]", grid[0], minimum=MIN_POINTS), check_int("grid[1]", grid[1], minimum=MIN_POINTS))
    check_node_count("grid", grid, grid[0] * grid[1], what="the surface grid")
    size = _pair("size", size)
    hurst = check_range("hurst", hurst, 0.0, 1.0, low_open=True)
    if (rms_height is None) == (rms_slope is None):
        fail("(rms_height, rms_slope)", (rms_height, rms_slope), "exactly one given")
    target = check_scale("rms_height" if rms_slope is None else "rms_slope",  # physical scales
                         rms_height if rms_slope is None else rms_slope)
    if short_cutoff is not None:
        short_cutoff = check_scale("short_cutoff", short_cutoff)
    if long_cutoff is not None:
        long_cutoff = check_scale("long_cutoff", long_cutoff)
        if short_cutoff is not None and long_cutoff <= short_cutoff:
            fail("long_cutoff", long_cutoff, f"> short_cutoff = {short_cutoff!r}")
    rolloff = check_range("rolloff", rolloff, 0.0, 1.0)
    seed = check_int("seed", seed, minimum=0)
    topo = fourier_synthesis(grid, size, hurst=hurst, rms_height=1.0, short_cutoff=short_cutoff,
                             long_cutoff=long_cutoff, rolloff=rolloff, rng=seed)
    got = float(topo.Sq() if rms_slope is None else topo.rms_gradient())
    z = np.array(topo.heights(), dtype=float) * (target / got)
    source = f"self-affine H = {hurst:g}, seed = {seed}"
    return _surface(z, size, periodic=True, source=source, detrend=None)


def combined(first, second):
    """The composite surface ``z = z1 + z2`` of two rough surfaces in contact (module docstring).

    Parameters
    ----------
    first, second : RoughSurface
        On the same grid and cell size (relative difference ``<= 1e-9``), both in the common
        ``(x, y)`` frame, heights measured outwards.

    Returns
    -------
    RoughSurface
        The sum, periodic when both are, with its own statistics and edge jump.
    """
    for name, s in (("first", first), ("second", second)):
        if not isinstance(s, RoughSurface):
            fail(name, type(s).__name__, "a RoughSurface")
    if first.heights.shape != second.heights.shape or not np.allclose(first.size, second.size, rtol=1e-9, atol=0):
        fail("second", f"grid {second.heights.shape}, size {second.size}",
             f"on the grid {first.heights.shape} and size {first.size} of first (resample one of them)")
    z = np.array(first.heights) + np.array(second.heights)
    detrend = first.stats.detrend if first.stats.detrend == second.stats.detrend else None
    return _surface(z, first.size, periodic=first.stats.periodic and second.stats.periodic,
                    source=f"{first.stats.source} + {second.stats.source}", detrend=detrend)
