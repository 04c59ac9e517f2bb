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
import re

import numpy as np

from ..checks import InputError, check_choice, check_positive, fail
from .table import Table, _axis

__all__ = ["Measured", "RegionTable", "read_heights", "file_format", "EXTENSIONS", "FORMATS", "KINDS", "CENTERS"]

#: the format of a file by its extension
EXTENSIONS = {".npy": "npy", ".csv": "grid", ".txt": "grid", ".dat": "grid", ".asc": "asc", ".xyz": "xyz"}
FORMATS = ("asc", "grid", "npy", "xyz")
KINDS = ("gap", "topography")
CENTERS = ("grid", "minimum", "file")
_MIN_POINTS = 4  # of the scattered points of an xyz file
_UNIFORM = 1e-6  # relative tolerance of "evenly spaced"


def _refuse(name, value, rule):
    raise InputError(f"{name} = {value!r} is not allowed: {rule}.")


def _positive_pair(name, value):
    """``(a, b)`` from a number (``a = b``) or a pair, each a finite real ``> 0``."""
    if isinstance(value, (list, tuple, np.ndarray)):
        if len(value) != 2:
            fail(name, value, "a number or a pair of numbers")
        return check_positive(f"{name}[0]", value[0]), check_positive(f"{name}[1]", value[1])
    a = check_positive(name, value)
    return a, a


def file_format(file, format=None):
    """The format of ``file``: ``format`` when given (checked), else from its extension (:data:`EXTENSIONS`)."""
    if not isinstance(file, (str, os.PathLike)):
        fail("file", file, "a file name (str or os.PathLike)")
    suffix = os.path.splitext(os.fspath(file))[1].lower()
    if format is None:
        format = EXTENSIONS.get(suffix)
        if format is None:
            _refuse("file", os.fspath(file), f"its extension {suffix!r} does not tell the format; give format = "
                                             f"one of {list(FORMATS)}")
    return check_choice("format", format, FORMATS)


