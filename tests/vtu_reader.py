"""An independent reader of the ``.vtu`` files contactlab writes, written from the VTK XML format.

VTK's file-format description: inline ``format="binary"`` arrays are base64; with
``compressor="vtkZLibDataCompressor"`` each array starts with the header
``[number of blocks, block size, last block size, compressed size of each block]`` (integers of
``header_type``, UInt32 by default), base64-encoded on its own, followed by the zlib blocks,
base64-encoded together. Used to check the files without the writer's own reader (meshio).
"""

import base64
import math
import zlib
from xml.etree import ElementTree

import numpy as np

TYPES = {"Float32": "f4", "Float64": "f8", "Int8": "i1", "Int16": "i2", "Int32": "i4", "Int64": "i8",
         "UInt8": "u1", "UInt16": "u2", "UInt32": "u4", "UInt64": "u8"}


def _decode(text, dtype, header, compressed, order):
    text = "".join(text.split())
    if not compressed:
        raw = base64.b64decode(text)
        return np.frombuffer(raw[header.itemsize:], dtype=dtype.newbyteorder(order))
    first = base64.b64decode(text[:4 * math.ceil(3 * header.itemsize / 3)])
    n_blocks = int(np.frombuffer(first[:header.itemsize], header)[0])
    n_header = 4 * math.ceil((3 + n_blocks) * header.itemsize / 3)
    sizes = np.frombuffer(base64.b64decode(text[:n_header]), header)[3:3 + n_blocks]
    data, start, out = base64.b64decode(text[n_header:]), 0, b""
    for size in sizes:
        out += zlib.decompress(data[start:start + int(size)])
        start += int(size)
    return np.frombuffer(out, dtype=dtype.newbyteorder(order))


def read_vtu(path):
    """``(points, cells, point_data, cell_data, attributes)`` of an UnstructuredGrid file.

    ``cells`` is ``(connectivity, offsets, types)``; ``attributes`` those of ``<VTKFile>``.
    """
    root = ElementTree.parse(path).getroot()
    assert root.tag == "VTKFile" and root.get("type") == "UnstructuredGrid"
    order = "<" if root.get("byte_order", "LittleEndian") == "LittleEndian" else ">"
    header = np.dtype(TYPES[root.get("header_type", "UInt32")]).newbyteorder(order)
    compressed = root.get("compressor") == "vtkZLibDataCompressor"
    piece = root.find("UnstructuredGrid/Piece")
    n_points, n_cells = int(piece.get("NumberOfPoints")), int(piece.get("NumberOfCells"))

    def arrays(tag):
        out = {}
        for da in piece.findall(f"{tag}/DataArray"):
            assert da.get("format") == "binary", da.get("format")
            values = _decode(da.text, np.dtype(TYPES[da.get("type")]), header, compressed, order)
            k = int(da.get("NumberOfComponents", "1"))
            out[da.get("Name")] = values.reshape(-1, k) if k > 1 else values
        return out

    points = arrays("Points")
    cells = arrays("Cells")
    assert len(points) == 1 and next(iter(points.values())).shape == (n_points, 3)
    assert cells["types"].size == n_cells
    return (next(iter(points.values())), (cells["connectivity"], cells["offsets"], cells["types"]),
            arrays("PointData"), arrays("CellData"), dict(root.attrib))
