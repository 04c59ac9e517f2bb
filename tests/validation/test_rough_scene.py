"""Periodic scenes of rough surfaces: the keys and their errors, contact spots, a run of rough_flat, its report.

The run's numbers are checked against independent computations from its .vtu field: the
contact fraction and mean pressure from the nodal pressures, the spots by a flood fill over
neighbours found from the node coordinates (distance one step, minimum image across the cell).
"""

import json
import math
from collections import deque

import numpy as np
import pytest

from validation.run import run_scene
from validation.run.periodic import contact_spots
from validation.run.record import RunResult
from validation.scene import SceneError, load_scene, parse_scene
from validation.scene.load import read_toml
from validation.scene.source import builtin_path

from ..vtu_reader import read_vtu
from .conftest import cli

SQRT3 = math.sqrt(3.0)


def _base(**changes):
    raw = read_toml(builtin_path("rough_flat"))
    raw["gap"].update(grid=32, size=1e-3, long_cutoff=2.5e-4, short_cutoff=1e-4)
    raw["bem"]["cell_nodes"] = 32
    raw.pop("report")
    for key, value in changes.items():
        section, name = key.split("__")
        if value is None:
            raw[section].pop(name, None)
        else:
            raw.setdefault(section, {})[name] = value
    return raw


def _flood_fill(x, y, contact, size, step):
    """Spots by breadth-first search; neighbours: nodes one step apart, minimum image in the cell."""
    lx, ly = size
    nodes = np.flatnonzero(contact)
    label = {}
    count = 0
    for start in nodes:
        if start in label:
            continue
        label[start] = count
        queue = deque([start])
        while queue:
            i = queue.popleft()
            dx = (x[nodes] - x[i] + lx / 2) % lx - lx / 2
            dy = (y[nodes] - y[i] + ly / 2) % ly - ly / 2
            for j in nodes[np.abs(np.hypot(dx, dy) - step) < 1e-6 * step]:
                if j not in label:
                    label[j] = count
                    queue.append(j)
        count += 1
    return label, count


def _same_partition(labels, reference):
    pairs = {(int(labels[i]), reference[i]) for i in reference}
    return len(pairs) == len({a for a, _ in pairs}) == len({b for _, b in pairs})


def test_contact_spots_of_a_hand_made_pattern():
    c = np.zeros((6, 8), dtype=bool)
    c[2, 0] = c[2, 7] = True  # neighbours across the x edge: one spot
    c[0, 4] = c[5, 4] = True  # row 5 (odd) node 4 sits at x = 4.5: (4, 0) is its neighbour across y
    c[2, 3] = c[3, 2] = True  # even row 2: (q - 1, r + 1) is a neighbour
    c[4, 1] = c[5, 7] = True  # x = 1 and x = 7.5: not neighbours, nor of the others
    labels, n = contact_spots(c)
    assert n == 5
    assert labels[2, 0] == labels[2, 7] and labels[0, 4] == labels[5, 4] and labels[2, 3] == labels[3, 2]
    assert labels[4, 1] != labels[5, 7]
    assert np.all(labels[~c] == -1) and sorted(set(labels[c].tolist())) == list(range(n))
    c2 = np.zeros((6, 8), dtype=bool)
    c2[2, 4] = c2[3, 5] = True  # even row 2: (q + 1, r + 1) is NOT a neighbour (x = 4 and x = 5.5)
    assert contact_spots(c2)[1] == 2
    assert contact_spots(np.zeros((4, 4), dtype=bool))[1] == 0


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_contact_spots_match_a_flood_fill_over_the_coordinates(seed):
    n_rows, n_cols = 12, 10
    c = np.random.default_rng(seed).random((n_rows, n_cols)) < 0.45
    r, q = np.mgrid[0:n_rows, 0:n_cols]
    x, y = (q + 0.5 * (r % 2)).ravel(), (r * SQRT3 / 2).ravel()
    reference, count = _flood_fill(x, y, c.ravel(), (n_cols, n_rows * SQRT3 / 2), 1.0)
    labels, n = contact_spots(c)
    assert n == count
    assert _same_partition(labels.ravel(), reference)


