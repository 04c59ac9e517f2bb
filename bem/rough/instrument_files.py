"""Measured topographies read from instrument files through SurfaceTopography.

:func:`read_surface` reads one of the formats SurfaceTopography knows (:func:`formats`: x3p,
sur, opd, datx, gwy, nc, npy, text matrices, x-y-z lists, ...) into a :class:`RoughSurface`
whose cell is the detrended patch (:mod:`bem.rough.surface`). Every error is a
:class:`bem.InputError` that names the argument and the file and quotes nothing from the file:
the readers' own messages and logs may hold its bytes, so only the kind of error is named and
the loggers of the readers tried while detecting a format are kept quiet.

**Units.** The lengths come back in ``length_unit`` (metres by default), converted from the
unit the file states; that unit is always the one used. ``unit`` names the file's unit only
for a file that states none (``.npy``, plain text matrices); given for a file that states
another unit, it is refused.

**Missing points.** Optical instruments leave points without data. A file with missing
points is refused unless ``fill = "harmonic"`` (SurfaceTopography's
``interpolate_undefined_data``: each missing height solves the discrete Laplace equation with
the measured points around it as boundary values), and refused in any case when more than
:data:`MAX_MISSING` = 5 % of its points are missing: a map that holes is not a measurement of
the surface. :attr:`SurfaceStats.filled` counts the points filled.

**Guards.** The header is checked before the data is read (:mod:`bem.rough.file_guards`):
more points than :func:`bem.checks.max_nodes`, an ``.x3p`` whose data does not match its
header or that would inflate beyond it, and a file that is not of the format its extension
names (random bytes called ``.x3p``) stop with a message naming the file.

Layouts differ between readers: SurfaceTopography takes a ``.npy`` array as ``z[ix, iy]``
(x first), while :func:`bem.gaps.measured.read_heights` takes it as rows along y; text
matrices are rows along y for both.
"""

from __future__ import annotations

import contextlib
import logging
import os

import numpy as np

from ..checks import SCALE_RANGE, InputError, check_choice, check_int, check_positive, fail
from .file_guards import check_points, guard_file, read_npy
from .surface import DETRENDS, MIN_POINTS, _pair, _surface, _surface_topography

__all__ = ["read_surface", "formats", "MAX_MISSING", "FILLS"]

#: largest fraction of missing points a file may have, filled or not
MAX_MISSING = 0.05
#: the ways of filling missing points (``fill`` of :func:`read_surface`)
FILLS = ("harmonic",)
#: extensions that several kinds of text share: the contents decide their reader
_TEXT_EXTENSIONS = ("txt", "csv", "asc", "xyz", "dat")


def formats():
    """The format names SurfaceTopography reads (the ``format`` of :func:`read_surface`)."""
    _surface_topography()
    from SurfaceTopography.IO import lookup_reader_by_format

    return tuple(sorted(lookup_reader_by_format))


#: loggers of readers SurfaceTopography tries while detecting a format, which log bytes of the file
_READER_LOGGERS = ("igor2",)


@contextlib.contextmanager
def _quiet_readers():
    """Keep the readers' own loggers from quoting the file (errors name the file, never its contents)."""
    loggers = [logging.getLogger(name) for name in _READER_LOGGERS]
    before = [lg.level for lg in loggers]
    for lg in loggers:  # their child loggers inherit the level
        lg.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for lg, level in zip(loggers, before):
            lg.setLevel(level)


def _named_reader(st, path):
    """The one reader format the file's extension names, or ``None`` (text, unknown or shared extensions)."""
    from SurfaceTopography.IO import readers

    ext = os.path.splitext(path)[1].lower().lstrip(".")
    if not ext or ext in _TEXT_EXTENSIONS:
        return None
    named = [r for r in readers if ext in (getattr(r, "_file_extensions", None) or ())]
    return named[0]._format if len(named) == 1 else None


