"""The periodic cell of a surface as measured: detrending, spikes, and the seam.

:func:`patch_cell` takes a surface read without detrending (``read_surface(..., detrend=None)``)
and makes the cell the periodic solver repeats, in this order:

1. ``detrend``: ``"none"`` keeps the heights bit for bit (the only choice that keeps a periodic
   surface periodic), ``"height"`` takes off the plane of least rms height, ``"curvature"`` the
   second-order polynomial of least rms height (a measured form, e.g. a ball or a cylinder),
   ``"center"`` and ``"slope"`` as SurfaceTopography's; ``"auto"``: ``"none"`` for a periodic
   surface, ``"height"`` for a patch.
2. ``spikes``: :func:`bem.rough.find_spikes` on the detrended heights, always (its numbers are
   logged once as a warning when there are spikes, and recorded); ``"remove"`` fills them
   (:func:`bem.rough.remove_spikes`), ``"keep"`` leaves them.
3. ``cell``: ``"repeat"`` repeats the patch with its period ``(nx dx, ny dy)``: the last column is
   followed by the first, with a seam (:mod:`bem.rough.surface`). ``"mirror"`` repeats the patch
   and its mirror images,

       z_m = [[z, z[::-1, :]], [z[:, ::-1], z[::-1, ::-1]]],  (2 nx) x (2 ny) points, (2 Lx, 2 Ly),

   which is periodic without a height step: each edge meets its own image. The cell's contact
   is symmetric about the mirror lines, so its quarters carry equal shares: the mean pressure,
   the mean gap and the contact fraction of the mirrored cell are those of the patch between
   frictionless symmetry walls, with every measured height kept. The price is four times the
   nodes and kinks (slope jumps) along the mirror lines. A window (a taper to the mean plane
   at the edges, as for a PSD) is not offered: it lowers the summits near the edges, which
   then touch later or not at all, and so changes the contact the law is made from.

The one warning about the seam is that of the cell solved (:mod:`bem.rough.surface`, in its
length unit): a mirrored cell has none. :func:`check_cell_size` counts the nodes of the cell
(a mirrored one included) from the surface before :func:`patch_cell` makes it.
"""

from __future__ import annotations

import contextlib
import logging
from dataclasses import dataclass

import numpy as np

from ..checks import check_choice, check_int, check_node_count, check_positive, fail
from .lattice_heights import cell_shape
from .outliers import SPIKE_THRESHOLD, Spikes, find_spikes, remove_spikes
from .surface import DETRENDS, MIN_POINTS, RoughSurface, _surface, _surface_topography

__all__ = ["PatchCell", "patch_cell", "cell_grid", "check_cell_size", "quiet_seam", "DETREND_CHOICES", "CELLS",
           "SPIKE_ACTIONS"]

log = logging.getLogger(__name__)

#: the ``detrend`` of :func:`patch_cell`
DETREND_CHOICES = ("auto", "none", *DETRENDS)
#: how a patch becomes a periodic cell
CELLS = ("repeat", "mirror")
#: what :func:`patch_cell` does with spikes
SPIKE_ACTIONS = ("keep", "remove")


@dataclass(frozen=True)
class PatchCell:
    """The cell of :func:`patch_cell` and what was done to make it.

    Attributes
    ----------
    surface : RoughSurface
        The periodic cell.
    detrend : str
        The detrending applied (``"none"`` or one of :data:`bem.rough.DETRENDS`).
    cell : str
        ``"repeat"``, ``"mirror"`` or ``"periodic"`` (the surface is one period).
    spikes : Spikes
        Found on the detrended heights.
    spikes_removed : bool
        The spikes were filled.
    """

    surface: RoughSurface
    detrend: str
    cell: str
    spikes: Spikes
    spikes_removed: bool

    def record(self):
        """What was done, as plain values (a law file's ``[topography.preparation]``, ``result.json``)."""
        stats = self.surface.stats
        return dict(detrend=self.detrend, cell=self.cell, spikes_removed=self.spikes_removed,
                    spike_points=self.spikes.count, spikes=self.spikes.as_dict(), edge_jump=stats.edge_jump,
                    edge_jump_large=stats.edge_jump_large)


@contextlib.contextmanager
def quiet_seam():
    """Keep :mod:`bem.rough.surface` from warning about the seam of a surface that is not the cell solved."""
    logger = logging.getLogger("bem.rough.surface")
    before = logger.level
    logger.setLevel(logging.ERROR)
    try:
        yield
    finally:
        logger.setLevel(before)


def cell_grid(surface, *, cell="repeat", name="cell"):
    """``((nx, ny), (Lx, Ly), mirrored)``: the height grid and size of the cell :func:`patch_cell`
    makes of ``surface`` with ``cell`` (named ``name`` in messages), counted without making it."""
    if not isinstance(surface, RoughSurface):
        fail("surface", type(surface).__name__, "a bem.rough.RoughSurface")
    check_choice(name, cell, CELLS)
    k = 2 if cell == "mirror" and not surface.stats.periodic else 1
    nx, ny = surface.heights.shape
    return (k * nx, k * ny), (k * surface.size[0], k * surface.size[1]), k == 2