@pytest.mark.parametrize("changes, key", [
    ({"bem__periodic": None}, "bem.periodic"),
    ({"load__force": 10.0}, "load.mean_pressure"),
    ({"gap__hurst": 1.5}, "gap.hurst"),
    ({"gap__seed": None}, "gap.seed"),
    ({"gap__rms_height": 1e-6}, "gap.rms_height"),
    ({"gap__grid": 4}, "gap.grid"),
    ({"gap__spacing": 1e-6}, "gap.spacing"),
    ({"bem__step": 1e-5}, "bem.step"),
    ({"bem__cell_nodes": 4}, "bem.cell_nodes"),
    ({"bem__cell_nodes": "many"}, "bem.cell_nodes"),
    ({"bem__periodic": "yes"}, "bem.periodic"),
    ({"load__mean_pressure": None, "load__approach": 1.0}, "load.approach"),
    ({"stress__depths": "auto"}, "stress"),
    ({"layer__law": "root", "layer__lam_ref": 1e-12}, "layer.law"),
])
def test_bad_periodic_keys_name_the_key(changes, key):
    with pytest.raises(SceneError) as err:
        load_scene(_base(**changes))
    assert key in str(err.value)


@pytest.mark.parametrize("size, shown", [(1e-300, "1e-300"), (1e300, "1e+300"), ([1e-3, 1e-70], "1e-70")])
def test_a_cell_size_beyond_the_physical_scales_is_refused_before_any_work(tmp_path, size, shown):
    import tomli_w

    path = tmp_path / "tiny.toml"
    path.write_text(tomli_w.dumps(_base(gap__size=size)))
    code, out, err = cli("check", path)
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert err.startswith(f"contactlab: error: gap.size = {shown} is not allowed: it must be in [1e-60, 1e+60]")


@pytest.mark.parametrize("override, key", [("gap.long_cutoff=1e300", "gap.long_cutoff = 1e+300"),
                                           ("gap.short_cutoff=1e-300", "gap.short_cutoff = 1e-300"),
                                           ("gap.rms_slope=1e300", "gap.rms_slope = 1e+300")])
def test_a_length_of_the_self_affine_surface_beyond_the_physical_scales_is_refused(override, key):
    code, out, err = cli("check", "rough_flat", "--set", override)
    assert code == 2 and out == "" and err.startswith(f"contactlab: error: {key} is not allowed: it must be in [1e-60")


@pytest.mark.parametrize("increment", [1e300, 1e-300])
def test_an_instrument_file_whose_header_states_an_impossible_size_is_refused(tmp_path, increment):
    """An x3p file's ``Increment`` (the grid step) times its points is the cell size: 1e300 m or
    1e-300 m is no length a solve can take."""
    import SurfaceTopography
    import tomli_w

    z = np.random.default_rng(0).random((32, 32)) * 1e-6
    SurfaceTopography.Topography(z, (32 * increment, 32 * increment), unit="m").to_x3p(str(tmp_path / "s.x3p"))
    raw = _base()
    raw["gap"] = {"type": "surface", "file": "s.x3p"}
    (tmp_path / "s.toml").write_text(tomli_w.dumps(raw))
    code, out, err = cli("check", tmp_path / "s.toml")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert err.startswith(f"contactlab: error: gap.file = 's.x3p' is not allowed: the size it "
                          f"states times scale, ({32 * increment:.4g}, {32 * increment:.4g}), must be two lengths in")


def test_periodic_keys_are_refused_outside_a_rough_scene():
    smooth = read_toml(builtin_path("elliptic"))
    for section, key, value in (("bem", "periodic", True), ("bem", "cell_nodes", 64), ("load", "mean_pressure", 1e6)):
        raw = json.loads(json.dumps(smooth))
        raw[section][key] = value
        if key == "mean_pressure":
            raw["load"] = {"mean_pressure": value}
        with pytest.raises(SceneError, match=f"{section}.{key}"):
            load_scene(raw)


