"""Height maps read from files: :func:`read_heights` gives ``(x, y, z)``, NaN where there is no data.

The formats, their coordinates and the limits on what a file may hold are described in
:mod:`bem.gaps.measured`. Every error is an :class:`bem.InputError` whose message starts with
the argument it blames and never shows the file's content.
"""

from __future__ import annotations

import itertools
import os
import re

import numpy as np

from ..checks import InputError, check_choice, check_positive, fail

__all__ = ["read_heights", "file_format", "EXTENSIONS", "FORMATS", "MAX_FILE_BYTES", "MAX_GRID_VALUES"]

#: the format of a file by its extension
EXTENSIONS = {".npy": "npy", ".csv": "grid", ".txt": "grid", ".dat": "grid", ".asc": "asc", ".xyz": "xyz"}
FORMATS = ("asc", "grid", "npy", "xyz")
_MIN_POINTS = 4  # of the scattered points of an xyz file
_UNIFORM = 1e-6  # relative tolerance of "evenly spaced"
#: largest text file (grid, asc, xyz) read [bytes]; checked before reading
MAX_FILE_BYTES = 512 * 2**20
#: most grid points a height map may hold (a file's grid, or the grid an xyz file is resampled
#: onto): 8192 x 8192, 512 MiB of float64; checked before the grid is allocated
MAX_GRID_VALUES = 8192 * 8192
_NPY_MAGIC = b"\x93NUMPY"


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


def _check_size(file, fmt):
    """Refuse a text file larger than :data:`MAX_FILE_BYTES` before reading it."""
    size = os.path.getsize(file)
    if size > MAX_FILE_BYTES:
        _refuse("file", file, f"it holds {size} bytes, more than the {MAX_FILE_BYTES} bytes a {fmt!r} text file "
                              "may hold (bem.gaps.MAX_FILE_BYTES); save a large map as .npy")


def _not_numbers(exc):
    """Where a text table stops being numbers, from numpy's message, without its content."""
    text = str(exc)
    bad = re.search(r"to \w+ at row (\d+), column (\d+)", text)  # numpy: row from 0, column from 1
    if bad is not None:
        return f"data row {int(bad[1]) + 1}, column {bad[2]} is not a number"
    ragged = re.search(r"columns changed from (\d+) to (\d+) at row (\d+)", text)  # numpy: row from 1
    if ragged is not None:
        return f"data row {ragged[3]} has {ragged[2]} values, the rows before it {ragged[1]}"
    return "a value is not a number, or the rows differ in length"


def _load_table(file, fmt):
    """A 2-D table of numbers from a text file (comma- or whitespace-separated), read line by line
    (the peak memory is about that of the table)."""
    _check_size(file, fmt)
    rule = f"it must be a UTF-8 text table of numbers for format = {fmt!r} (blank and # lines left out)"
    try:
        with open(file, encoding="utf-8") as fh:
            lines = (ln for ln in fh if ln.strip() and not ln.lstrip().startswith("#"))
            first = next(lines, None)
            if first is None:
                _refuse("file", file, f"{rule}: it holds none")
            delimiter = "," if "," in first else None
            return np.loadtxt(itertools.chain([first], lines), delimiter=delimiter, ndmin=2, dtype=float)
    except (OSError, UnicodeDecodeError) as exc:
        _refuse("file", file, f"{rule} ({type(exc).__name__})")
    except ValueError as exc:
        _refuse("file", file, f"{rule}: {_not_numbers(exc)}")


