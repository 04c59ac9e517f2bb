"""Measured surfaces: height maps read from files, and the gap they give over a candidate region.

:func:`read_heights` reads a file into a grid ``z[i, j]`` at ``(x[i], y[j])``, with NaN where
there is no data; :class:`Measured` holds such a grid and gives the gap over a candidate
region ``|x| <= X``, ``|y| <= Y`` as a :class:`bem.gaps.Table` (:meth:`Measured.region`).
Every length of a file (coordinates, heights, ``spacing``) is in its own length unit;
:meth:`Measured.from_file` multiplies them by ``scale`` into the length unit of the solve.
Every error is an :class:`bem.InputError` whose message starts with the argument it blames.

Formats (``format`` inferred from the extension, :data:`EXTENSIONS`: ``.npy``; ``.csv``,
``.txt``, ``.dat``: grid; ``.asc``; ``.xyz``; give ``format = "xyz"`` for point lists in
``.csv`` or ``.txt`` files):

- ``npy``: a 2-D numpy array ``z[i, j]`` at ``x = j dx``, ``y = i dy`` (row ``i`` along y);
- ``grid``: the same as a text table, comma- or whitespace-separated, ``#`` comments;
- ``asc``: ESRI ASCII grid (header ``ncols``, ``nrows``, ``xllcorner``/``xllcenter``,
  ``yllcorner``/``yllcenter``, ``cellsize``, optional ``NODATA_value``; the first row is
  the northernmost, largest y);
- ``xyz``: three columns ``x, y, z``. Points on a complete, evenly spaced grid are used as
  that grid; other points (or any points when ``spacing`` is given) are interpolated
  linearly on their Delaunay triangles onto a grid of step ``spacing`` (default: the median
  distance of a point to its nearest neighbour); outside their convex hull there is no data.

``kind = "gap"``: the values are the gap ``h >= 0`` itself. ``kind = "topography"``: the
values are the heights ``z`` of one body's surface, measured outwards (towards the other,
flat, body; summits positive); the gap is ``h = max z - z`` over the candidate region, so
the highest summit there touches first. Two rough surfaces: add their topographies first.

``center``: ``"grid"`` puts the middle of the data's bounding box at ``x = y = 0``;
``"minimum"`` the lowest point of the gap (the highest summit); ``"file"`` keeps the given
coordinates (``.asc``: its lower-left corner, ``.xyz``: its columns, npy and grid: the first
point at the origin).
"""

from __future__ import annotations

import os

import numpy as np

from ..checks import InputError, check_choice, check_positive, fail
from .heights import (EXTENSIONS, FORMATS, MAX_FILE_BYTES, MAX_GRID_VALUES, _positive_pair, _refuse, file_format,
                      read_heights)
from .table import Table, _axis

__all__ = ["Measured", "RegionTable", "read_heights", "file_format", "EXTENSIONS", "FORMATS", "KINDS", "CENTERS",
           "MAX_FILE_BYTES", "MAX_GRID_VALUES"]

KINDS = ("gap", "topography")
CENTERS = ("grid", "minimum", "file")


def check_within(extent, x, y, *, name="extent", data="the data"):
    """Refuse a candidate region ``|x| <= X``, ``|y| <= Y`` that reaches beyond the grid ``x``, ``y``.

    The one rule of :meth:`Measured.region`, :meth:`Measured.check_region` (a scene's
    ``bem.extent``) and :func:`bem.solve` with a :class:`RegionTable`: data are never extended
    beyond where they were measured.

    Raises
    ------
    bem.InputError
        ``{name} = extent is not allowed``, naming the data's extent.
    """
    ex, ey = _positive_pair(name, extent)
    tol = 1e-9
    if -ex < x[0] - tol * ex or ex > x[-1] + tol * ex or -ey < y[0] - tol * ey or ey > y[-1] + tol * ey:
        _refuse(name, extent, f"the candidate region |x| <= {ex:.6g}, |y| <= {ey:.6g} must lie inside {data}, "
                              f"x in [{x[0]:.6g}, {x[-1]:.6g}], y in [{y[0]:.6g}, {y[-1]:.6g}] (data are not "
                              "extended beyond where they were measured); make it smaller")
    return ex, ey