def test_surface_file_outside_the_scene_folder_is_refused(tmp_path):
    (tmp_path / "scene").mkdir()
    np.save(tmp_path / "z.npy", np.random.default_rng(0).random((16, 16)) * 1e-6)
    raw = _base()
    raw["gap"] = {"type": "surface", "file": "../z.npy", "reader": "core", "spacing": 1e-5}
    (tmp_path / "scene" / "s.toml").write_text(
        "\n".join(f"[{s}]\n" + "\n".join(f"{k} = {json.dumps(v)}" for k, v in t.items()) for s, t in raw.items()))
    with pytest.raises(SceneError, match="gap.file"):
        load_scene(tmp_path / "scene" / "s.toml")
    scene = load_scene(tmp_path / "scene" / "s.toml", allow_outside_files=True)
    assert scene.bem["cell"][0] == 32 and scene.gap.surface.stats.grid == (16, 16)
    assert scene.gap.surface.size == pytest.approx((16e-5, 16e-5))
    z = np.random.default_rng(0).random((16, 16))
    z[3, 4] = np.nan
    np.save(tmp_path / "scene" / "holes.npy", z)
    raw["gap"]["file"] = str(tmp_path / "scene" / "holes.npy")
    with pytest.raises(SceneError, match=r"gap.file = .*holes.npy.* 1 points without data"):
        parse_scene(raw, base_dir=tmp_path / "scene")


def test_force_on_one_cell_is_the_mean_pressure_times_the_cell():
    by_pressure = run_scene(_base())
    lx, ly = by_pressure.bem.size
    by_force = run_scene(_base(), overrides={"load.force": by_pressure.periodic.mean_pressure * lx * ly})  # replaces it
    assert by_force.periodic.mean_pressure == pytest.approx(by_pressure.periodic.mean_pressure, rel=1e-12)
    assert by_force.periodic.contact_fraction == by_pressure.periodic.contact_fraction
    assert by_force.approach == pytest.approx(by_pressure.approach, rel=1e-8)


@pytest.fixture(scope="module")
def rough_run(tmp_path_factory):
    """``contactlab run rough_flat``, once: (result folder, stdout)."""
    out = tmp_path_factory.mktemp("rough") / "res"
    code, stdout, stderr = cli("run", "rough_flat", "--out", out)
    assert code == 0, stderr
    return out, stdout


@pytest.fixture
def drawn(monkeypatch):
    """The matplotlib figures the periodic figures save, in order."""
    from validation.report.figures import periodic

    figures, save = [], periodic.save_figure
    def keep(fig, path, **kw):
        figures.append(fig)
        return save(fig, path, **kw)

    monkeypatch.setattr(periodic, "save_figure", keep)
    return figures


def test_run_rough_flat_records_what_its_field_shows(rough_run):
    out, stdout = rough_run
    r = RunResult.read(out / "result.json")
    points, _, data, _, _ = read_vtu(out / "bem_field.vtu")
    p, gap = data["p"], data["gap"]
    n_cols, n_rows = r.bem.cell
    step = r.bem.step
    assert p.size == n_cols * n_rows == r.bem.n_nodes
    lx, ly = n_cols * step, n_rows * step * SQRT3 / 2
    assert r.converged and r.periodic is not None
    assert r.periodic.contact_fraction == np.count_nonzero(p > 0) / p.size
    assert 0.01 < r.periodic.contact_fraction < 0.2
    assert r.periodic.mean_pressure == pytest.approx(SQRT3 / 2 * step**2 * p.sum() / (lx * ly), rel=1e-12)
    assert r.periodic.mean_pressure == pytest.approx(read_toml(builtin_path("rough_flat"))["load"]["mean_pressure"],
                                               rel=1e-8)
    assert r.periodic.mean_gap == pytest.approx(gap.mean(), rel=1e-12)
    reference, count = _flood_fill(points[:, 0], points[:, 1], p > 0, (lx, ly), step)
    assert r.periodic.n_spots == r.periodic.spots.count == count > 10
    assert _same_partition(data["contact_spot"], reference)
    assert np.all(data["contact_spot"][p <= 0] == -1)
    s = r.periodic.surface
    assert s["rms_slope"] == pytest.approx(0.1, rel=1e-12)  # the scene's rms_slope
    assert s["stretch_y"] == pytest.approx(ly / s["size"][1], rel=1e-12)
    h = data["initial_gap"]
    assert h.min() == 0.0
    assert h.std() == pytest.approx(s["rms_height"], rel=0.02)  # the band-limited surface on the lattice
    assert s["edge_jump_large"] is False and s["edge_jump"] > 0
    for text in ("contact fraction", f"{count} contact spots", "rms height", "stretch_y"):
        assert text in stdout