def _load_table(file, fmt):
    """A 2-D table of numbers from a text file (comma- or whitespace-separated)."""
    try:
        with open(file, encoding="utf-8") as fh:
            lines = [ln for ln in fh.read().splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
        delimiter = "," if lines and "," in lines[0] else None
        return np.loadtxt(lines, delimiter=delimiter, ndmin=2, dtype=float)
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        _refuse("file", file, f"it must be a table of numbers for format = {fmt!r} ({exc})")


def _read_grid(file, fmt, spacing):
    """``(x, y, z)`` of an npy or grid file: rows along y, steps ``spacing = (dx, dy)``."""
    if fmt == "npy":
        try:
            z = np.load(file, allow_pickle=False)
        except (OSError, ValueError) as exc:
            _refuse("file", file, f"it must be a .npy file of numbers ({exc})")
    else:
        z = _load_table(file, fmt)
    if z.ndim != 2 or min(z.shape) < 2 or z.dtype.kind not in "biuf":
        _refuse("file", file, f"it must hold a 2-D array of numbers of at least 2 x 2 values, it has shape "
                              f"{z.shape} and dtype {z.dtype} (wrong shape)")
    z = np.array(z, dtype=float).T  # rows run along y
    return spacing[0] * np.arange(z.shape[0]), spacing[1] * np.arange(z.shape[1]), z


def _read_asc(file):
    """``(x, y, z)`` of an ESRI ASCII grid, cell centres, rows turned to increasing y."""
    header, rows = {}, []
    try:
        with open(file, encoding="utf-8") as fh:
            for line in fh:
                parts = line.split()
                if not parts:
                    continue
                if len(parts) == 2 and re.match(r"^[A-Za-z_]+$", parts[0]) and not rows:
                    header[parts[0].lower()] = float(parts[1])
                else:
                    rows.append([float(v) for v in parts])
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        _refuse("file", file, f"it must be an ESRI ASCII grid ({exc})")
    need = [k for k in ("ncols", "nrows", "cellsize") if k not in header]
    if need or not any(k in header for k in ("xllcorner", "xllcenter")):
        _refuse("file", file, f"an ESRI ASCII grid needs the header keys ncols, nrows, xllcorner (or xllcenter), "
                              f"yllcorner (or yllcenter), cellsize; missing {need or ['xllcorner']}")
    nx, ny, c = int(header["ncols"]), int(header["nrows"]), header["cellsize"]
    if len(rows) != ny or any(len(r) != nx for r in rows):
        _refuse("file", file, f"its header says nrows = {ny}, ncols = {nx} but the data has {len(rows)} rows of "
                              f"{sorted({len(r) for r in rows})} values (wrong shape)")
    z = np.array(rows[::-1], dtype=float)  # first row is the northernmost
    if "nodata_value" in header:
        z[z == header["nodata_value"]] = np.nan
    x0 = header.get("xllcenter", header.get("xllcorner", 0.0)) + (0.0 if "xllcenter" in header else 0.5 * c)
    y0 = header.get("yllcenter", header.get("yllcorner", 0.0)) + (0.0 if "yllcenter" in header else 0.5 * c)
    return x0 + c * np.arange(nx), y0 + c * np.arange(ny), z.T


def _grid_of_points(x, y, z, file):
    """``(xs, ys, Z)`` when the points form a complete grid (each node once), else ``None``."""
    xs, ix = np.unique(x, return_inverse=True)
    ys, iy = np.unique(y, return_inverse=True)
    if xs.size * ys.size != x.size or xs.size < 2 or ys.size < 2:
        return None
    grid = np.full((xs.size, ys.size), np.nan)
    seen = np.zeros(grid.shape, dtype=bool)
    seen[ix, iy] = True
    if not seen.all():
        return None
    grid[ix, iy] = z
    for name, axis in (("x", xs), ("y", ys)):
        step = np.diff(axis)
        if np.abs(step - step.mean()).max() > _UNIFORM * step.mean():
            _refuse("file", file, f"its points lie on a grid whose {name} step varies from {step.min():.6g} to "
                                  f"{step.max():.6g} (not evenly spaced: coordinates rounded in the export?); "
                                  "give spacing to interpolate the points onto an even grid instead")
    return xs, ys, grid


def _read_xyz(file, spacing):
    """``(x, y, z)`` of an x-y-z point list: its own grid, or the points resampled (module docstring)."""
    pts = _load_table(file, "xyz")
    if pts.shape[1] != 3:
        _refuse("file", file, f"an x-y-z point list needs 3 columns, it has {pts.shape[1]} (wrong shape)")
    pts = pts[np.isfinite(pts[:, :2]).all(axis=1)]
    if pts.shape[0] < _MIN_POINTS:
        _refuse("file", file, f"an x-y-z point list needs at least {_MIN_POINTS} points, it has "
                              f"{pts.shape[0]} (too few points)")
    x, y, z = pts.T
    if spacing is None:
        grid = _grid_of_points(x, y, z, file)
        if grid is not None:
            return grid
    from scipy.interpolate import LinearNDInterpolator
    from scipy.spatial import QhullError, cKDTree

    ok = np.isfinite(z)
    try:
        interp = LinearNDInterpolator(np.column_stack([x[ok], y[ok]]), z[ok])
    except (QhullError, ValueError) as exc:
        _refuse("file", file, f"its points must span an area (too few points, or all on one line: {exc})")
    if spacing is None:
        dist, _ = cKDTree(np.column_stack([x, y])).query(np.column_stack([x, y]), k=2)
        spacing = (float(np.median(dist[:, 1])),) * 2
    xs = np.arange(x.min(), x.max() + 1e-9 * spacing[0], spacing[0])
    ys = np.arange(y.min(), y.max() + 1e-9 * spacing[1], spacing[1])
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    return xs, ys, interp(gx, gy)


def read_heights(file, *, format=None, spacing=None, nodata=None):
    """Read a height map (or a gap) from a file: ``(x, y, z)`` in the file's length unit.

    Parameters
    ----------
    file : str or os.PathLike
        The file (a relative name starts from the current directory).
    format : {"npy", "grid", "asc", "xyz"}, optional
        Default: from the extension (:data:`EXTENSIONS`); see the module docstring.
    spacing : float or (float, float), optional
        Grid step ``(dx, dy)`` [file length unit], ``> 0``; one number when ``dx = dy``.
        Required for npy and grid files, refused for asc (it has ``cellsize``); for xyz the
        step of the grid the points are interpolated onto.
    nodata : float, optional
        Value marking missing points (``.asc`` files also use their ``NODATA_value``).

    Returns
    -------
    x, y : ndarray
        Increasing grid coordinates [file length unit], as the file places them.
    z : ndarray
        ``z[i, j]`` at ``(x[i], y[j])`` [file length unit], NaN where there is no data.

    Raises
    ------
    bem.InputError
        Missing or unreadable file, wrong shape, too few points, a grid that is not evenly
        spaced, no finite value, or a bad argument; the message starts with its name.
    """
    fmt = file_format(file, format)
    file = os.fspath(file)
    if not os.path.isfile(file):
        _refuse("file", file, "there is no such file" + ("" if os.path.isabs(file) else f" in {os.getcwd()}"))
    if spacing is None and fmt in ("npy", "grid"):
        raise InputError(f"spacing is missing: a {fmt!r} file holds heights only; give the grid step (dx, dy) "
                         "(or one number) in the file's length unit.")
    if spacing is not None and fmt == "asc":
        _refuse("spacing", spacing, "an ESRI grid states its own step (cellsize); leave spacing out")
    spacing = None if spacing is None else _positive_pair("spacing", spacing)
    if nodata is not None and (isinstance(nodata, bool) or not isinstance(nodata, (int, float, np.number))):
        fail("nodata", nodata, "a number (the value that marks a missing point)")
    if fmt == "asc":
        x, y, z = _read_asc(file)
    elif fmt == "xyz":
        x, y, z = _read_xyz(file, spacing)
    else:
        x, y, z = _read_grid(file, fmt, spacing)
    if nodata is not None:
        z[z == nodata] = np.nan
    if not np.isfinite(z).any():
        _refuse("file", file, "it holds no finite value")
    return x, y, z


class RegionTable(Table):
    """A :class:`bem.gaps.Table` over the candidate region that gives points beyond its grid the
    value at the nearest edge instead of refusing them.

    The lattice evaluates the gap at every node of its brick array, including the masked node
    half a step beyond the region at the end of each odd row (a coarser step in nested solves);
    those values are never used. Every candidate node is inside (:meth:`Measured.region`).
    """

    def _inside(self, name, v, other):
        axis = self.x if name == "x" else self.y
        return np.clip(v, axis[0], axis[-1])


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
            Missing data (NaN, NODATA, outside the hull of x-y-z points) at a node of the
            region, too few nodes for ``method``, or negative values of ``kind = "gap"``.
        """
        ex, ey = _positive_pair(name, extent)
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
