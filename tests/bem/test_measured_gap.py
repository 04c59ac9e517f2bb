"""bem.gaps.measured on its own: reading height maps, the gap over a region, errors naming the argument."""

import numpy as np
import pytest

from bem.checks import InputError
from bem.gaps import GAPS, Measured, read_heights
from bem.gaps.measured import RegionTable

R = 2.0  # radius of the paraboloid [length]


def _paraboloid(x, y):
    return (x**2 + y**2) / (2 * R)


def _grid(n=21, step=0.1):
    x = (np.arange(n) - (n - 1) / 2) * step
    y = (np.arange(n + 4) - (n + 3) / 2) * step
    return x, y, _paraboloid(*np.meshgrid(x, y, indexing="ij"))


def test_read_asc_gives_cell_centres_rows_to_increasing_y_and_nodata(tmp_path):
    rows = np.array([[1.0, 2.0, 3.0], [4.0, -9999.0, 6.0]])  # first row northernmost (largest y)
    text = "ncols 3\nnrows 2\nxllcorner 10.0\nyllcorner -1.0\ncellsize 0.5\nNODATA_value -9999\n"
    (tmp_path / "s.asc").write_text(text + "\n".join(" ".join(map(str, r)) for r in rows) + "\n")
    x, y, z = read_heights(tmp_path / "s.asc")
    np.testing.assert_allclose(x, [10.25, 10.75, 11.25])
    np.testing.assert_allclose(y, [-0.75, -0.25])
    np.testing.assert_array_equal(z, [[4.0, 1.0], [np.nan, 2.0], [6.0, 3.0]])  # z[i, j] at (x[i], y[j])


def test_read_xyz_on_a_grid_in_any_order_and_scattered(tmp_path):
    x, y, z = _grid()
    X, Y = np.meshgrid(x, y, indexing="ij")
    pts = np.column_stack([X.ravel(), Y.ravel(), z.ravel()])
    np.savetxt(tmp_path / "g.xyz", np.random.default_rng(3).permutation(pts))
    gx, gy, gz = read_heights(tmp_path / "g.xyz")
    np.testing.assert_allclose(gx, x, atol=1e-15)
    np.testing.assert_allclose(gy, y, atol=1e-15)
    np.testing.assert_allclose(gz, z, atol=1e-15)
    # scattered points of a plane, linear on their triangles: the plane inside their hull, NaN outside
    xy = np.random.default_rng(4).uniform(-1.0, 1.0, size=(400, 2))
    np.savetxt(tmp_path / "p.txt", np.column_stack([xy, 1.0 + 2.0 * xy[:, 0] - xy[:, 1]]), delimiter=",")
    sx, sy, sz = read_heights(tmp_path / "p.txt", format="xyz", spacing=0.05)
    assert sx[1] - sx[0] == pytest.approx(0.05) and sy[1] - sy[0] == pytest.approx(0.05)
    ok = np.isfinite(sz)
    assert ok.mean() > 0.8
    SX, SY = np.meshgrid(sx, sy, indexing="ij")
    np.testing.assert_allclose(sz[ok], (1.0 + 2.0 * SX - SY)[ok], atol=1e-12)


def test_read_npy_and_grid_rows_along_y(tmp_path):
    z = np.arange(6.0).reshape(2, 3)  # z[i, j] at x = j dx, y = i dy
    np.save(tmp_path / "z.npy", z)
    np.savetxt(tmp_path / "z.csv", z, delimiter=",", header="a comment")
    for name in ("z.npy", "z.csv"):
        x, y, h = read_heights(tmp_path / name, spacing=(0.5, 2.0), nodata=5.0)
        np.testing.assert_allclose(x, [0.0, 0.5, 1.0])
        np.testing.assert_allclose(y, [0.0, 2.0])
        np.testing.assert_array_equal(h, [[0.0, 3.0], [1.0, 4.0], [2.0, np.nan]])


@pytest.mark.parametrize("method", ["cubic", "quintic"])
def test_region_of_a_paraboloid_is_the_paraboloid(method):
    x, y, z = _grid()
    gap = Measured(x + 7.0, y - 3.0, z, method=method)  # centred on the grid
    table = gap.region((0.6, 0.45))
    assert isinstance(table, RegionTable) and table.method == method
    assert table.x[0] <= -0.6 and table.x[-1] >= 0.6 and table.y[0] <= -0.45 and table.y[-1] >= 0.45
    px, py = np.random.default_rng(5).uniform(-1.0, 1.0, size=(2, 300)) * np.array([[0.6], [0.45]])
    np.testing.assert_allclose(table(px, py), _paraboloid(px, py), atol=1e-12)
    # points beyond the grid take the edge's value instead of failing
    assert table(np.array([5.0]), np.array([0.0]))[0] == pytest.approx(_paraboloid(table.x[-1], 0.0), abs=1e-12)
    assert gap.expected_semi_axes(E_star=1.0, force=1.0) is None and "measured" not in GAPS