def _load_npy(file):
    """The array of a .npy file, its header (shape, type, size) checked before the data is read."""
    with open(file, "rb") as fh:
        start = fh.read(len(_NPY_MAGIC))
    if start != _NPY_MAGIC:
        _refuse("file", file, "it is not a valid .npy file: it does not start with the .npy header (an empty "
                              "file, or another format: save the array with numpy.save)")
    try:
        mapped = np.load(file, mmap_mode="r", allow_pickle=False)  # reads the header only
    except (OSError, ValueError, EOFError):
        _refuse("file", file, "it is not a valid .npy file: its header cannot be read, or its data is shorter "
                              "than the header says (a truncated file?), or it holds Python objects")
    shape, dtype = mapped.shape, mapped.dtype
    if len(shape) != 2 or min(shape) < 2 or dtype.kind not in "biuf":
        _refuse("file", file, f"it must hold a 2-D array of numbers of at least 2 x 2 values, it has shape "
                              f"{shape} and dtype {dtype} (wrong shape)")
    if shape[0] * shape[1] > MAX_GRID_VALUES:
        _refuse("file", file, f"its array of shape {shape} holds more than the {MAX_GRID_VALUES} values a height "
                              "map may hold (bem.gaps.MAX_GRID_VALUES)")
    return np.array(mapped)


def _read_grid(file, fmt, spacing):
    """``(x, y, z)`` of an npy or grid file: rows along y, steps ``spacing = (dx, dy)``."""
    z = _load_npy(file) if fmt == "npy" else _load_table(file, fmt)
    if z.ndim != 2 or min(z.shape) < 2 or z.dtype.kind not in "biuf":
        _refuse("file", file, f"it must hold a 2-D array of numbers of at least 2 x 2 values, it has shape "
                              f"{z.shape} and dtype {z.dtype} (wrong shape)")
    z = np.array(z, dtype=float).T  # rows run along y
    return spacing[0] * np.arange(z.shape[0]), spacing[1] * np.arange(z.shape[1]), z


def _read_asc(file):
    """``(x, y, z)`` of an ESRI ASCII grid, cell centres, rows turned to increasing y."""
    _check_size(file, "asc")
    header, rows, number = {}, [], 0
    try:
        with open(file, encoding="utf-8") as fh:
            for number, line in enumerate(fh, 1):  # noqa: B007 - the line number names a bad line
                parts = line.split()
                if not parts:
                    continue
                if len(parts) == 2 and re.match(r"^[A-Za-z_]+$", parts[0]) and not rows:
                    header[parts[0].lower()] = float(parts[1])
                else:
                    rows.append([float(v) for v in parts])
    except (OSError, UnicodeDecodeError) as exc:
        _refuse("file", file, f"it must be an ESRI ASCII grid in UTF-8 text ({type(exc).__name__})")
    except ValueError:
        _refuse("file", file, f"it must be an ESRI ASCII grid: line {number} holds a value that is not a number")
    need = [k for k in ("ncols", "nrows", "cellsize") if k not in header]
    if need or not any(k in header for k in ("xllcorner", "xllcenter")):
        _refuse("file", file, f"an ESRI ASCII grid needs the header keys ncols, nrows, xllcorner (or xllcenter), "
                              f"yllcorner (or yllcenter), cellsize; missing {need or ['xllcorner']}")
    nx, ny, c = int(header["ncols"]), int(header["nrows"]), header["cellsize"]
    if not (np.isfinite(c) and c > 0):
        _refuse("file", file, f"its header has cellsize = {c!r}: the grid step must be finite and > 0")
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
    given = spacing is not None
    if not given:
        dist, _ = cKDTree(np.column_stack([x, y])).query(np.column_stack([x, y]), k=2)
        spacing = (float(np.median(dist[:, 1])),) * 2
    n = ((x.max() - x.min()) / spacing[0] + 1) * ((y.max() - y.min()) / spacing[1] + 1)
    if not n <= MAX_GRID_VALUES:
        rule = (f"the points span {x.max() - x.min():.6g} x {y.max() - y.min():.6g}, and a step of "
                f"{spacing[0]:.6g} x {spacing[1]:.6g} would resample them onto {n:.3g} grid points, more than "
                f"{MAX_GRID_VALUES} (bem.gaps.MAX_GRID_VALUES)")
        if given:
            fail("spacing", spacing, f"a coarser step: {rule}")
        raise InputError(f"spacing is missing: {rule} (the default step is the median distance between the "
                         "points); give a coarser spacing.")
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