def _open(st, handle, path, format, refuse):
    """The reader of an open file: ``format``, else the one its extension names, else detected."""
    named = None if format is not None else _named_reader(st, path)
    try:  # the readers raise many kinds of errors, whose messages may quote the file: name the kind only
        return st.open_topography(handle, format=format or named)
    except Exception as exc:
        if named is not None:
            refuse(f"it is not a readable {named} file (SurfaceTopography's {named} reader: {type(exc).__name__}); "
                   "give format (bem.rough.formats()) if it is of another format")
        refuse(f"SurfaceTopography cannot read it as {format or 'any format it knows'} ({type(exc).__name__}); "
               "give format (bem.rough.formats()) or convert the file")


def _read(st, handle, path, shown, format, physical_sizes, channel, refuse, name):
    """``(topography, stated unit)`` of an open file, checked before its data is read (:func:`read_surface`)."""
    reader = _open(st, handle, path, format, refuse)
    channels = reader.channels
    if channel is not None and channel >= len(channels):
        fail(name("channel"), channel, f"< {len(channels)}, the number of data channels of the file")
    info = reader.default_channel if channel is None else channels[channel]
    if not info.is_uniform:
        refuse("its points are not on an evenly spaced grid (non-uniform); resample them onto a regular grid")
    if info.dim != 2:
        refuse(f"it holds a {info.dim}-D line scan; a 2-D height map is needed")
    _check_grid(shown, info.nb_grid_pts, refuse)
    kwargs = _sizes(shown, info.physical_sizes, physical_sizes, name)
    try:
        return reader.topography(channel_index=info.index, **kwargs), info.unit
    except Exception as exc:
        refuse(f"SurfaceTopography cannot read its data ({type(exc).__name__})")


@contextlib.contextmanager
def _as_named(what):
    """Name the file as the caller's user does in the messages of :mod:`bem.rough.file_guards`."""
    try:
        yield
    except InputError as exc:
        message = str(exc)
        if what == "file" or not message.startswith("file = "):
            raise
        raise InputError(what + message[len("file"):]) from None


def _check_grid(path, shape, refuse):
    if min(shape) < MIN_POINTS:
        refuse(f"it holds {shape[0]} x {shape[1]} points; at least {MIN_POINTS} x {MIN_POINTS} are needed "
               "(too small)")
    with _as_named(refuse.what):
        check_points(path, shape)


def _sizes(path, stated, given, name):
    """The ``physical_sizes`` keyword of the reader: the file's own, or the one given."""
    if stated is None and given is None:
        raise InputError(f"{name('physical_sizes')} is missing: {name('file')} = {path!r} does not state its size; "
                         f"give {names_rule(name, 'physical_sizes', '(Lx, Ly)')} in the file's length unit.")
    if stated is not None and given is not None:
        fail(name("physical_sizes"), given, f"left out: {name('file')} = {path!r} states its size "
                                            f"{tuple(float(s) for s in stated)}")
    return {} if given is None else {"physical_sizes": given}


def _npy(st, path, shown, physical_sizes, refuse, name):
    """``(topography, None)`` of a ``.npy`` file, read by numpy after its header is checked."""
    with _as_named(refuse.what):
        z = read_npy(path, shown)
    _check_grid(shown, z.shape, refuse)
    kwargs = _sizes(shown, None, physical_sizes, name)
    return st.Topography(np.ma.masked_invalid(z) if not np.isfinite(z).all() else z, kwargs["physical_sizes"]), None


def _length(unit):
    """Metres per ``unit``: a SurfaceTopography length unit name, or ``None`` when it is not one."""
    from SurfaceTopography.Support.UnitConversion import length_units, mangle_length_unit_utf8

    return length_units.get(mangle_length_unit_utf8(unit)) if isinstance(unit, str) else None


def names_rule(name, key, rule):
    """The rule of the argument ``key`` as the caller's user knows it: ``name(key + "_rule")`` where the caller
    gives one (:func:`read_surface`, ``names``), else ``rule``."""
    given = name(f"{key}_rule")
    return rule if given == f"{key}_rule" else given


