"""Writing files whole or not at all, and the one ParaView (``.vtu``) writer of the toolkit.

Every file contactlab writes (result JSON, scene TOML, field ``.vtu``, figure
PNG, study tables) goes through :func:`atomic_path`: the content is written to a temporary
file in the target's own directory, given the permissions of any new file (``0666`` less the
process umask, i.e. ``0644`` under the usual umask ``022``; ``tempfile.mkstemp`` alone would
leave ``0600``) and moved over the target with :func:`os.replace`, atomic on POSIX and
Windows within one file system. A reader never sees a half-written file, and an error or an
interrupt leaves the previous file, or none.

The helpers live here, in :mod:`bem`, because the packages depend one way,
``validation -> fem_reference -> bem``: the lowest package is the only place both others can
import. :func:`write_vtu` writes any mesh with point and cell data through meshio (VTK XML,
binary, zlib-compressed); :func:`write_result_vtu` gives it the BEM lattice as triangles, :func:`write_stress_vtu` the
lattice times the depths as hexahedra, and :mod:`fem_reference.fields` its quadratic
triangles, so there is one writer for every field.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

import numpy as np

__all__ = ["atomic_path", "write_bytes", "write_text", "file_mode", "umask", "write_vtu", "lattice_triangles",
           "write_result_vtu", "write_stress_vtu", "volume_grid", "MAX_POINTS"]

#: largest number of points (all bodies, all depths) of :func:`write_stress_vtu`'s volume file
MAX_POINTS = 150_000
_VOIGT_TO_VTK = (0, 1, 2, 5, 3, 4)  # xx, yy, zz, xy, yz, xz from xx, yy, zz, yz, xz, xy


def umask():
    """The process umask (read by setting and restoring it), e.g. ``0o022``."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def file_mode():
    """Permission bits of a new file under the current umask (``0o666 & ~umask``).

    Returns
    -------
    int
        E.g. ``0o644`` under the usual umask ``0o022``.
    """
    return 0o666 & ~umask()