class RegionTable(Table):
    """A :class:`bem.gaps.Table` over the candidate region that gives points beyond its grid the
    value at the nearest edge instead of refusing them.

    The lattice evaluates the gap at every node of its brick array, including the masked node
    half a step beyond the region at the end of each odd row (a coarser step in nested solves);
    those values are never used. Every candidate node is inside: :meth:`Measured.region` makes
    it so, and :func:`bem.solve` calls :meth:`check_region` with its ``extent``.
    """

    def _inside(self, name, v, other):
        axis = self.x if name == "x" else self.y
        return np.clip(v, axis[0], axis[-1])

    def check_region(self, extent, *, name="extent"):
        """Refuse a candidate region beyond the table's grid (:func:`check_within`)."""
        check_within(extent, self.x, self.y, name=name, data="the measured data of this gap table")


def _cover(axis, half, need):
    """Index range ``[lo, hi)`` of the nodes of ``axis`` covering ``[-half, half]``, at least ``need`` wide."""
    lo = max(int(np.searchsorted(axis, -half, side="right")) - 1, 0)
    hi = min(int(np.searchsorted(axis, half, side="left")) + 1, axis.size)
    while hi - lo < need and (lo > 0 or hi < axis.size):
        lo, hi = max(lo - 1, 0), min(hi + 1, axis.size)
    return lo, hi