def check_cell_size(surface, *, cell="repeat", n_cols=None, names=None):
    """Refuse a cell :func:`patch_cell` would make too large, counted from ``surface`` before it is made.

    The memory guard :func:`bem.checks.check_node_count` on the heights of a mirrored cell
    (``2 nx x 2 ny`` points) and on the lattice cell of ``n_cols`` nodes along x over the
    cell's size (``(2 Lx, 2 Ly)`` when mirrored).

    Parameters
    ----------
    surface : RoughSurface
        The surface :func:`patch_cell` is given.
    cell : str
        As :func:`patch_cell`.
    n_cols : int, optional
        Lattice nodes along x of the cell, ``>= 2``; default: the cell's ``Lx / max(dx, dy)``
        (:meth:`RoughSurface.default_n_cols` of the cell made).
    names : dict, optional
        The names the caller's user knows ``cell`` and ``n_cols`` by, for messages (e.g.
        ``{"cell": "--cell", "n_cols": "--n-cols"}``); a default ``n_cols`` is named with its rule.

    Returns
    -------
    int
        ``n_cols`` (its default when not given).
    """
    names = dict(names or {})
    (nx, ny), size, mirrored = cell_grid(surface, cell=cell, name=names.get("cell", "cell"))
    what = "the mirrored periodic cell" if mirrored else "the periodic cell"
    if mirrored:
        check_node_count(names.get("cell", "cell"), cell, nx * ny, what="the mirrored surface grid")
    k = 2 if mirrored else 1
    name = names.get("n_cols", "n_cols")
    if n_cols is None:
        name = f"{name} (default: Lx / max(dx, dy) of the {'mirrored ' if k == 2 else ''}cell)"
        n_cols = max(MIN_POINTS, int(round(size[0] / max(surface.stats.pixel))))
    n_rows, n_cols = cell_shape(size, check_int(name, n_cols, minimum=2))
    check_node_count(name, n_cols, n_rows * n_cols, what=what)
    return n_cols


def _mirrored(z):
    top = np.concatenate([z, z[::-1, :]], axis=0)
    return np.concatenate([top, top[:, ::-1]], axis=1)


def patch_cell(surface, *, detrend="auto", cell="repeat", spikes="keep", spike_threshold=SPIKE_THRESHOLD, scale=1.0,
               unit="m"):
    """The periodic cell of a surface as measured (module docstring).

    Parameters
    ----------
    surface : RoughSurface
        Read without detrending (``stats.detrend`` ``None``), in the length unit of the solve.
    detrend : str
        One of :data:`DETREND_CHOICES`; a periodic surface takes ``"auto"``, ``"none"`` or
        ``"center"`` only (a plane or a form taken off breaks its period).
    cell : str
        ``"repeat"`` or ``"mirror"`` (:data:`CELLS`); a periodic surface is its own cell (either
        is accepted and ignored).
    spikes : str
        ``"keep"`` or ``"remove"`` (:data:`SPIKE_ACTIONS`).
    spike_threshold : float
        Of :func:`bem.rough.find_spikes`, robust standard deviations, ``> 0``.
    scale : float
        [solve length per surface length], ``> 0``: multiplies the heights and the size first.
    unit : str
        The length unit of the solve, named in the spike warning.

    Returns
    -------
    PatchCell

    Raises
    ------
    bem.InputError
        A bad argument, or a mirrored cell of more than :func:`bem.checks.max_nodes` points
        (counted before it is made; :func:`check_cell_size` counts its lattice too).
    """
    check_choice("detrend", detrend, DETREND_CHOICES)
    (nx, ny), _, mirrored = cell_grid(surface, cell=cell)
    if mirrored:
        check_node_count("cell", cell, nx * ny, what="the mirrored surface grid")
    check_choice("spikes", spikes, SPIKE_ACTIONS)
    scale = check_positive("scale", scale)
    spike_threshold = check_positive("spike_threshold", spike_threshold)
    stats = surface.stats
    if stats.detrend is not None:
        fail("surface.stats.detrend", stats.detrend, "None: read the surface with detrend=None and detrend here")
    periodic = stats.periodic
    if detrend == "auto":
        detrend = "none" if periodic else "height"
    if periodic and detrend not in ("none", "center"):
        fail("detrend", detrend, "'none', 'center' or 'auto' for a periodic surface (a plane or a form taken off "
                                 "breaks its period)")
    z, size = np.array(surface.heights, dtype=float) * scale, (surface.size[0] * scale, surface.size[1] * scale)
    if detrend != "none":
        st = _surface_topography()
        z = np.array(np.ma.getdata(st.Topography(z, size, periodic=periodic).detrend(detrend).heights()),
                     dtype=float)
    found = find_spikes(z, threshold=spike_threshold)
    if found.count:
        log.warning("%s: %s; %s", stats.source, found.describe(unit),
                    "they are filled by harmonic interpolation" if spikes == "remove"
                    else "they are kept (they may decide the first touch; removing them fills them from their "
                         "neighbours)")
        if spikes == "remove":
            z = remove_spikes(z, found, size, periodic=periodic)
    if not periodic and cell == "mirror":
        z, size = _mirrored(z), (2 * size[0], 2 * size[1])
    out = _surface(z, size, periodic=periodic or cell == "mirror", source=stats.source, unit=stats.unit,
                   detrend=None if detrend == "none" else detrend, filled=stats.filled, fill=stats.fill,
                   length_unit=stats.length_unit if scale == 1.0 else None)
    return PatchCell(out, detrend, "periodic" if periodic else cell, found, spikes == "remove" and found.count > 0)