@contextlib.contextmanager
def atomic_path(path, suffix=None):
    """Yield a temporary path beside ``path``; on success move it onto ``path``.

    Write the file at the yielded path (any writer that takes a file name: numpy, meshio,
    gmsh, Pillow, ``open``). When the block ends without an exception the file gets the
    permissions of a new file (:func:`file_mode`) and replaces ``path`` atomically; on any
    exception (``KeyboardInterrupt`` included) it is removed and ``path`` is left as it was.

    Parameters
    ----------
    path : path-like
        The target file; its directory is created if needed.
    suffix : str, optional
        Suffix of the temporary name (default: that of ``path``), for writers that choose the
        format by extension.

    Yields
    ------
    str
        The temporary file name (hidden: ``.<name>.<random><suffix>``).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix if suffix is None else suffix,
                               dir=path.parent)
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, file_mode())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def write_bytes(path, data):
    """Write ``data`` (bytes) to ``path`` whole or not at all (:func:`atomic_path`).

    Returns
    -------
    pathlib.Path
    """
    path = Path(path)
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())
    return path


def write_text(path, text):
    """Write the string ``text`` (UTF-8) to ``path`` whole or not at all. Returns the path."""
    return write_bytes(path, text.encode("utf-8"))


def write_vtu(path, points, cells, point_data=None, cell_data=None):
    """Write a mesh with fields as a compressed VTK XML ``.vtu`` file (ParaView), atomically.

    Parameters
    ----------
    path : path-like
        Target file (``.vtu``).
    points : array_like, shape (n, 3)
        Node coordinates [length].
    cells : list of (str, array_like of int)
        meshio cell blocks, e.g. ``[("triangle", tris)]`` or ``[("triangle6", conn)]``.
    point_data : dict, optional
        ``name -> array`` of shape ``(n,)`` or ``(n, k)`` (nodal fields, in the caller's units).
    cell_data : dict, optional
        ``name -> [array per cell block]``.

    Returns
    -------
    pathlib.Path

    Notes
    -----
    Binary arrays, zlib-compressed (``compressor="vtkZLibDataCompressor"``); float64 values
    are written exactly.
    """
    import meshio

    mesh = meshio.Mesh(np.asarray(points, dtype=np.float64), cells, point_data=point_data or {},
                       cell_data=cell_data or {})
    path = Path(path)
    with atomic_path(path, suffix=".vtu") as tmp:
        meshio.write(tmp, mesh, file_format="vtu", binary=True, compression="zlib")
    return path


def lattice_triangles(lattice):
    """Triangles of the candidate lattice as node indices into the masked (nodal) arrays.

    Between brick rows ``r`` and ``r + 1`` (lattice rows ``j`` and ``j + 1``) the row of odd
    ``j`` is shifted by half a step, so with ``s = j mod 2``:

    - ``s = 0``: triangles ``(L_q, L_q+1, U_q)`` and ``(U_q, L_q+1, U_q+1)``;
    - ``s = 1``: triangles ``(L_q, U_q+1, U_q)`` and ``(L_q, L_q+1, U_q+1)``,

    where ``L``/``U`` are the lower/upper rows; all counter-clockwise. Triangles touching a
    masked-out node are dropped. On these triangles linear interpolation is exactly the
    BEM's pyramid basis, so ParaView shows the pressure as the BEM represents it.

    Parameters
    ----------
    lattice : bem.lattice.Lattice

    Returns
    -------
    ndarray of int64, shape (n_triangles, 3)
        Indices into ``values[lattice.mask]`` (the order of :class:`bem.ContactResult` arrays).
    """
    mask = lattice.mask
    index = np.full(lattice.shape, -1, dtype=np.int64)
    index[mask] = np.arange(int(mask.sum()))
    n_rows, n_cols = lattice.shape
    q = np.arange(n_cols - 1)
    tris = []
    for r in range(n_rows - 1):
        lo, up = index[r], index[r + 1]
        if lattice.parity[r] == 0:
            t = [(lo[q], lo[q + 1], up[q]), (up[q], lo[q + 1], up[q + 1])]
        else:
            t = [(lo[q], up[q + 1], up[q]), (lo[q], lo[q + 1], up[q + 1])]
        tris.extend(np.stack(tri, axis=1) for tri in t)
    tris = np.concatenate(tris) if tris else np.zeros((0, 3), dtype=np.int64)
    return tris[(tris >= 0).all(axis=1)]


def write_result_vtu(path, result, **extra):
    """Write the nodal fields of a BEM result on its lattice triangles (:func:`write_vtu`).

    Parameters
    ----------
    path : path-like
        Target ``.vtu`` file.
    result : bem.ContactResult
        Points ``(x, y, 0)`` [length]; point data ``p`` [pressure], ``gap``, ``closure``,
        ``displacement`` [length].
    **extra : array_like, shape (n,)
        More nodal fields, e.g. ``initial_gap=gap(result.x, result.y)``.

    Returns
    -------
    pathlib.Path
    """
    x = np.asarray(result.x, dtype=np.float64)
    points = np.column_stack([x, np.asarray(result.y, dtype=np.float64), np.zeros(x.size)])
    fields = {"p": result.p, "gap": result.gap, "closure": result.closure, "displacement": result.displacement,
              **extra}
    point_data = {name: np.asarray(v, dtype=np.float64).reshape(x.size) for name, v in fields.items()}
    return write_vtu(path, points, [("triangle", lattice_triangles(result.lattice))], point_data)


def volume_grid(lattice, n_depths, n_bodies):
    """Rows and columns of the lattice kept in the volume grid of :func:`write_stress_vtu`.

    Every ``stride``-th brick row and column, the stride chosen so that the file holds at most
    :data:`MAX_POINTS` points.

    Returns
    -------
    (rows, cols, nodes) : ndarray, ndarray, ndarray of shape (len(rows), len(cols))
        Brick rows and columns kept and the index of each kept node in the nodal arrays of
        :class:`bem.ContactResult` (masked nodes are never kept: the last column of odd rows
        lies outside the region, so the columns stop one short of it).
    """
    n_rows, n_cols = lattice.shape
    per_layer = MAX_POINTS / max(1, n_depths * n_bodies)
    stride = max(1, int(np.ceil(np.sqrt(n_rows * n_cols / per_layer))))
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


def write_stress_vtu(path, result, upper=None, lower=None):
    """Write subsurface stresses as a volume of hexahedra ParaView opens, atomically (:func:`write_vtu`).

    The grid is the brick lattice of the candidate nodes (:func:`volume_grid`) times the depths;
    a cell joins two neighbouring rows, columns and depths (odd rows are shifted by half a step,
    so the cells are parallelepipeds). Global frame, as in the FEM field: ``z`` points up into
    the upper body (``z = +depth``) and down into the lower one (``z = -depth``), whose shear
    stresses ``yz``, ``xz`` change sign accordingly.

    Parameters
    ----------
    path : path-like
        Target ``.vtu`` file.
    result : bem.ContactResult
        The BEM solution the stresses were computed from (its lattice and nodes).
    upper, lower : bem.SubsurfaceStress or bem.CoatedStress, optional
        Stresses of the upper body (cell data ``body = 0``) and of the lower one (``body = 1``),
        numbered as in the FEM reference's field file ``fem_field.vtu``,
        on the candidate nodes at increasing depths [length]. A coated body's coating and
        substrate are two blocks of cells that meet at the interface without sharing points (each
        holds its own side's stresses there, :meth:`bem.CoatedStress.layers`), the cell data
        ``coating`` 1 in the coating, 0 elsewhere.

    Returns
    -------
    pathlib.Path

    Notes
    -----
    Point data: ``stress`` (six components in VTK's order ``xx, yy, zz, xy, yz, xz``, which
    ParaView reads as a symmetric tensor), ``von_mises`` and ``max_shear`` [pressure]; single
    precision (a picture: the numbers of record are those of :func:`bem.subsurface_stress`
    and :func:`bem.coated_stress`).
    """
    from .stress import principal_stresses

    bodies = [(body, sign, _blocks(st)) for body, sign, st in ((0, 1.0, upper), (1, -1.0, lower)) if st is not None]
    depths = max(sum(b[0].size for b in blocks) for *_, blocks in bodies)
    rows, cols, nodes = volume_grid(result.lattice, depths, len(bodies))
    flat = nodes.ravel()
    points, data, cells, body_id, coating = [], [], [], [], []
    offset = 0
    for body, sign, blocks in bodies:
        for depth, stress, von_mises, in_coating in blocks:
            # lower body (depth downwards): reverse the depth order so that every cell's first face is its lowest
            order = np.arange(depth.size) if sign > 0 else np.arange(depth.size)[::-1]
            z = sign * depth[order]
            x = np.broadcast_to(result.x[flat], (z.size, flat.size))
            y = np.broadcast_to(result.y[flat], (z.size, flat.size))
            points.append(np.stack([x, y, np.broadcast_to(z[:, None], x.shape)], axis=-1).reshape(-1, 3))
            sigma = stress[order][:, flat].reshape(-1, 6).copy()
            if sign < 0:
                sigma[:, 3:5] *= -1.0  # yz, xz in the global frame
            principal = principal_stresses(sigma)
            data.append((sigma[:, _VOIGT_TO_VTK], von_mises[order][:, flat].ravel(),
                         0.5 * (principal[:, 0] - principal[:, 2])))
            hexa = _hexahedra(z.size, rows.size, cols.size, offset)
            cells.append(hexa)
            body_id.append(np.full(len(hexa), body, dtype=np.int32))
            coating.append(np.full(len(hexa), in_coating, dtype=np.int32))
            offset += z.size * flat.size
    return write_vtu(path, np.concatenate(points), [("hexahedron", np.concatenate(cells))],
                     point_data={name: np.concatenate([d[k] for d in data]).astype(np.float32)
                                 for k, name in enumerate(("stress", "von_mises", "max_shear"))},
                     cell_data={"body": [np.concatenate(body_id)], "coating": [np.concatenate(coating)]})


def _blocks(st):
    """``(z, sigma, von_mises, in_coating)`` blocks of a body's stresses: the body (``in_coating = 0``), or a
    coated body's coating (1) and substrate (0, none when rigid), each with its side of the interface."""
    from .coated_subsurface import CoatedStress

    if not isinstance(st, CoatedStress):
        return [(st.z, st.sigma, st.von_mises, 0)]
    z, sigma, von_mises, inside = st.layers()
    return [(z[m], sigma[m], von_mises[m], flag) for m, flag in ((inside, 1), (~inside, 0)) if m.any()]
