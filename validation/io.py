"""The one writer of validation: JSON of numpy data, result directories written whole or not at
all, and the subsurface stress field.

Single files are written by :func:`bem.files.atomic_path` and the helpers built on it (a
temporary file in the target's directory moved over the target with :func:`os.replace`,
ordinary permissions). A directory is assembled in a hidden temporary directory beside the
target and renamed into place at the end (:func:`atomic_directory`); an exception or an
interrupt (``KeyboardInterrupt`` included) removes the temporary directory and leaves any
previous result untouched. Result directories and report directories both use it.

The subsurface stress field as a volume file ParaView opens (``stress_field.vtu``,
:func:`write_stress_field`) is a structured volume grid of hexahedra per body, written with
meshio (VTK XML, zlib-compressed) and atomically (:func:`bem.files.write_vtu`, the one writer).
The grid is the brick lattice of the candidate nodes (every ``stride``-th row and column, the
stride chosen so that the file holds at most :data:`MAX_POINTS` points) times the depths; a
cell joins two neighbouring rows, two neighbouring columns and two neighbouring depths (the odd
rows are shifted by half a step, so the cells are parallelepipeds). Global frame: ``z`` points
up into body 1 (the upper body, ``z = +depth``) and down into body 2 (``z = -depth``), as in
the FEM field; the lower body's shear stresses ``xz``, ``yz`` change sign accordingly.

Point data: ``stress`` (six components in VTK's order ``xx, yy, zz, xy, yz, xz``, so that
ParaView reads it as a symmetric tensor), ``von_mises`` and ``max_shear`` [pressure]; cell
data: ``body`` (1 or 2). Coordinates and fields are stored in single precision (a picture; the
numbers of record are in ``result.json`` and :func:`bem.subsurface_stress`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import logging
import math
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from bem.files import umask, write_text, write_vtu
from bem.stress import principal_stresses

__all__ = ["atomic_write_json", "atomic_directory", "to_jsonable", "OutputError", "RESULT_MARKER",
           "check_result_dir", "write_stress_field", "volume_grid", "MAX_POINTS"]

log = logging.getLogger(__name__)

#: A directory holding this file is a contactlab result directory (it may be replaced).
RESULT_MARKER = "result.json"


class OutputError(OSError):
    """The output location cannot be used (e.g. it is a non-empty foreign directory)."""


def to_jsonable(obj):
    """Plain JSON types from numpy scalars/arrays, tuples, paths, dataclasses and objects with
    ``to_dict()``; non-finite floats become None."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return to_jsonable(dataclasses.asdict(obj))
    if hasattr(obj, "to_dict") and callable(obj.to_dict):
        return to_jsonable(obj.to_dict())
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        value = float(obj)
        return value if math.isfinite(value) else None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def atomic_write_json(path, obj):
    """Write ``obj`` as indented JSON (strict: NaN/inf written as null) atomically."""
    text = json.dumps(to_jsonable(obj), indent=2, allow_nan=False) + "\n"
    return write_text(path, text)


def check_result_dir(target):
    """A result directory may be replaced if it does not exist, is empty, or holds ``result.json``.

    Raises
    ------
    OutputError
        ``target`` is a file, or a non-empty directory that is not a contactlab result.
    """
    if not target.exists():
        return
    if not target.is_dir():
        raise OutputError(f"out = {str(target)!r} is not allowed: it is a file; give a directory path.")
    if any(target.iterdir()) and not (target / RESULT_MARKER).is_file():
        raise OutputError(
            f"out = {str(target)!r} is not allowed: it is a non-empty directory that holds no "
            f"{RESULT_MARKER} (not a contactlab result); give a new or empty directory.")


@contextlib.contextmanager
def atomic_directory(target, *, check=check_result_dir):
    """Assemble a directory in a temporary place; move it to ``target`` only on success.

    Parameters
    ----------
    target : path-like
        The directory to create or replace.
    check : callable, optional
        ``check(target)`` raises if ``target`` may not be replaced (default
        :func:`check_result_dir`; the report builder passes its own rule).

    Yields
    ------
    pathlib.Path
        The temporary directory (beside ``target``, permissions of a new directory). On
        success an existing ``target`` is replaced; on any exception the temporary
        directory is removed and ``target`` is left as it was.

    Raises
    ------
    OutputError
        ``target`` is a file or a non-empty directory that is not a result directory.
    """
    target = Path(target).absolute()
    check(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.tmp-", dir=target.parent))
    try:
        os.chmod(tmp, 0o777 & ~umask())  # mkdtemp creates 0700
        yield tmp
        old = None
        if target.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{target.name}.old-", dir=target.parent))
            os.replace(target, old / "previous")
        try:
            os.replace(tmp, target)
        except BaseException:
            if old is not None:
                os.replace(old / "previous", target)
            raise
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
        log.info("written: %s", target)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)