def _factor(path, stated, unit, length_unit, name):
    """Returned lengths per file length (module docstring, Units)."""
    if isinstance(length_unit, str):
        out = _length(length_unit)
        if out is None:
            fail(name("length_unit"), length_unit, "a length unit (m, mm, um, nm, ...) or metres per unit (a number)")
    else:
        out = check_positive(name("length_unit"), length_unit)
    if stated is not None:
        metres = _length(stated)
        if metres is None:
            raise InputError(f"{name('file')} = {path!r} is not allowed: it states the length unit {stated!r}, which "
                             "is not a known length unit; convert the file")
        factor = metres / out
        given = _length(unit) / out if isinstance(unit, str) else unit
        if unit is not None and not np.isclose(given, factor, rtol=1e-9, atol=0):
            fail(name("unit"), unit,
                 f"left out: {name('file')} = {path!r} states its lengths in {stated}, the unit used")
        return factor
    if unit is None:
        raise InputError(f"{name('unit')} is missing: {name('file')} = {path!r} states no length unit; give "
                         + names_rule(name, "unit", "its unit (m, mm, um, nm) or the returned lengths per file length")
                         + ".")
    return _length(unit) / out if isinstance(unit, str) else unit


def _missing(topo, fill, refuse, name):
    """``(topography without missing points, points filled)`` (module docstring, Missing points)."""
    if not topo.has_undefined_data:
        return topo, 0
    mask = np.ma.getmaskarray(topo.heights())
    missing, fraction = int(mask.sum()), float(mask.mean())
    said = f"it has {missing} points without data ({100 * fraction:.3g} % of {mask.size})"
    if fraction > MAX_MISSING:
        refuse(f"{said}, more than {100 * MAX_MISSING:g} %: crop it to a measured part first")
    if fill is None:
        refuse(f"{said}; fill them (give {name('fill')} = 'harmonic': interpolated from the points around them) or "
               "crop them")
    return topo.interpolate_undefined_data(fill), missing


