"""Measured surfaces as the gap of a scene: ``[gap] type = "measured"`` reads a file of heights.

Keys of the ``[gap]`` table (every length of the file, and ``spacing``, in ``length_unit``)::

    type        = "measured"
    file        = "surface.npy"   # required; relative to the scene file's folder
    format      = "npy" | "grid" | "asc" | "xyz"   # default from the extension
    kind        = "gap" | "topography"             # default "gap"
    length_unit = "um"            # "m", "mm", "um" (or "µm"), "nm", or a factor to the scene's length unit
    spacing     = [dx, dy]        # grid step of .npy and grid files (a number when dx = dy)
    center      = "grid" | "minimum" | "file"      # default "grid"
    method      = "cubic"         # interpolation onto the lattice: linear, cubic, quintic, pchip
    nodata      = -9999.0         # value marking missing points (.asc: its NODATA_value)

Formats (``format`` inferred from the extension: ``.npy``; ``.csv``, ``.txt``, ``.dat``: grid;
``.asc``; ``.xyz``; give ``format = "xyz"`` for point lists in ``.csv`` or ``.txt`` files):

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
values are the heights ``z`` of one body's surface, measured outwards (towards the other
body, summits positive), the other body flat; the gap is ``h = max z - z`` over the
candidate region, so the highest summit there touches first (``h = 0``). Two rough surfaces:
add their topographies into one file first.

``center``: ``"grid"`` puts the middle of the data's bounding box at ``x = y = 0``;
``"minimum"`` the lowest point of the gap (the highest summit); ``"file"`` keeps the file's
coordinates (``.asc``: its lower-left corner, ``.xyz``: its columns, arrays: the first
point at the origin). The BEM candidate region ``|x| <= X``, ``|y| <= Y`` (``bem.extent``,
required with ``bem.step`` since there is no estimate of the contact size) must lie inside
the data and hold no missing point; the gap is interpolated (:class:`bem.gaps.Table`) on the
part of the grid that covers it.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from bem.gaps import Table

from ..units import METRES
from . import checks as ck

__all__ = ["MeasuredSurface", "RegionTable", "measured_gap", "measured_region", "read_surface", "KEYS", "FORMATS",
           "LENGTH_UNITS"]

KEYS = ("type", "file", "format", "kind", "length_unit", "spacing", "center", "method", "nodata")
FORMATS = {".npy": "npy", ".csv": "grid", ".txt": "grid", ".dat": "grid", ".asc": "asc", ".xyz": "xyz"}
#: metres per unit of the length units a measured file may name
LENGTH_UNITS = {k: METRES[k] for k in ("m", "mm", "um", "µm", "nm")}
_MIN_POINTS = 4  # of the scattered points of an xyz file
_UNIFORM = 1e-6  # relative tolerance of "evenly spaced"


class MeasuredSurface:
    """A measured grid ``z[i, j]`` at ``(x[i], y[j])`` in scene units, with NaN where data are missing.

    Not a gap yet: :func:`measured_region` turns it into a :class:`bem.gaps.Table` over the
    candidate region once the region is known. It has what sizing the region needs:
    ``domain`` (the data's bounding box), ``is_axisymmetric`` (False), ``type_name`` and
    :meth:`expected_semi_axes` (none).
    """

    type_name = "measured"
    is_axisymmetric = False

    def __init__(self, x, y, z, *, kind, method, file):
        self.x, self.y, self.z = x, y, z
        self.kind, self.method, self.file = kind, method, file
        self.domain = ((float(x[0]), float(x[-1])), (float(y[0]), float(y[-1])))

    def expected_semi_axes(self, **_):
        """No estimate of the contact size: the scene gives ``bem.step`` and ``bem.extent``."""
        return None

    def __call__(self, x, y):  # pragma: no cover - only the region's Table is ever evaluated
        raise TypeError("a MeasuredSurface is evaluated through measured_region(surface, extent)")


def _fail(key, value, rule):
    raise ck.SceneError(f"gap.{key} = {value!r} is not allowed: {rule}.")


def _factor(d, units):
    """Scene length units per length unit of the file (``gap.length_unit``)."""
    value = d.get("length_unit")
    if value is None:
        return 1.0
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return ck.positive("gap.length_unit", value)
    if not isinstance(value, str) or value not in LENGTH_UNITS:
        _fail("length_unit", value, f"it must be one of {', '.join(map(repr, LENGTH_UNITS))} or a positive "
                                    "factor from the file's numbers to the scene's length unit")
    scene = None if units is None else units.metres
    if scene is None:
        label = None if units is None else units.label
        _fail("length_unit", value, f"the scene's units label {label!r} names no length unit (m, mm, um, "
                                    "nm) to convert to; give the factor as a number instead")
    return LENGTH_UNITS[value] / scene


def _load_table(path, fmt, key="file"):
    """A 2-D table of numbers from a text file (comma- or whitespace-separated)."""
    try:
        with open(path, encoding="utf-8") as fh:
            lines = [ln for ln in fh.read().splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
        delimiter = "," if lines and "," in lines[0] else None
        table = np.loadtxt(lines, delimiter=delimiter, ndmin=2, dtype=float)
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        _fail(key, str(path), f"it must be a table of numbers for format = {fmt!r} ({exc})")
    return table


def _read_asc(path):
    """``(x, y, z)`` of an ESRI ASCII grid, cell centres, rows turned to increasing y."""
    header, rows = {}, []
    try:
        with open(path, encoding="utf-8") as fh:
            for line in fh:
                parts = line.split()
                if not parts:
                    continue
                if len(parts) == 2 and re.match(r"^[A-Za-z_]+$", parts[0]) and not rows:
                    header[parts[0].lower()] = float(parts[1])
                else:
                    rows.append([float(v) for v in parts])
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        _fail("file", str(path), f"it must be an ESRI ASCII grid ({exc})")
    need = [k for k in ("ncols", "nrows", "cellsize") if k not in header]
    if need or not any(k in header for k in ("xllcorner", "xllcenter")):
        _fail("file", str(path), f"an ESRI ASCII grid needs the header keys ncols, nrows, xllcorner (or xllcenter), "
                                 f"yllcorner (or yllcenter), cellsize; missing {need or ['xllcorner']}")
    nx, ny, c = int(header["ncols"]), int(header["nrows"]), header["cellsize"]
    if len(rows) != ny or any(len(r) != nx for r in rows):
        _fail("file", str(path), f"its header says nrows = {ny}, ncols = {nx} but the data has {len(rows)} rows of "
                                 f"{sorted({len(r) for r in rows})} values (wrong shape)")
    z = np.array(rows[::-1], dtype=float)  # first row is the northernmost
    if "nodata_value" in header:
        z[z == header["nodata_value"]] = np.nan
    shift = 0.0 if "xllcenter" in header else 0.5 * c
    x0 = header.get("xllcenter", header.get("xllcorner", 0.0)) + shift
    y0 = header.get("yllcenter", header.get("yllcorner", 0.0)) + (0.0 if "yllcenter" in header else 0.5 * c)
    return x0 + c * np.arange(nx), y0 + c * np.arange(ny), z.T


def _spacing(d, fmt):
    if "spacing" not in d:
        if fmt in ("npy", "grid"):
            raise ck.SceneError(f"gap.spacing is missing: a {fmt!r} file holds heights only; give the grid step "
                                "[dx, dy] (or one number) in gap.length_unit.")
        return None
    if fmt == "asc":
        _fail("spacing", d["spacing"], "an ESRI grid states its own step (cellsize); remove gap.spacing")
    return ck.number_or_pair("gap.spacing", d["spacing"], ck.positive)


def _grid_of_points(x, y, z, path):
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
            _fail("file", str(path), f"its points lie on a grid whose {name} step varies from {step.min():.6g} to "
                                 f"{step.max():.6g} (not evenly spaced: coordinates rounded in the export?); give "
                                 "gap.spacing to interpolate the points onto an even grid instead")
    return xs, ys, grid


def _read_xyz(path, fmt, spacing):
    pts = _load_table(path, fmt)
    if pts.shape[1] != 3:
        _fail("file", str(path), f"an x-y-z point list needs 3 columns, it has {pts.shape[1]} (wrong shape)")
    pts = pts[np.isfinite(pts[:, :2]).all(axis=1)]
    if pts.shape[0] < _MIN_POINTS:
        _fail("file", str(path), f"an x-y-z point list needs at least {_MIN_POINTS} points, it has "
                                 f"{pts.shape[0]} (too few points)")
    x, y, z = pts.T
    if spacing is None:
        grid = _grid_of_points(x, y, z, path)
        if grid is not None:
            return grid
    from scipy.interpolate import LinearNDInterpolator
    from scipy.spatial import QhullError, cKDTree

    ok = np.isfinite(z)
    try:
        interp = LinearNDInterpolator(np.column_stack([x[ok], y[ok]]), z[ok])
    except (QhullError, ValueError) as exc:
        _fail("file", str(path), f"its points must span an area (too few points, or all on one line: {exc})")
    if spacing is None:
        dist, _ = cKDTree(np.column_stack([x, y])).query(np.column_stack([x, y]), k=2)
        step = float(np.median(dist[:, 1]))
        spacing = (step, step)
    xs = np.arange(x.min(), x.max() + 1e-9 * spacing[0], spacing[0])
    ys = np.arange(y.min(), y.max() + 1e-9 * spacing[1], spacing[1])
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    return xs, ys, interp(gx, gy)


def read_surface(d, *, units=None):
    """Read the file of a ``[gap] type = "measured"`` table: ``(x, y, z, fmt)`` in scene units.

    ``z[i, j]`` is the value at ``(x[i], y[j])`` (NaN: no data), ``x`` and ``y`` increasing,
    before ``center`` is applied. ``units`` is the scene's :class:`validation.units.Units` (for ``length_unit``).

    Raises
    ------
    validation.scene.SceneError
        Missing or unreadable file, wrong shape, too few points, a grid that is not evenly
        spaced, or bad keys; the message names the key (``gap.file``, ``gap.spacing``, ...).
    """
    file = ck.string("gap.file", ck.require("gap", d, "file", 'give the measured surface, e.g. file = "z.npy"'))
    path = Path(file)
    suffix = path.suffix.lower()
    fmt = d.get("format", FORMATS.get(suffix))
    if fmt is None:
        _fail("file", file, f"its extension {suffix!r} does not tell the format; give gap.format = one of "
                            f"{sorted(set(FORMATS.values()))}")
    ck.choice("gap.format", fmt, sorted(set(FORMATS.values())))
    if not path.is_file():
        _fail("file", file, "there is no such file (a relative name starts from the scene file's folder)")
    factor = _factor(d, units)
    spacing = _spacing(d, fmt)
    if fmt == "asc":
        x, y, z = _read_asc(path)
    elif fmt == "xyz":
        x, y, z = _read_xyz(path, fmt, spacing)
    else:
        if fmt == "npy":
            try:
                z = np.load(path, allow_pickle=False)
            except (OSError, ValueError) as exc:
                _fail("file", file, f"it must be a .npy file of numbers ({exc})")
        else:
            z = _load_table(path, fmt)
        if z.ndim != 2 or min(z.shape) < 2 or z.dtype.kind not in "biuf":
            _fail("file", file, f"it must hold a 2-D array of numbers of at least 2 x 2 values, it has shape "
                                f"{z.shape} and dtype {z.dtype} (wrong shape)")
        z = np.asarray(z, dtype=float).T  # rows run along y
        x, y = spacing[0] * np.arange(z.shape[0]), spacing[1] * np.arange(z.shape[1])
    z = np.array(z, dtype=float)
    if "nodata" in d:
        nodata = d["nodata"]
        if isinstance(nodata, bool) or not isinstance(nodata, (int, float)):
            _fail("nodata", nodata, "it must be a number (the value that marks a missing point)")
        z[z == nodata] = np.nan
    if not np.isfinite(z).any():
        _fail("file", file, "it holds no finite value")
    return x * factor, y * factor, z * factor, fmt


def measured_gap(d, *, units=None):
    """``(spec, MeasuredSurface)`` of a ``[gap] type = "measured"`` table (see the module docstring)."""
    ck.unknown_keys("gap", d, KEYS)
    kind = ck.choice("gap.kind", d.get("kind", "gap"), ("gap", "topography"))
    center = ck.choice("gap.center", d.get("center", "grid"), ("grid", "minimum", "file"))
    x, y, z, fmt = read_surface(d, units=units)
    method = ck.choice("gap.method", d.get("method", "linear" if fmt == "xyz" else "cubic"), tuple(Table.MIN_POINTS))
    if center == "grid":
        x, y = x - 0.5 * (x[0] + x[-1]), y - 0.5 * (y[0] + y[-1])
    elif center == "minimum":
        low = np.where(np.isfinite(z), z if kind == "gap" else -z, np.inf)
        i, j = np.unravel_index(np.argmin(low), low.shape)
        x, y = x - x[i], y - y[j]
    spec = dict(d, format=fmt, kind=kind, center=center, method=method)
    return spec, MeasuredSurface(x, y, z, kind=kind, method=method, file=str(d["file"]))


class RegionTable(Table):
    """A :class:`bem.gaps.Table` over the candidate region that gives points beyond its grid the
    value at the nearest edge instead of refusing them.

    The lattice evaluates the gap at every node of its brick array, including the masked
    node half a step beyond the region at the end of each odd row (a coarser step in nested
    solves); those values are never used. Every candidate node lies inside the grid, which
    :func:`measured_region` checked.
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


def measured_region(gap, extent):
    """The gap over the candidate region: a :class:`bem.gaps.Table` for a :class:`MeasuredSurface`.

    Other gaps are returned as they are. The table holds the grid nodes covering
    ``|x| <= extent[0]``, ``|y| <= extent[1]`` [scene length]; for a topography the gap is
    ``max z - z`` over them.

    Raises
    ------
    validation.scene.SceneError
        Missing data (NaN, NODATA, outside the hull of x-y-z points) at a node of the
        region, too few nodes for ``gap.method``, or negative values of ``kind = "gap"``.
    """
    if not isinstance(gap, MeasuredSurface):
        return gap
    ex, ey = extent
    need = Table.MIN_POINTS[gap.method]
    (i0, i1), (j0, j1) = _cover(gap.x, ex, need), _cover(gap.y, ey, need)
    x, y, z = gap.x[i0:i1], gap.y[j0:j1], gap.z[i0:i1, j0:j1]
    if min(z.shape) < need:
        _fail("file", gap.file, f"the grid has only {z.shape[0]} x {z.shape[1]} points around the candidate region "
                                f"and gap.method = {gap.method!r} needs {need} per axis (too few points)")
    bad = ~np.isfinite(z)
    if bad.any():
        i, j = np.argwhere(bad)[0]
        _fail("file", gap.file, f"it has no data (NaN, NODATA or outside the measured points) at (x, y) = "
                                f"({x[i]:.6g}, {y[j]:.6g}), inside the candidate region |x| <= {ex:.6g}, "
                                f"|y| <= {ey:.6g} (bem.extent); make bem.extent smaller or fill in the data")
    h = z.max() - z if gap.kind == "topography" else z
    if gap.kind == "gap" and (h < 0).any():
        i, j = np.argwhere(h < 0)[0]
        _fail("file", gap.file, f"it holds the negative gap {h[i, j]:.6g} at (x, y) = ({x[i]:.6g}, {y[j]:.6g}); "
                                "a gap is a separation >= 0 (use gap.kind = 'topography' for surface heights)")
    with ck.scene_errors("gap."):
        return RegionTable(x, y, h, method=gap.method)
