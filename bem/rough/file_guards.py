"""Checks of an instrument file made from its header, before its data is read or inflated.

A file may declare more points than memory holds, hold data that does not match its header,
or be a compressed archive that inflates far beyond its size. :func:`guard_file` reads only
what the format declares (numpy's ``.npy`` header; an ``.x3p`` archive's directory and its
``main.xml``) and refuses:

- a file larger than :data:`MAX_BYTES_PER_POINT` bytes per point of the largest grid
  (:func:`bem.checks.max_nodes` of a surface grid), before any reader sees it;
- a grid of more than :func:`bem.checks.max_nodes` points (:func:`check_points`, also called
  on the grid every other format declares);
- an ``.x3p`` that is not a zip archive or has no readable ``main.xml``, whose ``main.xml``
  is larger than :data:`MAX_HEADER_BYTES`, or whose data member does not hold exactly
  ``SizeX SizeY`` values of its declared ``DataType`` (``I`` int16, ``L`` int32, ``F``
  float32, ``D`` float64): the sizes an archive's directory declares bound what is inflated.

Messages name the file and quote nothing from it.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ElementTree
import zipfile

import numpy as np

from ..checks import InputError, check_node_count, max_nodes

__all__ = ["guard_file", "check_points", "read_npy", "MAX_BYTES_PER_POINT", "MAX_HEADER_BYTES"]

#: largest file per point of the largest grid: a text matrix spends about 25 bytes a number
MAX_BYTES_PER_POINT = 32
#: largest ``main.xml`` of an ``.x3p`` archive [bytes]
MAX_HEADER_BYTES = 16 * 2**20
_X3P_ITEMSIZE = {"I": 2, "L": 4, "F": 4, "D": 8}


def _refuse(path, rule):
    raise InputError(f"file = {path!r} is not allowed: {rule}.")


def check_points(path, shape, shown=None):
    """Refuse a grid ``shape`` of more than :func:`bem.checks.max_nodes` points (a memory guard);
    ``shown``: the file's name in messages (default ``path``)."""
    n = int(np.prod([int(s) for s in shape]))
    try:
        check_node_count("file", path, n, what="the surface grid")
    except InputError:
        grid = " x ".join(str(int(s)) for s in shape)
        _refuse(shown or path, f"it declares {grid} = {float(n):.3g} points, more than the "
                               f"{float(max_nodes('the surface grid')):.3g} of the largest grid this machine's memory "
                               "holds; crop or subsample it first")
    return n


def _npy_header(path, shown):
    """``(shape, fortran_order, dtype, offset)`` of a ``.npy`` file, from its header alone."""
    with open(path, "rb") as f:
        try:
            version = np.lib.format.read_magic(f)
            read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
            shape, fortran, dtype = read(f)
        except Exception as exc:  # numpy's messages may quote the header
            _refuse(shown, f"it is not a readable .npy file ({type(exc).__name__})")
        return shape, fortran, dtype, f.tell()


def read_npy(path, shown=None):
    """The heights of a ``.npy`` file, checked against its header before they are read.

    SurfaceTopography's layout: ``z[ix, iy]`` (x first). Refuses arrays that are not 2-D real
    numbers, more points than the limit, and a file shorter than its header declares.
    """
    shown = shown or path
    shape, fortran, dtype, offset = _npy_header(path, shown)
    if len(shape) != 2:
        _refuse(shown, f"it holds a {len(shape)}-D array; a 2-D height map is needed")
    if dtype.kind not in "fiu" or dtype.hasobject:
        _refuse(shown, f"it holds {dtype.kind!r} values; real numbers are needed")
    check_points(path, shape, shown)
    need = offset + int(np.prod(shape)) * dtype.itemsize
    if os.path.getsize(path) < need:
        _refuse(shown, f"it is shorter ({os.path.getsize(path)} bytes) than the {shape} array its header declares")
    z = np.lib.format.open_memmap(path, mode="r")
    return np.array(z, dtype=float)


def _x3p(path, shown):
    """Check an ``.x3p`` archive's header against its data member (module docstring)."""
    try:
        archive = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, OSError, ValueError) as exc:
        _refuse(shown, f"it is not a readable x3p file (not a zip archive: {type(exc).__name__})")
    with archive:
        members = {info.filename: info for info in archive.infolist()}
        main = members.get("main.xml")
        if main is None:
            _refuse(shown, "it is not a readable x3p file (no main.xml in the archive)")
        if main.file_size > MAX_HEADER_BYTES:
            _refuse(shown, f"its main.xml declares {main.file_size} bytes (limit {MAX_HEADER_BYTES}): not an x3p "
                           "header")
        try:
            root = ElementTree.fromstring(archive.read(main))
            dims = root.find("Record3/MatrixDimension")
            nx, ny, nz = (int(dims.find(k).text) for k in ("SizeX", "SizeY", "SizeZ"))
            kind = root.find("Record1/Axes/CZ/DataType").text.strip()
            link = root.find("Record3/DataLink/PointDataLink").text.strip()
        except Exception as exc:
            _refuse(shown, f"it is not a readable x3p file (main.xml lacks the sizes, data type or data link: "
                          f"{type(exc).__name__})")
    if kind not in _X3P_ITEMSIZE or nx < 1 or ny < 1 or nz != 1:
        _refuse(shown, "it is not a readable x3p file (its main.xml declares no 2-D grid of I, L, F or D values)")
    check_points(path, (nx, ny), shown)
    data = members.get(link)
    need = nx * ny * _X3P_ITEMSIZE[kind]
    if data is None or data.file_size != need:
        held = "no such member" if data is None else f"{data.file_size} bytes"
        _refuse(shown, f"its data does not match its header: main.xml declares {nx} x {ny} values of type {kind} "
                      f"({need} bytes), the data member holds {held}")


def guard_file(path, format=None, shown=None):
    """Refuse ``path`` from its size and header before a reader sees it (module docstring).

    ``format``: the format asked for, or ``None`` (then the extension decides which header is
    read); ``shown``: the file's name in messages (default ``path``).
    """
    shown = shown or path
    size = os.path.getsize(path)
    largest = max_nodes("the surface grid")
    if size > MAX_BYTES_PER_POINT * largest:
        _refuse(shown, f"it is {size / 2**30:.3g} GiB, more than a file of the largest grid this machine's memory "
                      f"holds ({float(largest):.3g} points) needs; crop or subsample it first")
    kind = format or os.path.splitext(path)[1].lower().lstrip(".")
    if kind == "x3p":
        _x3p(path, shown)
    elif kind == "npy":
        check_points(path, _npy_header(path, shown)[0], shown)
