"""Measured surfaces as a scene's gap ([gap] type = "measured"): every file format gives the gap it
holds (a measured paraboloid solves as the Paraboloid scene does), and every bad file is refused
at scene-check time with the key named."""

import json

import numpy as np
import pytest

from validation.run import execute_scene, run_scene
from validation.scene import SceneError, load_scene
from tomli_w import dumps

from .conftest import cli

R = 0.01  # m
STEP, EXTENT = 1e-5, 3e-4  # m: lattice step and candidate region half-width
DX = 5.0  # um: grid step of the files
N = 161  # grid points per axis: +-400 um
BASE = {"scene": {"name": "measured", "units": "SI (m, Pa, N)"},
        "bodies": {"E1": 210e9, "nu1": 0.3, "E2": 210e9, "nu2": 0.3},
        "load": {"force": 100.0}, "bem": {"step": STEP, "extent": EXTENT}}


def _axis(n=N, dx=DX, shift=0.0):
    return (np.arange(n) - (n - 1) / 2) * dx + shift


def _paraboloid_um(x, y):
    """The gap r^2 / (2 R) in um at (x, y) in um."""
    return (x**2 + y**2) * 1e-12 / (2 * R) * 1e6


def _grid(shift=(0.0, 0.0)):
    """Rows along y: z[i, j] at (x[j], y[i]) [um]."""
    x, y = _axis(shift=shift[0]), _axis(shift=shift[1])
    X, Y = np.meshgrid(x, y)
    return x, y, _paraboloid_um(X, Y)


def _scene(tmp_path, gap, name="scene.toml", **extra):
    raw = {**BASE, "gap": gap, **extra}
    path = tmp_path / name
    path.write_text(dumps(raw))
    return path


@pytest.fixture(scope="module")
def paraboloid():
    return execute_scene({**BASE, "gap": {"type": "paraboloid", "R": R}}).bem


def _assert_same(result, reference, rtol=1e-9):
    np.testing.assert_allclose(result.p, reference.p, atol=rtol * reference.p_max)
    assert result.approach == pytest.approx(reference.approach, rel=rtol)


def _write_asc(path, z_rows_north_first, *, cellsize=DX, nodata=None, corner=(-400.0 - DX / 2, -400.0 - DX / 2)):
    ny, nx = z_rows_north_first.shape
    head = [f"ncols {nx}", f"nrows {ny}", f"xllcorner {corner[0]}", f"yllcorner {corner[1]}", f"cellsize {cellsize}"]
    if nodata is not None:
        head.append(f"NODATA_value {nodata}")
    body = "\n".join(" ".join(f"{v:.17g}" for v in row) for row in z_rows_north_first)
    path.write_text("\n".join(head) + "\n" + body + "\n")


def test_npy_paraboloid_solves_as_the_paraboloid_scene(tmp_path, paraboloid):
    _x, _y, z = _grid()
    np.save(tmp_path / "surface.npy", z)
    scene = _scene(tmp_path, {"type": "measured", "file": "surface.npy", "length_unit": "um", "spacing": DX})
    result = execute_scene(scene).bem  # cubic splines reproduce the quadratic exactly
    _assert_same(result, paraboloid)


def test_csv_grid_in_other_units_and_minimum_centring(tmp_path, paraboloid):
    x, y, z = _grid(shift=(60.0, -35.0))  # the lowest point is off the grid's centre
    z = _paraboloid_um(*np.meshgrid(x - 60.0, y + 35.0))
    np.savetxt(tmp_path / "surface.csv", z * 1e-3, delimiter=",", header="heights in mm")  # mm
    gap = {"type": "measured", "file": "surface.csv", "length_unit": 1e-3, "spacing": [DX * 1e-3, DX * 1e-3],
           "center": "minimum"}
    result = execute_scene(_scene(tmp_path, gap)).bem
    _assert_same(result, paraboloid)


def test_asc_topography_with_nodata_outside_the_region(tmp_path, paraboloid):
    _x, _y, z = _grid()
    top = 3.0 - z  # heights of a sphere's surface measured outwards [um]: summit at the centre
    top[:12, :] = -9999.0  # missing data far outside the candidate region
    _write_asc(tmp_path / "sphere.asc", top[::-1], nodata=-9999)
    gap = {"type": "measured", "file": "sphere.asc", "kind": "topography", "length_unit": "um"}
    result = execute_scene(_scene(tmp_path, gap)).bem
    _assert_same(result, paraboloid)