def test_core_install_refusal_message_names_the_extra(monkeypatch):
    from validation import extras

    monkeypatch.setattr(extras, "missing", lambda extra: [("SurfaceTopography", "not installed")]
                        if extra == "rough" else [])
    with pytest.raises(extras.MissingExtraError, match=r"gap.type = 'self_affine'.*install contactlab\[rough\]"):
        load_scene(_base())


def test_report_maps_show_the_pressure_and_the_spots(rough_run, drawn):
    out, _ = rough_run
    code, _, stderr = cli("report", out)
    assert code == 0, stderr
    r = RunResult.read(out / "result.json")
    md = (out / "report" / "report.md").read_text()
    assert "Rough surface on a flat: the periodic cell" in md and "| contact spots | " + str(r.periodic.n_spots) in md
    assert "| load: mean pressure over the cell | 200 | MPa |" in md and "| gap long_cutoff | 0.25 | mm |" in md
    (fig,) = drawn
    ax_p, ax_s, bar = fig.axes
    image = ax_p.images[0].get_array()
    assert image.max() == pytest.approx(r.p_max / 1e6)  # MPa, as every pressure of the report
    assert np.count_nonzero(~np.ma.getmaskarray(image)) == r.bem.n_contact
    assert "MPa" in bar.get_ylabel()
    lx, ly = r.bem.size
    for ax in (ax_p, ax_s):
        assert ax.get_xlabel() == "$x$ [mm]" and ax.get_ylabel() == "$y$ [mm]"
        assert ax.get_xlim() == pytest.approx((0.0, lx * 1e3)) and ax.get_ylim() == pytest.approx((0.0, ly * 1e3))
        assert ax.get_aspect() == 1.0
    assert ax_s.get_title().startswith(f"{r.periodic.n_spots} contact spots")
    rgb = ax_s.images[0].get_array()
    white = np.all(rgb == 1.0, axis=-1)
    assert np.count_nonzero(~white) == r.bem.n_contact
    n_colours = len({tuple(c) for c in rgb[~white]})
    assert min(r.periodic.n_spots, 10) <= n_colours <= r.periodic.n_spots


def test_sweep_of_the_mean_pressure_draws_the_load_curves(tmp_path, drawn):
    values = [5e7, 2e8, 8e8]
    code, _, stderr = cli("sweep", "rough_flat", "--param", "load.mean_pressure", "--values",
                          ",".join(map(str, values)), "--set", "gap.grid=64", "--set", "bem.cell_nodes=64",
                          "--workers", "1", "--out", tmp_path / "sw")
    assert code == 0, stderr
    code, _, stderr = cli("report", tmp_path / "sw")
    assert code == 0, stderr
    points = [RunResult.from_json(json.loads(f.read_text())["result"])
              for f in sorted((tmp_path / "sw" / "points").glob("point-*.json"))]
    points.sort(key=lambda p: p.periodic.mean_pressure)
    (fig,) = drawn
    ax_a, ax_g = fig.axes
    (area, hyun), (gap,) = ax_a.get_lines(), ax_g.get_lines()
    assert area.get_xdata() == pytest.approx([v / 1e6 for v in values])  # MPa
    assert area.get_ydata() == pytest.approx([p.periodic.contact_fraction for p in points])
    assert np.all(np.diff(area.get_ydata()) > 0)
    slope_modulus = points[0].bem.E_star * points[0].periodic.surface["rms_slope"]
    assert hyun.get_ydata() == pytest.approx([2 * v / slope_modulus for v in values])
    assert gap.get_xdata() == pytest.approx([p.periodic.mean_gap / 1e-3 for p in points])  # mm, as every length
    assert np.all(np.diff(gap.get_xdata()) < 0)
    assert "MPa" in ax_a.get_xlabel() and "A/A_0" in ax_a.get_ylabel()
    assert "mm" in ax_g.get_xlabel() and "MPa" in ax_g.get_ylabel()
    assert ax_a.get_xscale() == ax_a.get_yscale() == ax_g.get_yscale() == "log"


def test_check_describes_the_periodic_cell():
    code, stdout, stderr = cli("check", "rough_flat")
    assert code == 0, stderr
    step = 1e-3 / 256
    n_rows = 2 * round(1e-3 / (step * SQRT3))  # the even number of rows nearest Ly / (c sqrt(3)/2)
    assert f"periodic cell 0.001 x 0.001001 of 256 x {n_rows}, {256 * n_rows} nodes" in stdout
