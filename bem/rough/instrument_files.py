"""Measured topographies read from instrument files through SurfaceTopography.

:func:`read_surface` reads one of the formats SurfaceTopography knows (:func:`formats`: x3p,
sur, opd, datx, gwy, nc, npy, text matrices, x-y-z lists, ...) into a :class:`RoughSurface`
whose cell is the detrended patch (:mod:`bem.rough.surface`). Every error is a
:class:`bem.InputError` that names the argument and the file and quotes nothing from the file:
the readers' own messages and logs may hold its bytes, so only the kind of error is named and
the loggers of the readers tried while detecting a format are kept quiet.

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
from .surface import DETRENDS, MIN_POINTS, _pair, _surface, _surface_topography

__all__ = ["read_surface", "formats"]


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


def _read(st, handle, path, format, physical_sizes, channel, refuse):
    """The topography of an open file, checked before its data is read (:func:`read_surface`)."""
    try:  # the readers raise many kinds of errors, whose messages may quote the file: name the kind only
        reader = st.open_topography(handle, format=format)
    except Exception as exc:
        refuse(f"SurfaceTopography cannot read it as {format or 'any format it knows'} ({type(exc).__name__}); "
               "give format (bem.rough.formats()) or convert the file")
    channels = reader.channels
    if channel is not None and channel >= len(channels):
        fail("channel", channel, f"< {len(channels)}, the number of data channels of the file")
    info = reader.default_channel if channel is None else channels[channel]
    if not info.is_uniform:
        refuse("its points are not on an evenly spaced grid (non-uniform); resample them onto a regular grid")
    if info.dim != 2:
        refuse(f"it holds a {info.dim}-D line scan; a 2-D height map is needed")
    if min(info.nb_grid_pts) < MIN_POINTS:
        refuse(f"it holds {info.nb_grid_pts[0]} x {info.nb_grid_pts[1]} points; at least {MIN_POINTS} x "
               f"{MIN_POINTS} are needed (too small)")
    if info.physical_sizes is None and physical_sizes is None:
        raise InputError(f"physical_sizes is missing: file = {path!r} does not state its size; give (Lx, Ly) in "
                         "the file's length unit.")
    if info.physical_sizes is not None and physical_sizes is not None:
        fail("physical_sizes", physical_sizes, f"left out: file = {path!r} states its size "
                                               f"{tuple(float(s) for s in info.physical_sizes)}")
    kwargs = {} if physical_sizes is None else {"physical_sizes": physical_sizes}
    try:
        return reader.topography(channel_index=info.index, **kwargs)
    except Exception as exc:
        refuse(f"SurfaceTopography cannot read its data ({type(exc).__name__})")


def read_surface(file, *, format=None, physical_sizes=None, channel=None, scale=1.0, detrend="height"):
    """Read a measured topography with SurfaceTopography into a :class:`RoughSurface`.

    Parameters
    ----------
    file : str or os.PathLike
        The instrument file.
    format : str, optional
        One of :func:`formats`; default: detected from the file's contents.
    physical_sizes : (float, float), optional
        ``(Lx, Ly)`` [file length unit] when the file does not state its size (npy, plain
        text matrices); refused when it does.
    channel : int, optional
        Index of the data channel (default: the file's default channel).
    scale : float
        [solve length per file length unit], ``> 0``: multiplies every length (sizes and heights).
    detrend : str or None
        One of :data:`DETRENDS` (default ``"height"``: the plane of least rms height), or
        ``None`` to keep the heights as measured.

    Returns
    -------
    RoughSurface
        The detrended patch as a periodic cell, its statistics and edge jump (module
        docstring; a large jump is logged as a warning).

    Raises
    ------
    bem.InputError
        No such file, a format SurfaceTopography cannot read, a line scan, points not on an
        evenly spaced grid, missing data (NaN holes), fewer than 8 x 8 points, a missing or
        superfluous ``physical_sizes``, a bad argument; the message starts with its name and
        quotes nothing from the file. SurfaceTopography missing: the message names
        ``contactlab[rough]``.
    """
    st = _surface_topography()
    if not isinstance(file, (str, os.PathLike)):
        fail("file", file, "a file name (str or os.PathLike)")
    path = os.fspath(file)
    if format is not None:
        check_choice("format", format, formats())
    if physical_sizes is not None:
        physical_sizes = _pair("physical_sizes", physical_sizes)
    if channel is not None:
        channel = check_int("channel", channel, minimum=0)
    scale = check_positive("scale", scale)
    if detrend is not None:
        check_choice("detrend", detrend, DETRENDS)
    if not os.path.isfile(path):
        fail("file", path, "an existing file" + ("" if os.path.isabs(path) else f" (relative to {os.getcwd()})"))

    def refuse(rule):
        raise InputError(f"file = {path!r} is not allowed: {rule}.")

    try:
        handle = open(path, "rb")  # our handle: some readers leave the files they open open
    except OSError as exc:
        refuse(f"it cannot be opened ({type(exc).__name__})")
    with handle, _quiet_readers():
        topo = _read(st, handle, path, format, physical_sizes, channel, refuse)
    if topo.has_undefined_data:
        missing = int(np.ma.getmaskarray(topo.heights()).sum())
        refuse(f"it has {missing} points without data (NaN holes or missing data); fill or crop them first "
               "(SurfaceTopography: interpolate_undefined_data)")
    z = np.ma.getdata(topo.heights())
    if not np.isfinite(z).all():
        refuse(f"it has {int((~np.isfinite(z)).sum())} heights that are not finite (NaN or inf)")
    size = tuple(float(s) * scale for s in topo.physical_sizes)
    try:
        _pair("size", size)
    except InputError:
        refuse(f"the size it states times scale, ({size[0]:.4g}, {size[1]:.4g}), must be two lengths in "
               f"[{SCALE_RANGE[0]:g}, {SCALE_RANGE[1]:g}] (physical scales; the header's increments or scale "
               "are wrong)")
    if detrend is not None:
        z = np.ma.getdata(topo.detrend(detrend).heights())
    periodic = bool(topo.is_periodic) and detrend in (None, "center")  # a plane taken off breaks a period
    return _surface(np.array(z, dtype=float) * scale, size, periodic=periodic, source=path, unit=topo.unit,
                    detrend=detrend)
