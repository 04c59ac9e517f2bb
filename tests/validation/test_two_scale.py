"""The two-scale check (validation.studies.two_scale): the study at a tiny size, its windows, gap and figures."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

from bem.checks import InputError
from bem.lattice import Lattice
from validation.studies.two_scale_models import (TiledRoughness, _f32, greenwood_tripp_law, gw_pressure,
                                                 nominal_radius, spectral_moments, windowed)

pytest.importorskip("SurfaceTopography")

TINY = dict(ratios=(2,), nodes_per_roll_off=4, layer_nodes_across=20, refine=(4, 8, 16), refine_ratio=2)


@pytest.fixture(scope="module")
def tiny():
    from validation.studies.two_scale import QUICK, run_two_scale

    return run_two_scale(dict(QUICK, **TINY), keep=True)


def test_tiny_study_gives_every_error_finite_for_both_loads(tiny):
    rows = tiny["rows"]
    assert [(r["ratio"], r["load_factor"]) for r in rows] == [(2, 1.0), (2, 2.0)]
    for r in rows:
        assert r["resolved_converged"] and r["layer_converged"] and r["gt_converged"]
        for model in ("layer", "gt"):
            for what in ("approach", "radius", "l2", "peak", "l2_wide"):
                assert math.isfinite(r[f"{model}_{what}_err"])
        assert 0 <= r["first_touch_offset"] < tiny["first_touch_gap"]
    assert rows[1]["approach"] > rows[0]["approach"] > 0  # the heavier load presses further
    ref = tiny["refinement"]
    assert [lv["nodes_per_roll_off"] for lv in ref["levels"]] == [4, 8, 16]
    assert all(lv["converged"] for lv in ref["levels"])
    assert math.isfinite(ref["order_approach"]) and math.isfinite(ref["order_windows"])


def test_study_writes_json_and_table_and_figures(tiny, tmp_path):
    from validation.report.documents.studies import write_study_outputs
    from validation.studies import save
    from validation.studies.two_scale import COLUMNS

    data = {k: v for k, v in tiny.items() if k != "fields"}
    text, figures = write_study_outputs(save(tmp_path, "two_scale", data, fields=tiny["fields"]))
    assert (tmp_path / "two_scale.md").read_text() == text
    assert json.loads((tmp_path / "two_scale.json").read_text())["rows"][0]["ratio"] == 2
    for _, heading, _ in COLUMNS:
        assert heading.replace("[", "\\[").replace("]", "\\]") in text
    from validation.report.documents.studies import report_studies_dir

    report_studies_dir(tmp_path, tmp_path / "report")
    md = (tmp_path / "report" / "report.md").read_text()
    assert "Two-scale check" in md
    for name in ("two_scale_map.png", "two_scale_profile.png"):  # drawn from the JSON alone
        assert f"figures/{name}" in md and (tmp_path / "report" / "figures" / name).is_file()
    from PIL import Image

    assert [Path(f).name for f in figures] == ["two_scale_map.png", "two_scale_profile.png"]
    for path in figures:
        with Image.open(path) as img:
            arr = np.asarray(img.convert("L"), dtype=float)
        assert arr.shape[0] > 200 and arr.std() > 5  # drawn, not blank


def test_windowed_mean_matches_a_loop_over_windows():
    rng = np.random.default_rng(3)
    x, y = rng.uniform(-5.3, 4.1, 2000), rng.uniform(-2.2, 6.7, 2000)
    p = rng.uniform(0, 1, 2000)
    ix, iy, mean, count = windowed(x, y, p, 1.5)
    for i, j, m, n in zip(ix, iy, mean, count):
        inside = (np.abs(x - 1.5 * i) < 0.75) & (np.abs(y - 1.5 * j) < 0.75)
        assert n == inside.sum()
        assert m == pytest.approx(p[inside].mean(), rel=1e-12)
    assert count.sum() == 2000


def test_nominal_radius_of_a_uniform_disc():
    lat = Lattice.from_extent(0.01, 1.5)
    x, y = lat.x[lat.mask], lat.y[lat.mask]
    p = (np.hypot(x, y) <= 1.0).astype(float)
    assert nominal_radius(x, y, p, 0.99) == pytest.approx(math.sqrt(0.99), abs=0.01)


def _cell():
    from bem import rough

    n_cols, n_rows = 16, 18
    surface = rough.self_affine((32, 32), (1.0, n_rows * math.sqrt(3) / (2 * n_cols)), hurst=0.8, rms_height=0.01,
                                long_cutoff=0.5, short_cutoff=0.125, seed=4)
    return surface, surface.to_lattice(n_cols)


def test_tiled_roughness_puts_the_cell_heights_on_the_lattice_nodes():
    surface, cell = _cell()
    assert not cell.stretch_large and cell.stretch_y == pytest.approx(1.0, abs=1e-12)
    lat = Lattice.from_extent(cell.step, 1.7)
    x, y = lat.x[lat.mask], lat.y[lat.mask]
    gap = TiledRoughness(cell, R=3.0)
    # independent: the cell node at the same position modulo the periods
    cx, cy = cell.positions()
    Lx, Ly = cell.size
    dx = (x[:, None] - cx.ravel()[None, :] + Lx / 2) % Lx - Lx / 2
    dy = (y[:, None] - cy.ravel()[None, :] + Ly / 2) % Ly - Ly / 2
    match = np.argmin(np.hypot(dx, dy), axis=1)
    assert np.hypot(dx, dy)[np.arange(x.size), match].max() < 1e-9
    expected = (x**2 + y**2) / 6.0 + cell.heights.max() - cell.heights.ravel()[match]
    np.testing.assert_allclose(gap(x, y), expected, rtol=0, atol=1e-15)
    with pytest.raises(InputError, match="away from the lattice"):
        gap(np.array([0.3 * cell.step]), np.array([0.0]))


def test_gw_integral_and_greenwood_tripp_law():
    assert _f32(0.0)[0] == pytest.approx(2**0.25 * math.gamma(1.25) / math.sqrt(2 * math.pi), rel=1e-6)
    surface, cell = _cell()
    moments = spectral_moments(surface.heights, surface.size)
    assert moments[0] == pytest.approx(surface.stats.rms_height**2, rel=1e-9)
    h0 = float(cell.heights.max() - cell.heights.mean())
    p = gw_pressure(np.linspace(h0, -h0, 50), moments, 1.0)
    assert np.all(np.diff(p) > 0)  # pressure rises as the separation closes
    law = greenwood_tripp_law(moments, 1.0, h0, p_max=p[-1])
    d = np.linspace(h0, -h0, 7)[1:]
    np.testing.assert_allclose(law.w(gw_pressure(d, moments, 1.0)), h0 - d, rtol=1e-3)


def test_cli_runs_the_two_scale_study_and_refuses_a_scene(monkeypatch, tmp_path):
    import sys
    import types

    from validation.studies import save

    from .conftest import cli

    monkeypatch.chdir(tmp_path)
    seen = {}
    fake = types.ModuleType("validation.studies.two_scale")
    fake.STEM = "two_scale"
    fake.main = lambda **kw: seen.update(kw) or save(kw["out"], "robustness", [], status=7)
    monkeypatch.setitem(sys.modules, "validation.studies.two_scale", fake)
    code, _, _ = cli("study", "two-scale", "--quick")
    assert code == 7 and seen["quick"]
    monkeypatch.undo()
    code, out, err = cli("study", "two-scale", "hertz")
    assert code == 2 and "scene = 'hertz' is not allowed" in err and "Traceback" not in err


def test_map_pixels_and_profile_windows_hold_the_field_drawn():
    from validation.studies.two_scale_figure import binned_map, window_row

    lat = Lattice.from_extent(0.01, 1.0)
    x, y = lat.x[lat.mask], lat.y[lat.mask]
    p = np.where(x >= 0.0, 2.0, 0.0) + y  # a step in x (at a pixel edge) and a ramp in y
    edges, image = binned_map(x, y, p, 0.8, pixels=16)
    centres = 0.5 * (edges[1:] + edges[:-1])
    expected = np.where(centres[None, :] > 0, 2.0, 0.0) + centres[:, None]
    np.testing.assert_allclose(image, expected, atol=0.01)  # a pixel mean: the ramp's mean over its nodes
    xs, means = window_row(x, y, p, 0.25)
    assert np.all(np.diff(xs) > 0) and xs[0] <= -0.75 and xs[-1] >= 0.75
    np.testing.assert_allclose(means[np.abs(xs) > 0.2], np.where(xs[np.abs(xs) > 0.2] > 0, 2.0, 0.0), atol=0.01)
