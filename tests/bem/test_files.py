"""bem.files: whole-or-nothing files with ordinary permissions, and the one .vtu writer."""

import os
import re
import stat
from pathlib import Path

import numpy as np
import pytest

import bem
from bem.files import atomic_path, lattice_triangles, write_bytes, write_result_vtu, write_text, write_vtu
from bem.gaps import Paraboloid
from bem.lattice import Lattice

from ..vtu_reader import read_vtu

ROOT = Path(__file__).resolve().parents[2]


def _mode(path):
    return stat.S_IMODE(os.stat(path).st_mode)


@pytest.fixture
def umask():
    """Set a umask for the test and restore the previous one."""
    saved = os.umask(0o022)
    yield os.umask
    os.umask(saved)


@pytest.mark.parametrize("mask, mode", [(0o022, 0o644), (0o027, 0o640), (0o002, 0o664)])
def test_files_get_the_permissions_of_a_new_file(tmp_path, umask, mask, mode):
    umask(mask)
    text = write_text(tmp_path / "a.txt", "x")
    vtu = write_vtu(tmp_path / "b.vtu", np.zeros((3, 3)), [("triangle", np.array([[0, 1, 2]]))])
    with atomic_path(tmp_path / "c.bin") as tmp:
        Path(tmp).write_bytes(b"1")
    (tmp_path / "plain").write_bytes(b"")  # what open() makes under the same umask
    for path in (text, vtu, tmp_path / "c.bin", tmp_path / "plain"):
        assert _mode(path) == mode, path


@pytest.mark.parametrize("exc", [RuntimeError("disk full"), KeyboardInterrupt()])
def test_a_failed_write_leaves_the_previous_file(tmp_path, exc):
    target = write_bytes(tmp_path / "f.json", b"old")
    with pytest.raises(type(exc)):
        with atomic_path(target) as tmp:
            Path(tmp).write_bytes(b"half")
            raise exc
    assert target.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["f.json"]


def test_temporary_name_is_hidden_beside_the_target(tmp_path):
    with atomic_path(tmp_path / "sub" / "x.vtu") as tmp:
        assert Path(tmp).parent == tmp_path / "sub" and Path(tmp).name.startswith(".x.vtu.")
        assert tmp.endswith(".vtu")
        Path(tmp).write_text("v")
    assert (tmp_path / "sub" / "x.vtu").read_text() == "v"


def test_vtu_is_compressed_and_exact(tmp_path):
    rng = np.random.default_rng(1)
    points = rng.normal(size=(7, 3))
    tris = np.array([[0, 1, 2], [2, 3, 4], [4, 5, 6]])
    p = rng.normal(size=7) * 1e9
    v = rng.normal(size=(7, 3))
    path = write_vtu(tmp_path / "m.vtu", points, [("triangle", tris)], {"p": p, "v": v},
                     {"body": [np.array([0, 1, 1], dtype=np.int32)]})
    got_points, (conn, offsets, types), point_data, cell_data, attrs = read_vtu(path)
    assert attrs["compressor"] == "vtkZLibDataCompressor"
    np.testing.assert_array_equal(got_points, points)
    np.testing.assert_array_equal(conn, tris.ravel())
    np.testing.assert_array_equal(offsets, [3, 6, 9])
    np.testing.assert_array_equal(types, [5, 5, 5])  # VTK_TRIANGLE
    np.testing.assert_array_equal(point_data["p"], p)
    np.testing.assert_array_equal(point_data["v"], v)
    np.testing.assert_array_equal(cell_data["body"], [0, 1, 1])


def test_bem_result_field(tmp_path):
    res = bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=0.1, extent=1.4)
    path = write_result_vtu(tmp_path / "bem.vtu", res, initial_gap=(res.x**2 + res.y**2) / 2)
    points, (conn, _, types), data, _, attrs = read_vtu(path)
    assert attrs["compressor"] == "vtkZLibDataCompressor"
    np.testing.assert_array_equal(points[:, 0], res.x)
    np.testing.assert_array_equal(points[:, 1], res.y)
    assert not points[:, 2].any()
    for name in ("p", "gap", "closure", "displacement"):
        np.testing.assert_array_equal(data[name], getattr(res, name))
    np.testing.assert_allclose(data["initial_gap"], (res.x**2 + res.y**2) / 2, rtol=0, atol=0)
    np.testing.assert_array_equal(conn.reshape(-1, 3), lattice_triangles(res.lattice))
    assert set(types) == {5}
    raw = os.path.getsize(path)
    assert raw < 0.7 * 8 * (4 * res.p.size + 3 * res.p.size)  # compressed below the raw float64 size


def test_lattice_triangles_are_exactly_the_lattice_cells():
    lat = Lattice.from_extent(0.1, (0.35, 0.3))
    tris = lattice_triangles(lat)
    area = np.sqrt(3) / 4 * 0.01
    x, y = lat.x[lat.mask], lat.y[lat.mask]
    a = 0.5 * ((x[tris[:, 1]] - x[tris[:, 0]]) * (y[tris[:, 2]] - y[tris[:, 0]])
               - (x[tris[:, 2]] - x[tris[:, 0]]) * (y[tris[:, 1]] - y[tris[:, 0]]))
    np.testing.assert_allclose(a, area, rtol=1e-12)


def test_one_writer_of_files_in_the_packages():
    """Temporary-file-and-rename appears only in bem.files (files) and validation.io (directories);
    meshio writes only in bem.files."""
    pattern = re.compile(r"\bos\.replace\(|\bos\.rename\(|\bmkstemp\(|\bmkdtemp\(|\bmeshio\.write\(")
    found = {}
    for package in ("bem", "fem_reference", "validation"):
        for path in (ROOT / package).rglob("*.py"):
            hits = pattern.findall(path.read_text(encoding="utf-8"))
            if hits:
                found[str(path.relative_to(ROOT))] = sorted(set(hits))
    assert set(found) == {"bem/files.py", "validation/io.py", "validation/folders.py"}, found
    assert "meshio.write(" not in found["validation/io.py"]
