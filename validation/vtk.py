"""A small VTK XML writer for the BEM nodal fields (ParaView opens the ``.vtu`` file).

Pure numpy: no meshio or pyvista, so a BEM-only run never imports them. The nodes of the
brick-stored triangular lattice (:class:`bem.lattice.Lattice`) are joined into the
equilateral triangles of the lattice itself (:func:`lattice_triangles`), so ParaView shows
the piecewise-linear pressure exactly as the BEM represents it (pyramid basis = linear
interpolation on these triangles). Arrays are written base64-encoded (``format="binary"``,
``header_type="UInt64"``) in one ``UnstructuredGrid`` piece.
"""

from __future__ import annotations

import base64
from xml.sax.saxutils import quoteattr

import numpy as np

from .output import atomic_write_text

__all__ = ["lattice_triangles", "write_vtu"]

_VTK_TRIANGLE = 5
_TYPES = {np.dtype(np.float64): "Float64", np.dtype(np.int64): "Int64", np.dtype(np.uint8): "UInt8"}


def lattice_triangles(lattice):
    """Triangles of the candidate lattice as node indices into the masked (nodal) arrays.

    Between brick rows ``r`` and ``r + 1`` (lattice rows ``j`` and ``j + 1``) the row of odd
    ``j`` is shifted by half a step, so with ``s = j mod 2``:

    - ``s = 0``: triangles ``(L_q, L_q+1, U_q)`` and ``(U_q, L_q+1, U_q+1)``;
    - ``s = 1``: triangles ``(L_q, U_q+1, U_q)`` and ``(L_q, L_q+1, U_q+1)``,

    where ``L``/``U`` are the lower/upper rows; all counter-clockwise. Triangles touching a
    masked-out node are dropped.

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


def _data_array(name, values, n_components=1):
    values = np.ascontiguousarray(values)
    kind = _TYPES[values.dtype]
    raw = values.tobytes()
    payload = base64.b64encode(np.uint64(len(raw)).tobytes() + raw).decode("ascii")
    return (f'<DataArray type="{kind}" Name={quoteattr(name)} NumberOfComponents="{n_components}" '
            f'format="binary">{payload}</DataArray>')


def write_vtu(path, x, y, triangles, point_data, *, z=None):
    """Write a triangulated surface with nodal fields as a VTK XML ``.vtu`` file, atomically.

    Parameters
    ----------
    path : path-like
        Target file (``.vtu``).
    x, y : array_like, shape (n,)
        Node coordinates [length]; ``z`` (default 0) the third coordinate.
    triangles : array_like of int, shape (m, 3)
        Node indices of the triangles.
    point_data : dict
        ``name -> array of shape (n,)`` (float) nodal fields.

    Returns
    -------
    pathlib.Path
    """
    x = np.asarray(x, dtype=np.float64)
    n = x.size
    z = np.zeros(n) if z is None else np.asarray(z, dtype=np.float64)
    points = np.column_stack([x, np.asarray(y, dtype=np.float64), z])
    tris = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    m = tris.shape[0]
    fields = "".join(_data_array(name, np.asarray(v, dtype=np.float64).reshape(n))
                     for name, v in point_data.items())
    text = (
        '<?xml version="1.0"?>\n'
        '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n'
        '<UnstructuredGrid>\n'
        f'<Piece NumberOfPoints="{n}" NumberOfCells="{m}">\n'
        f'<PointData>{fields}</PointData>\n'
        f'<Points>{_data_array("Points", points.astype("<f8"), 3)}</Points>\n'
        '<Cells>'
        f'{_data_array("connectivity", tris.ravel().astype("<i8"))}'
        f'{_data_array("offsets", (3 * np.arange(1, m + 1)).astype("<i8"))}'
        f'{_data_array("types", np.full(m, _VTK_TRIANGLE, dtype=np.uint8))}'
        '</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n'
    )
    return atomic_write_text(path, text)