def test_xyz_points_on_a_grid_and_scattered(tmp_path, paraboloid):
    x, y, z = _grid()
    X, Y = np.meshgrid(x, y)
    pts = np.column_stack([X.ravel(), Y.ravel(), z.ravel()])
    rng = np.random.default_rng(13)
    np.savetxt(tmp_path / "grid.xyz", rng.permutation(pts))  # any order
    gap = {"type": "measured", "file": "grid.xyz", "length_unit": "um", "method": "cubic"}
    _assert_same(execute_scene(_scene(tmp_path, gap)).bem, paraboloid)
    # scattered points, linear on their triangles, resampled on a 4 um grid: close, not exact
    xy = rng.uniform(-420.0, 420.0, size=(40000, 2))
    np.savetxt(tmp_path / "points.txt", np.column_stack([xy, _paraboloid_um(*xy.T)]), delimiter=",")
    gap = {"type": "measured", "file": "points.txt", "format": "xyz", "length_unit": "um", "spacing": 4.0}
    scattered = execute_scene(_scene(tmp_path, gap, name="scattered.toml")).bem
    assert scattered.p_max == pytest.approx(paraboloid.p_max, rel=0.02)
    assert scattered.approach == pytest.approx(paraboloid.approach, rel=0.05)


def test_relative_file_follows_the_scene_and_the_result_reloads(tmp_path, monkeypatch, paraboloid):
    _x, _y, z = _grid()
    (tmp_path / "data").mkdir()
    np.save(tmp_path / "data" / "surface.npy", z)
    scene = _scene(tmp_path / "data", {"type": "measured", "file": "surface.npy", "length_unit": "um",
                                       "spacing": DX})
    monkeypatch.chdir(tmp_path)  # elsewhere: the file is found next to the scene
    run_scene(str(scene), tmp_path / "out")
    saved = (tmp_path / "out" / "scene.toml").read_text()
    assert str(tmp_path / "data" / "surface.npy") in saved  # absolute in the effective scene
    monkeypatch.chdir(tmp_path / "out")  # the file lies outside the effective scene's folder: opt in
    again = execute_scene(load_scene("scene.toml", allow_outside_files=True)).bem
    _assert_same(again, paraboloid)
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result["converged"]


def _bad(tmp_path, gap, name="scene.toml", **bem):
    raw = {**BASE, "gap": gap}
    if bem:
        raw["bem"] = {**BASE["bem"], **bem}
    path = tmp_path / name
    path.write_text(dumps(raw))
    with pytest.raises(SceneError) as info:
        load_scene(path)
    return str(info.value)


def test_bad_files_are_refused_with_the_key(tmp_path):
    _x, _y, z = _grid()
    np.save(tmp_path / "ok.npy", z)
    ok = {"type": "measured", "file": "ok.npy", "length_unit": "um", "spacing": DX}
    # missing file
    msg = _bad(tmp_path, {**ok, "file": "none.npy"})
    assert msg.startswith(f"gap.file = {str(tmp_path / 'none.npy')!r}") and "no such file" in msg  # where it looked
    # unreadable: not an npy, and text that is not numbers
    (tmp_path / "junk.npy").write_bytes(b"\x00\x01 not numpy at all")
    assert "gap.file" in _bad(tmp_path, {**ok, "file": "junk.npy"}) and "not a valid .npy file" in \
        _bad(tmp_path, {**ok, "file": "junk.npy"})
    (tmp_path / "words.csv").write_text("1,2,3\n4,five,6\n7,8,9\n")
    assert "table of numbers" in _bad(tmp_path, {**ok, "file": "words.csv"})
    # wrong shape: a 1-D array, ragged rows, an asc whose data does not match its header, 2-column points
    np.save(tmp_path / "line.npy", z[0])
    assert "2-D array" in _bad(tmp_path, {**ok, "file": "line.npy"})
    (tmp_path / "ragged.txt").write_text("1 2 3\n4 5\n")
    assert "gap.file" in _bad(tmp_path, {**ok, "file": "ragged.txt"})
    _write_asc(tmp_path / "short.asc", z[:-1][::-1])
    text = (tmp_path / "short.asc").read_text().replace(f"nrows {N - 1}", f"nrows {N}")
    (tmp_path / "short.asc").write_text(text)
    assert "wrong shape" in _bad(tmp_path, {"type": "measured", "file": "short.asc", "length_unit": "um"})
    np.savetxt(tmp_path / "two.xyz", np.ones((10, 2)))
    assert "3 columns" in _bad(tmp_path, {"type": "measured", "file": "two.xyz"})
    # too few points: three x-y-z points; points on a line; a grid too small for cubic splines
    np.savetxt(tmp_path / "three.xyz", np.eye(3))
    assert "too few points" in _bad(tmp_path, {"type": "measured", "file": "three.xyz"})
    np.savetxt(tmp_path / "line.xyz", np.column_stack([np.arange(9.0), np.arange(9.0) * 2, np.ones(9)]))
    assert "span an area" in _bad(tmp_path, {"type": "measured", "file": "line.xyz"})
    np.save(tmp_path / "tiny.npy", np.zeros((3, 3)))
    assert "too few points" in _bad(tmp_path, {**ok, "file": "tiny.npy", "spacing": 400.0})
    # non-uniform grid of points
    xs = np.array([0.0, 1.0, 2.5, 3.0, 4.0])
    X, Y = np.meshgrid(xs, np.arange(5.0))
    np.savetxt(tmp_path / "uneven.xyz", np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)]))
    assert "not evenly spaced" in _bad(tmp_path, {"type": "measured", "file": "uneven.xyz"})