class Measured:
    """A measured gap or topography on a grid, with missing points: the gap over a candidate region.

    Not a :class:`bem.gaps.Gap`, and not in :data:`bem.gaps.GAPS`: its gap exists only over
    a candidate region (a topography's gap is ``max z - z`` over it; missing data is an error
    only inside it), through the :class:`Table` of :meth:`region`; and a scene gives it a file
    and a length unit, not the constructor's arrays. It has what sizing the region needs:
    ``domain``, ``is_axisymmetric``, ``type_name``, :meth:`expected_semi_axes` (none).

    Parameters
    ----------
    x, y : array_like
        Strictly increasing grid coordinates [length].
    z : array_like
        ``z[i, j]`` at ``(x[i], y[j])`` [length], NaN where there is no data; shape
        ``(len(x), len(y))``, at least one finite value. Not modified.
    kind : {"gap", "topography"}
        The values are the gap ``h >= 0``, or heights of one surface (module docstring).
    method : {"cubic", "linear", "quintic", "pchip"}
        Interpolation of the region's :class:`Table`.
    center : {"grid", "minimum", "file"}
        Where ``x = y = 0`` goes (module docstring); ``"file"`` keeps ``x`` and ``y``.
    file, format : str, optional
        Where the data came from (:meth:`from_file`); errors about the data name ``file``
        (``z`` when there is none).

    Attributes
    ----------
    x, y, z, domain
        The grid after centring [length], and its box ``((x[0], x[-1]), (y[0], y[-1]))``.
    """

    type_name = "measured"
    is_axisymmetric = False

    def __init__(self, x, y, z, *, kind="gap", method="cubic", center="grid", file=None, format=None):
        self.kind, self.center, self.method = _options(kind, center, method)
        x, y = _axis("x", x, 2), _axis("y", y, 2)
        try:
            z = np.array(z, dtype=float)
        except (TypeError, ValueError):
            fail("z", z, "an array of numbers (NaN where there is no data)")
        if z.shape != (x.size, y.size):
            fail("z.shape", z.shape, f"(len(x), len(y)) = {(x.size, y.size)}")
        self.file, self.format = (None if file is None else os.fspath(file)), format
        if not np.isfinite(z).any():
            self._refuse("it holds no finite value")
        if center == "grid":
            x, y = x - 0.5 * (x[0] + x[-1]), y - 0.5 * (y[0] + y[-1])
        elif center == "minimum":
            low = np.where(np.isfinite(z), z if kind == "gap" else -z, np.inf)
            i, j = np.unravel_index(np.argmin(low), low.shape)
            x, y = x - x[i], y - y[j]
        self.x, self.y, self.z = x, y, z
        self.domain = ((float(x[0]), float(x[-1])), (float(y[0]), float(y[-1])))

    @classmethod
    def from_file(cls, file, *, format=None, spacing=None, nodata=None, kind="gap", center="grid", method=None,
                  scale=1.0):
        """Read ``file`` (:func:`read_heights`) into a :class:`Measured`.

        ``format``, ``spacing`` and ``nodata`` are those of :func:`read_heights`; ``kind``,
        ``center`` and ``method`` those of :class:`Measured` (``method`` default: ``"linear"``
        for xyz files, ``"cubic"`` otherwise). ``scale`` [length per file length unit], ``> 0``,
        multiplies every length of the file (``x``, ``y``, ``z``) into the solve's unit.
        """
        fmt = file_format(file, format)
        method = ("linear" if fmt == "xyz" else "cubic") if method is None else method
        _options(kind, center, method)  # before reading the file
        scale = check_positive("scale", scale)
        x, y, z = read_heights(file, format=fmt, spacing=spacing, nodata=nodata)
        return cls(x * scale, y * scale, z * scale, kind=kind, method=method, center=center, file=file, format=fmt)

    def expected_semi_axes(self, **_):
        """No estimate of the contact size: the candidate region is the caller's."""
        return None

    def check_region(self, extent, *, name="extent"):
        """Refuse a candidate region that reaches beyond the data (:func:`check_within`)."""
        return check_within(extent, self.x, self.y, name=name,
                            data="the measured data" + ("" if self.file is None else f" of {self.file}"))

    def _refuse(self, rule):
        if self.file is None:
            raise InputError(f"z is not allowed: {rule}.")
        _refuse("file", self.file, rule)

    def region(self, extent, *, name="extent"):
        """The gap over the candidate region ``|x| <= extent[0]``, ``|y| <= extent[1]`` [length].

        Parameters
        ----------
        extent : float or (float, float)
            Half-widths ``(X, Y)`` of the candidate region [length], ``> 0``.
        name : str
            What the messages call ``extent`` (a caller's own key, e.g. ``"bem.extent"``).

        Returns
        -------
        RegionTable
            The :class:`Table` of the grid nodes covering the region (at least ``method``'s
            minimum per axis); for a topography the gap ``max z - z`` over them.

        Raises
        ------
        bem.InputError
            A region reaching beyond the data, missing data (NaN, NODATA, outside the hull of
            x-y-z points) at a node of the region, too few nodes for ``method``, or negative
            values of ``kind = "gap"``.
        """
        ex, ey = self.check_region(extent, name=name)
        need = Table.MIN_POINTS[self.method]
        (i0, i1), (j0, j1) = _cover(self.x, ex, need), _cover(self.y, ey, need)
        x, y, z = self.x[i0:i1], self.y[j0:j1], self.z[i0:i1, j0:j1]
        if min(z.shape) < need:
            self._refuse(f"the grid has only {z.shape[0]} x {z.shape[1]} points around the candidate region and "
                         f"method = {self.method!r} needs {need} per axis (too few points)")
        bad = ~np.isfinite(z)
        if bad.any():
            i, j = np.argwhere(bad)[0]
            self._refuse(f"it has no data (NaN, NODATA or outside the measured points) at (x, y) = "
                         f"({x[i]:.6g}, {y[j]:.6g}), inside the candidate region |x| <= {ex:.6g}, "
                         f"|y| <= {ey:.6g} ({name}); make {name} smaller or fill in the data")
        h = z.max() - z if self.kind == "topography" else z
        if self.kind == "gap" and (h < 0).any():
            i, j = np.argwhere(h < 0)[0]
            self._refuse(f"it holds the negative gap {h[i, j]:.6g} at (x, y) = ({x[i]:.6g}, {y[j]:.6g}); a gap "
                         "is a separation >= 0 (use kind = 'topography' for surface heights)")
        return RegionTable(x, y, h, method=self.method)


def _options(kind, center, method):
    """The checked ``(kind, center, method)`` of a :class:`Measured`."""
    return (check_choice("kind", kind, KINDS), check_choice("center", center, CENTERS),
            check_choice("method", method, tuple(Table.MIN_POINTS)))