# -- the stress field ---------------------------------------------------------------------------



MAX_POINTS = 150_000
"""Largest number of points (all bodies, all depths) of the volume file."""
_VOIGT_TO_VTK = (0, 1, 2, 5, 3, 4)  # xx, yy, zz, xy, yz, xz from xx, yy, zz, yz, xz, xy


def volume_grid(lattice, n_depths, n_bodies):
    """Rows and columns of the lattice kept in the volume grid, and the node index of each.

    Returns
    -------
    (rows, cols, nodes) : ndarray, ndarray, ndarray of shape (len(rows), len(cols))
        Brick rows and columns kept and the index of each kept node in the nodal arrays of
        :class:`bem.ContactResult` (masked nodes are never kept: the last column of odd rows
        lies outside the region, so the columns stop one short of it).
    """
    n_rows, n_cols = lattice.shape
    per_layer = MAX_POINTS / max(1, n_depths * n_bodies)
    stride = max(1, math.ceil(math.sqrt(n_rows * n_cols / per_layer)))
    rows = np.arange(0, n_rows, stride)
    cols = np.arange(0, n_cols - 1, stride)
    index = np.full(lattice.shape, -1, dtype=np.int64)
    index[lattice.mask] = np.arange(int(lattice.mask.sum()))
    return rows, cols, index[np.ix_(rows, cols)]


def _hexahedra(n_z, n_r, n_c, offset):
    """Cells of a structured (depth, row, column) block of points numbered from ``offset``."""
    k, i, j = np.meshgrid(np.arange(n_z - 1), np.arange(n_r - 1), np.arange(n_c - 1), indexing="ij")
    base = (k * n_r + i) * n_c + j
    layer = n_r * n_c
    quad = [base, base + 1, base + n_c + 1, base + n_c]  # counter-clockwise seen from +z
    cells = np.stack(quad + [q + layer for q in quad], axis=-1).reshape(-1, 8)
    return (cells + offset).astype(np.int32)


def write_stress_field(path, res, run):
    """Write the stresses of ``run`` (:class:`validation.run.stress.StressRun`) on ``res``'s lattice to ``path``.

    Parameters
    ----------
    path : path-like
        Target ``.vtu`` file (replaced atomically).
    res : bem.ContactResult
        The BEM solution (its lattice and node coordinates).
    run : validation.stress.StressRun
        Stresses on the candidate nodes at increasing depths.

    Returns
    -------
    pathlib.Path
    """
    from .run.stress import BODIES

    rows, cols, nodes = volume_grid(res.lattice, run.depths.size, len(run.bodies))
    flat = nodes.ravel()
    points, data, cells, body_id = [], [], [], []
    offset = 0
    for name, st in run.bodies.items():
        sign = BODIES[name][1]
        # lower body (depth downwards): reverse the depth order so that every cell's first face is its lowest
        order = np.arange(st.z.size) if sign > 0 else np.arange(st.z.size)[::-1]
        z = sign * st.z[order]
        x = np.broadcast_to(res.x[flat], (z.size, flat.size))
        y = np.broadcast_to(res.y[flat], (z.size, flat.size))
        points.append(np.stack([x, y, np.broadcast_to(z[:, None], x.shape)], axis=-1).reshape(-1, 3))
        sigma = st.sigma[order][:, flat].reshape(-1, 6).copy()
        if sign < 0:
            sigma[:, 3:5] *= -1.0  # yz, xz in the global frame
        principal = principal_stresses(sigma)
        data.append((sigma[:, _VOIGT_TO_VTK], st.von_mises[order][:, flat].ravel(),
                     0.5 * (principal[:, 0] - principal[:, 2])))
        hexa = _hexahedra(z.size, rows.size, cols.size, offset)
        cells.append(hexa)
        body_id.append(np.full(len(hexa), int(name[-1]), dtype=np.int32))
        offset += z.size * flat.size
    single = np.float32  # the fields in single precision: a volume is large
    return write_vtu(path, np.concatenate(points), [("hexahedron", np.concatenate(cells))],
                     point_data={name: np.concatenate([d[k] for d in data]).astype(single)
                                 for k, name in enumerate(("stress", "von_mises", "max_shear"))},
                     cell_data={"body": [np.concatenate(body_id)]})