def read_surface(file, *, format=None, physical_sizes=None, channel=None, unit=None, length_unit="m",
                 detrend="height", fill=None, source=None, names=None, unit_default=None):
    """Read a measured topography with SurfaceTopography into a :class:`RoughSurface`.

    Parameters
    ----------
    file : str or os.PathLike
        The instrument file.
    format : str, optional
        One of :func:`formats`; default: the one format the file's extension names, else
        detected from the file's contents.
    physical_sizes : (float, float), optional
        ``(Lx, Ly)`` [file length unit] when the file does not state its size (npy, plain
        text matrices); refused when it does.
    channel : int, optional
        Index of the data channel (default: the file's default channel).
    unit : str or float, optional
        The file's length unit, for a file that states none: ``"m"``, ``"mm"``, ``"um"``,
        ``"nm"`` (SurfaceTopography's names), or the returned lengths per file length
        (``> 0``). Refused when the file states another unit (module docstring).
    length_unit : str or float
        The unit of the returned lengths: a name as for ``unit``, or metres per returned
        length; default ``"m"``.
    detrend : str or None
        One of :data:`DETRENDS` (default ``"height"``: the plane of least rms height), or
        ``None`` to keep the heights as measured.
    fill : str, optional
        ``"harmonic"`` fills missing points (:data:`FILLS`, module docstring); default: a file
        with missing points is refused.
    source : str, optional
        What the statistics and warnings call the file (default: ``file`` as given).
    names : dict, optional
        The names the caller's user knows the arguments by, for messages (e.g.
        ``{"unit": "--scale", "physical_sizes": "--size"}``); ``"unit_rule"``: what a missing
        ``unit`` should be, in the caller's terms (e.g. ``"metres per unit of the file"``),
        ``"physical_sizes_rule"`` the same for ``physical_sizes`` (e.g. ``"--size LX,LY"``).
    unit_default : str or float, optional
        ``unit`` of a file that states none when ``unit`` is not given (a scene's own length
        unit); default: such a file needs ``unit``.

    Returns
    -------
    RoughSurface
        The detrended patch as a periodic cell [length_unit], its statistics and edge jump
        (:mod:`bem.rough.surface`; a large jump is logged as a warning), the file's unit in
        ``stats.unit``, the unit of the lengths in ``stats.length_unit`` (a name given as
        ``length_unit``) and the points filled in ``stats.filled``.

    Raises
    ------
    bem.InputError
        No such file, a format SurfaceTopography cannot read, a file that is not of the format
        its extension names, a header its data does not match, more points than
        :func:`bem.checks.max_nodes`, a line scan, points not on an evenly spaced grid,
        missing points (without ``fill``, or more than :data:`MAX_MISSING`), fewer than 8 x 8
        points, a missing or conflicting unit or ``physical_sizes``, a bad argument; the
        message starts with its name and quotes nothing from the file. SurfaceTopography
        missing: the message names ``contactlab[rough]``.
    """
    names = dict(names or {})

    def name(key):
        return names.get(key, key)

    if not isinstance(file, (str, os.PathLike)):
        fail(name("file"), file, "a file name (str or os.PathLike)")
    path = os.fspath(file)
    if physical_sizes is not None:
        physical_sizes = _pair(name("physical_sizes"), physical_sizes)
    if channel is not None:
        channel = check_int(name("channel"), channel, minimum=0)
    if unit is not None and not isinstance(unit, str):
        unit = check_positive(name("unit"), unit)
    if detrend is not None:
        check_choice(name("detrend"), detrend, DETRENDS)
    if fill is not None:
        check_choice(name("fill"), fill, FILLS)
    if not os.path.isfile(path):
        fail(name("file"), path, "an existing file" + ("" if os.path.isabs(path) else f" (relative to {os.getcwd()})"))

    shown = path if source is None else str(source)

    def refuse(rule):
        raise InputError(f"{name('file')} = {shown!r} is not allowed: {rule}.")

    refuse.what = name("file")

    st = _surface_topography()
    if format is not None:
        check_choice(name("format"), format, formats())
    if isinstance(unit, str) and _length(unit) is None:
        fail(name("unit"), unit, "a length unit (m, mm, um, nm, ...) or the returned lengths per file length")
    with _as_named(name("file")):
        guard_file(path, format, shown)
    if (format or os.path.splitext(path)[1].lower()) in ("npy", ".npy"):
        topo, stated = _npy(st, path, shown, physical_sizes, refuse, name)
    else:
        try:
            handle = open(path, "rb")  # our handle: some readers leave the files they open open
        except OSError as exc:
            refuse(f"it cannot be opened ({type(exc).__name__})")
        with handle, _quiet_readers():
            topo, stated = _read(st, handle, path, shown, format, physical_sizes, channel, refuse, name)
    factor = _factor(shown, stated, unit if unit is not None or stated is not None else unit_default, length_unit, name)
    topo, filled = _missing(topo, fill, refuse, name)
    z = np.ma.getdata(topo.heights())
    if not np.isfinite(z).all():
        refuse(f"it has {int((~np.isfinite(z)).sum())} heights that are not finite (NaN or inf)")
    size = tuple(float(s) * factor for s in topo.physical_sizes)
    try:
        _pair("size", size)
    except InputError:
        refuse(f"the size it states times scale, ({size[0]:.4g}, {size[1]:.4g}), must be two lengths in "
               f"[{SCALE_RANGE[0]:g}, {SCALE_RANGE[1]:g}] (physical scales; the header's increments or scale "
               "are wrong)")
    if detrend is not None:
        z = np.ma.getdata(topo.detrend(detrend).heights())
    periodic = bool(topo.is_periodic) and detrend in (None, "center")  # a plane taken off breaks a period
    said = stated if stated is not None else (unit if isinstance(unit, str) else None)
    return _surface(np.array(z, dtype=float) * factor, size, periodic=periodic, detrend=detrend,
                    source=shown, unit=said, filled=filled, fill=fill if filled else None,
                    length_unit=length_unit if isinstance(length_unit, str) else None)
