"""The subsurface stress field as a volume file ParaView opens (``stress_field.vtu``).

A structured volume grid of hexahedra per body, written with meshio (VTK XML, zlib-compressed)
and atomically (:func:`bem.files.write_vtu`, the one writer). The grid is the brick lattice of
the candidate nodes (every ``stride``-th row and column, the stride chosen so that the file
holds at most :data:`MAX_POINTS` points) times the depths; a cell joins two neighbouring rows,
two neighbouring columns and two neighbouring depths (the odd rows are shifted by half a step,
so the cells are parallelepipeds). Global frame: ``z`` points up into body 1 (the upper body,
``z = +depth``) and down into body 2 (``z = -depth``), as in the FEM field; the lower body's
shear stresses ``xz``, ``yz`` change sign accordingly.

Point data: ``stress`` (six components in VTK's order ``xx, yy, zz, xy, yz, xz``, so that
ParaView reads it as a symmetric tensor), ``von_mises`` and ``max_shear`` [pressure]; cell
data: ``body`` (1 or 2). Coordinates and fields are stored in single precision (a picture; the
numbers of record are in ``result.json`` and :func:`bem.subsurface_stress`).
"""

from __future__ import annotations

import math

import numpy as np

from bem.files import write_vtu
from bem.stress import principal_stresses

__all__ = ["write_stress_field", "volume_grid", "MAX_POINTS"]

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
    """Write the stresses of ``run`` (:class:`validation.stress.StressRun`) on ``res``'s lattice to ``path``.

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
    from .stress import BODIES

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