def test_topography_from_file_scaled_with_the_summit_at_the_origin(tmp_path):
    _x, _y, z = _grid()
    np.save(tmp_path / "top.npy", (5.0 - np.roll(z, (3, -2), axis=(0, 1))).T)  # summit off the centre
    gap = Measured.from_file(tmp_path / "top.npy", spacing=0.1, kind="topography", center="minimum", scale=1e-3)
    assert (gap.format, gap.kind, gap.method, gap.file) == ("npy", "topography", "cubic", str(tmp_path / "top.npy"))
    table = gap.region(0.2e-3)  # the gap max z - z over the region, in the solve's unit (scale)
    px, py = np.random.default_rng(6).uniform(-0.2e-3, 0.2e-3, size=(2, 200))
    np.testing.assert_allclose(table(px, py), 1e-3 * _paraboloid(px * 1e3, py * 1e3), atol=1e-15)


def test_measured_does_not_modify_its_arrays():
    x, y, z = _grid()
    z[0, 0] = np.nan
    copies = [a.copy() for a in (x, y, z)]
    for center in ("grid", "minimum", "file"):
        gap = Measured(x, y, z, center=center, kind="topography")
        if all(lo <= -0.5 and hi >= 0.5 for lo, hi in gap.domain):
            gap.region(0.5)
        else:  # the origin is near an edge of the data: no region |x|, |y| <= 0.5 inside them
            with pytest.raises(InputError, match="must lie inside the measured data"):
                gap.region(0.5)
        for a, b in zip((x, y, z), copies):
            np.testing.assert_array_equal(a, b)
    assert Measured(x, y, z, center="file").x[0] == x[0]


def test_errors_name_the_argument(tmp_path):
    x, y, z = _grid()
    np.save(tmp_path / "z.npy", z)
    with pytest.raises(InputError, match=r"^spacing is missing: a 'npy' file"):
        read_heights(tmp_path / "z.npy")
    with pytest.raises(InputError, match=r"^spacing\[1\] = -1.0 is not allowed"):
        read_heights(tmp_path / "z.npy", spacing=[1, -1])
    with pytest.raises(InputError, match=r"^format = 'tiff' is not allowed"):
        read_heights(tmp_path / "z.npy", format="tiff")
    with pytest.raises(InputError, match=r"^nodata = 'none' is not allowed"):
        read_heights(tmp_path / "z.npy", spacing=1.0, nodata="none")
    with pytest.raises(InputError, match=r"^file = .*absent.npy' is not allowed: there is no such file"):
        read_heights(tmp_path / "absent.npy", spacing=1.0)
    with pytest.raises(InputError, match=r"^file = .*\.bin' is not allowed: its extension '.bin'"):
        read_heights(tmp_path / "z.bin")
    with pytest.raises(InputError, match=r"^kind = 'rough' is not allowed"):
        Measured.from_file(tmp_path / "z.npy", spacing=1.0, kind="rough")
    with pytest.raises(InputError, match=r"^scale = 0.0 is not allowed"):
        Measured.from_file(tmp_path / "z.npy", spacing=1.0, scale=0)
    hole = z.copy()
    hole[10, 12] = np.nan
    with pytest.raises(InputError, match=r"^z is not allowed: it has no data .* \(extent\); make extent smaller"):
        Measured(x, y, hole).region(0.3)
    np.save(tmp_path / "hole.npy", hole.T)
    with pytest.raises(InputError, match=r"^file = .*hole.npy' is not allowed: it has no data .*make X smaller"):
        Measured.from_file(tmp_path / "hole.npy", spacing=0.1).region((0.3, 0.3), name="X")
    with pytest.raises(InputError, match=r"^z is not allowed: it holds the negative gap"):
        Measured(x, y, z - 1.0).region(0.3)
    with pytest.raises(InputError, match=r"^z.shape = \(25, 21\) is not allowed"):
        Measured(x, y, z.T)