def test_missing_data_inside_the_region_is_refused(tmp_path):
    _x, _y, z = _grid()
    hole = z.copy()
    hole[N // 2 + 3, N // 2 - 4] = np.nan  # 15 um from the centre: inside the region
    np.save(tmp_path / "hole.npy", hole)
    msg = _bad(tmp_path, {"type": "measured", "file": "hole.npy", "length_unit": "um", "spacing": DX})
    assert msg.startswith("gap.file = ") and "no data" in msg and "bem.extent" in msg
    _write_asc(tmp_path / "nodata.asc", np.where(np.isnan(hole), -9999.0, hole)[::-1], nodata=-9999)
    assert "no data" in _bad(tmp_path, {"type": "measured", "file": "nodata.asc", "length_unit": "um"})
    far = z.copy()
    far[:3, :] = np.nan  # outside the region: fine
    np.save(tmp_path / "far.npy", far)
    load_scene(_scene(tmp_path, {"type": "measured", "file": "far.npy", "length_unit": "um", "spacing": DX}))
    # a region larger than the data: the message names the data's extent (the rule of bem.gaps.Measured)
    msg = _bad(tmp_path, {"type": "measured", "file": "far.npy", "length_unit": "um", "spacing": DX}, extent=5e-4)
    assert msg.startswith("bem.extent = 0.0005 is not allowed: the candidate region |x| <= 0.0005, |y| <= 0.0005 "
                          f"must lie inside the measured data of {tmp_path / 'far.npy'}, x in [-0.0004, 0.0004]")


def test_bad_keys_are_refused_with_the_key(tmp_path):
    _x, _y, z = _grid()
    np.save(tmp_path / "ok.npy", z)
    ok = {"type": "measured", "file": "ok.npy", "length_unit": "um", "spacing": DX}
    cases = {
        "gap.spacing is missing": {k: v for k, v in ok.items() if k != "spacing"},
        "gap.length_unit = 'inch'": {**ok, "length_unit": "inch"},
        "gap.kind = 'roughness'": {**ok, "kind": "roughness"},
        "gap.center = 'middle'": {**ok, "center": "middle"},
        "gap.method = 'spline'": {**ok, "method": "spline"},
        "gap.R = 0.01": {**ok, "R": 0.01},
        "extension '.bin' does not tell the format": {**ok, "file": "ok.bin"},
    }
    (tmp_path / "ok.bin").write_bytes(b"")
    for expected, gap in cases.items():
        assert expected in _bad(tmp_path, gap), expected
    _write_asc(tmp_path / "ok.asc", z[::-1])
    assert "gap.spacing" in _bad(tmp_path, {"type": "measured", "file": "ok.asc", "spacing": 5.0})
    np.save(tmp_path / "negative.npy", z - 1.0)
    assert "negative gap" in _bad(tmp_path, {**ok, "file": "negative.npy"})
    assert "gap.file is missing" in _bad(tmp_path, {"type": "measured"})


def test_check_names_the_key_and_exits_2(tmp_path):
    path = _scene(tmp_path, {"type": "measured", "file": "absent.npy", "spacing": 1e-6})
    code, out, err = cli("check", path)
    assert code == 2 and f"gap.file = {str(tmp_path / 'absent.npy')!r}" in err and out == ""
    _x, _y, z = _grid()
    np.save(tmp_path / "ok.npy", z)
    code, out, err = cli("check", _scene(tmp_path, {"type": "measured", "file": "ok.npy", "length_unit": "um",
                                                    "spacing": DX}, name="ok.toml"))
    assert code == 0 and "measured: OK" in out