def test_files_that_are_not_height_maps_say_what_they_are(tmp_path):
    (tmp_path / "empty.npy").write_bytes(b"")
    (tmp_path / "zeros.npy").write_bytes(bytes(4096))
    np.save(tmp_path / "full.npy", np.ones((30, 40)))
    (tmp_path / "cut.npy").write_bytes((tmp_path / "full.npy").read_bytes()[:-100])
    np.save(tmp_path / "flat.npy", np.ones(0))
    for name in ("empty", "zeros"):
        with pytest.raises(InputError, match=rf"^file = .*{name}.npy' is not allowed: it is not a valid .npy file: it "
                                             "does not start with the .npy header"):
            read_heights(tmp_path / f"{name}.npy", spacing=1.0)
    with pytest.raises(InputError, match=r"cut.npy' is not allowed: it is not a valid .npy file: .*shorter"):
        read_heights(tmp_path / "cut.npy", spacing=1.0)
    with pytest.raises(InputError, match=r"flat.npy' is not allowed: .*2-D array .* shape \(0,\)"):
        read_heights(tmp_path / "flat.npy", spacing=1.0)


def test_asc_cellsize_must_be_positive(tmp_path):
    head = "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize {}\n1 2 3\n4 5 6\n"
    for cellsize in ("0", "-1", "nan"):
        (tmp_path / "s.asc").write_text(head.format(cellsize))
        with pytest.raises(InputError, match=r"^file = .*s.asc' is not allowed: its header has cellsize = "):
            read_heights(tmp_path / "s.asc")


def test_large_files_and_grids_are_refused_before_they_are_read(tmp_path, monkeypatch):
    rng = np.random.default_rng(3)
    pts = rng.uniform(0.0, 1.0, (50, 3))
    np.savetxt(tmp_path / "p.xyz", pts)
    # 1e6 x 1e6 nodes: refused by the size the step implies, before any grid is allocated
    with pytest.raises(InputError, match=r"^spacing = \(1e-06, 1e-06\) is not allowed: .* more than 67108864"):
        read_heights(tmp_path / "p.xyz", spacing=1e-6)
    size = (tmp_path / "p.xyz").stat().st_size
    monkeypatch.setattr("bem.gaps.heights.MAX_FILE_BYTES", size - 1)
    monkeypatch.setattr("builtins.open", None)  # the file is refused by its size, never opened
    with pytest.raises(InputError, match=rf"^file = .*p.xyz' is not allowed: it holds {size} bytes, more than"):
        read_heights(tmp_path / "p.xyz")
    monkeypatch.undo()
    monkeypatch.setattr("bem.gaps.heights.MAX_GRID_VALUES", 30 * 40 - 1)
    np.save(tmp_path / "full.npy", np.ones((30, 40)))
    with pytest.raises(InputError, match=r"full.npy' is not allowed: its array of shape \(30, 40\) holds more"):
        read_heights(tmp_path / "full.npy", spacing=1.0)


def test_errors_never_show_the_files_content(tmp_path):
    (tmp_path / "secret.csv").write_text("1,2,3\n4,root:x:0:0,6\n")
    (tmp_path / "secret.asc").write_text("ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\nroot:x 3\n")
    for name, kw, where in (("secret.csv", {"spacing": 1.0}, "data row 2, column 2"),
                            ("secret.csv", {"format": "xyz"}, "data row 2, column 2"),
                            ("secret.asc", {}, "line 7")):
        with pytest.raises(InputError) as info:
            read_heights(tmp_path / name, **kw)
        assert where in str(info.value) and "root" not in str(info.value).replace(str(tmp_path), "")


def test_a_region_beyond_the_data_is_refused_naming_the_data_extent():
    x, y, z = _grid()  # x in [-1, 1], y in [-1.2, 1.2]
    gap = Measured(x, y, z)
    with pytest.raises(InputError, match=r"^extent = 1.5 is not allowed: the candidate region \|x\| <= 1.5, "
                                         r"\|y\| <= 1.5 must lie inside the measured data, x in \[-1, 1\], "
                                         r"y in \[-1.2, 1.2\]"):
        gap.region(1.5)
    with pytest.raises(InputError, match=r"^X = \(0.5, 1.3\) is not allowed: .* y in \[-1.2, 1.2\]"):
        gap.region((0.5, 1.3), name="X")
    table = gap.region(1.0)  # the whole data: allowed
    import bem

    kw = dict(E_star=1.0, force=1e-3, step=0.05)
    with pytest.raises(InputError, match=r"^extent = 2.0 is not allowed: .*measured data of this gap table, x in "
                                         r"\[-1, 1\]"):
        bem.solve(table, extent=2.0, **kw)
    assert bem.solve(gap.region(0.5), extent=0.5, **kw).converged
