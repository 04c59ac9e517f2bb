"""The hardness of a plastic surface in the harness: ``[bodies] hardness`` of a scene (its checks, the run's
solve, result.json), ``contactlab layer-law --hardness`` (units, refusals, the law file) and the two-scale
check's setting."""

import json
import math
import re

import numpy as np
import pytest
import tomli_w

from bem.reference import hertz_sphere
from validation.run import run_scene
from validation.run.record import RunResult
from validation.scene import SceneError, load_scene
from validation.scene.load import read_toml
from validation.scene.source import builtin_path
from validation.units import PASCALS, pressure_in_pa

from .conftest import cli

E_STAR = 115e9  # Pa
SPHERE = {"scene": {"name": "plastic_sphere", "units": "SI (m, Pa, N)"},
          "bodies": {"E_star": E_STAR}, "gap": {"type": "paraboloid", "R": 0.01}, "load": {"force": 100.0},
          "bem": {"nodes_across": 24, "extent_factor": 2.0}}
P0 = hertz_sphere(0.01, E_STAR, force=100.0).p_max  # Hertz's peak of the elastic sphere


def _sphere(**bodies):
    return json.loads(json.dumps(SPHERE)) | {"bodies": {"E_star": E_STAR, **bodies}}


def _rough(**changes):
    """rough_flat at 48 x 48 nodes; ``changes``: ``section__key = value``."""
    raw = read_toml(builtin_path("rough_flat"))
    raw["gap"].update(grid=48, short_cutoff=1e-4)
    raw["bem"]["cell_nodes"] = 48
    raw.pop("report")
    for key, value in changes.items():
        section, name = key.split("__")
        raw[section][name] = value
    return raw


# -- scenes: checks ------------------------------------------------------------------------------

@pytest.mark.parametrize("value, rule", [(-1e9, "> 0"), (0.0, "> 0"), (math.nan, "finite"), (math.inf, "finite"),
                                         ("2GPa", "a real number"), (1e61, "in [1e-60, 1e+60]")])
def test_a_bad_hardness_is_refused_naming_the_key(value, rule):
    with pytest.raises(SceneError, match=r"bodies\.hardness = .* is not allowed: it must be " + re.escape(rule)):
        load_scene(_sphere(hardness=value))


@pytest.mark.parametrize("section", ["fem", "analytic"])
def test_the_elastic_references_are_refused_with_a_hardness(section):
    """hertz has both; without its [fem] (no_fem) the closed form is refused."""
    with pytest.raises(SceneError, match=rf"bodies\.hardness = 2000000000.0 is not allowed with \[{section}\]: "
                                         "the .* is elastic"):
        load_scene("hertz", overrides=["bodies.hardness=2e9"], no_fem=section == "analytic")


@pytest.mark.parametrize("load", [{"mean_pressure": 2e8}, {"force": 2e8 * 1e-3 * 1e-3}])
def test_a_cell_pressed_at_or_beyond_its_hardness_is_refused(load):
    raw = _rough()
    raw["load"] = load
    key = next(iter(load))
    with pytest.raises(SceneError, match=rf"bodies\.hardness = 100000000.0 is not allowed with load\.{key} = .*"
                                         r"must be below the hardness"):
        load_scene(raw, overrides=["bodies.hardness=1e8"])


def test_a_scene_without_hardness_is_elastic_and_the_key_is_scene_units():
    assert load_scene(_sphere()).hardness is None
    scene = load_scene({**_sphere(hardness=2.0), "scene": {"name": "mpa", "units": "mm, MPa, N"},
                        "gap": {"type": "paraboloid", "R": 10.0}, "load": {"force": 100.0}})
    assert scene.hardness == 2.0  # in the scene's pressure unit (MPa), as E_star


# -- scenes: runs --------------------------------------------------------------------------------

def test_a_plastic_sphere_caps_its_pressure_and_records_the_hardness(tmp_path):
    """Hardness 0.7 p0: the pressure is capped, the load spreads over a wider contact than Hertz's, the
    force still balances; result.json records the hardness and the flowing area; an elastic run records
    null and 0."""
    hardness = 0.7 * P0
    run_scene(_sphere(hardness=hardness), tmp_path / "plastic")
    run_scene(_sphere(), tmp_path / "elastic")
    plastic = RunResult.read(tmp_path / "plastic" / "result.json")
    elastic = RunResult.read(tmp_path / "elastic" / "result.json")
    raw = json.loads((tmp_path / "plastic" / "result.json").read_text())
    assert raw["bem"]["hardness"] == hardness and plastic.bem.hardness == hardness
    assert plastic.converged and plastic.p_max <= hardness * (1 + 1e-12)
    assert 0 < plastic.bem.plastic_area < plastic.contact_area
    assert plastic.force == pytest.approx(100.0, rel=1e-8)
    assert plastic.contact_area > 1.05 * elastic.contact_area  # 1.08 measured at 24 nodes across
    assert plastic.approach > elastic.approach
    assert elastic.bem.hardness is None and elastic.bem.plastic_area == 0.0
    assert elastic.p_max > hardness


def test_a_plastic_rough_cell_touches_more_and_records_its_flowing_share(tmp_path):
    elastic = run_scene(_rough())
    hardness = 0.5 * elastic.p_max
    run_scene(_rough(), tmp_path / "r", overrides=[f"bodies.hardness={hardness!r}"])
    plastic = RunResult.read(tmp_path / "r" / "result.json")
    assert plastic.bem.hardness == hardness and plastic.p_max <= hardness * (1 + 1e-12)
    assert 0 < plastic.bem.plastic_fraction <= plastic.periodic.contact_fraction
    assert plastic.bem.plastic_area == pytest.approx(plastic.bem.plastic_fraction * np.prod(plastic.bem.size),
                                                     rel=1e-12)
    assert plastic.periodic.contact_fraction > elastic.periodic.contact_fraction
    assert plastic.periodic.mean_gap < elastic.periodic.mean_gap
    assert plastic.bem.mean_pressure == pytest.approx(2e8, rel=1e-8)


def test_a_measured_surface_scene_takes_the_hardness(tmp_path):
    """``type = "surface"``: a file's heights on the periodic cell, with the hardness passed to the solve."""
    from bem import rough

    z = rough.self_affine((32, 32), (1.0, 1.0), hurst=0.8, rms_height=0.005, long_cutoff=0.25, short_cutoff=0.125,
                          seed=4).heights
    np.save(tmp_path / "z.npy", np.asarray(z))
    raw = _rough()
    raw["gap"] = {"type": "surface", "file": "z.npy", "reader": "core", "spacing": 1 / 32}
    raw["bem"]["cell_nodes"] = 32
    raw["bodies"] = {"E_star": 1.0, "hardness": 0.1}  # numbers of order one
    raw["load"] = {"mean_pressure": 0.01}
    (tmp_path / "s.toml").write_text(tomli_w.dumps(raw))
    code, out, err = cli("run", tmp_path / "s.toml", "--out", tmp_path / "out")
    assert code == 0, err
    result = RunResult.read(tmp_path / "out" / "result.json")
    assert result.bem.hardness == 0.1 and result.p_max <= 0.1 * (1 + 1e-12) and result.bem.plastic_area > 0


# -- contactlab layer-law --hardness -------------------------------------------------------------

@pytest.mark.parametrize("text, pa", [("2.5GPa", 2.5e9), ("300 MPa", 3e8), ("1e9", 1e9), ("10 ksi", 1e4 * 6894.757293168361),
                                      ("0.5kPa", 500.0)])
def test_a_pressure_is_read_with_its_unit(text, pa):
    assert pressure_in_pa("--hardness", text) == pytest.approx(pa, rel=1e-15)
    assert set(PASCALS) == {"Pa", "kPa", "MPa", "GPa", "bar", "psi", "ksi"}


SYNTHETIC = "hurst=0.8,rms_height=0.5e-6,size=1e-4,grid=48,long_cutoff=25e-6,short_cutoff=12.5e-6,seed=3"
#: the same cell in numbers of order one (1 m, E* = 1 Pa)
UNIT = "hurst=0.8,rms_height=0.005,size=1,grid=48,long_cutoff=0.25,short_cutoff=0.125,seed=3"


@pytest.mark.parametrize("value, rule", [("-1GPa", "finite and > 0"), ("0", "finite and > 0"),
                                         ("nan", "finite and > 0"), ("2 GJ", "a number with an optional pressure unit"),
                                         ("hard", "a number with an optional pressure unit")])
def test_a_bad_hardness_option_stops_with_exit_2_naming_it(tmp_path, value, rule):
    code, out, err = cli("layer-law", "--synthetic", SYNTHETIC, "--E-star", E_STAR, f"--hardness={value}",
                         "--no-figures", "--out", tmp_path / "law")
    assert code == 2 and out == ""
    assert err.startswith(f"contactlab: error: --hardness = {value!r} is not allowed: it must be {rule}")
    assert not (tmp_path / "law").exists()


def test_a_hardness_below_the_ladder_stops_naming_the_option(tmp_path):
    code, out, err = cli("layer-law", "--synthetic", SYNTHETIC, "--E-star", E_STAR, "--hardness", "1MPa",
                         "--no-figures", "--out", tmp_path / "law")
    assert code == 2 and out == ""
    assert err.startswith("contactlab: error: --hardness = '1MPa' (1e+06 Pa) is not allowed: it must exceed the "
                          "ladder's last mean pressure")


def test_the_law_file_and_figures_record_the_hardness(tmp_path):
    import tomllib

    code, out, err = cli("layer-law", "--synthetic", UNIT, "--E-star", 1, "--hardness", "0.1",
                         "--p-range", "1e-4:0.03", "--n-pressures", 6, "--out", tmp_path / "law")
    assert code == 0, err
    assert "hardness H = 0.1 Pa" in out
    topo = tomllib.loads((tmp_path / "law" / "layer_law.toml").read_text())["topography"]
    assert topo["hardness"] == 0.1 and topo["plastic_fraction"][-1] > 0
    for name in ("closure.png", "contact_fraction.png", "stiffness.png", "persson.png"):
        assert (tmp_path / "law" / name).stat().st_size > 0


# -- the two-scale check -------------------------------------------------------------------------

class _Stop(Exception):
    """Raised by the recorders below once they have seen a call's keywords."""


def test_the_two_scale_check_solves_every_model_with_the_hardness(monkeypatch):
    """The law's ladder (tabulated up to HARDNESS_SHARE H) and the resolved sphere receive the setting's
    hardness (the smooth spheres take it from the same keywords, two_scale._plastic); without it neither
    does. Recorders stand in for the solvers: what is checked is what they are given."""
    import bem
    from bem import rough
    from validation.studies import two_scale

    seen = []

    def record(what):
        def call(*args, **kw):
            seen.append((what, kw.get("hardness"), kw.get("pressures", [None])[-1]))
            raise _Stop
        return call

    monkeypatch.setattr(bem, "solve", record("solve"))
    monkeypatch.setattr(rough, "layer_from_topography", record("law"))
    for hardness in (4e9, None):
        s = dict(two_scale.QUICK, ratios=(2,), nodes_per_roll_off=4, layer_nodes_across=20, hardness=hardness)
        surface = two_scale.make_surface(s)
        seen.clear()
        for call in (lambda: two_scale.layer_laws(s, surface, 1e10),
                     lambda: two_scale.run_case(s, surface, (None, None), 2, 1.0)):
            with pytest.raises(_Stop):
                call()
        assert [(what, h) for what, h, _ in seen] == [("law", hardness), ("solve", hardness)]
        assert seen[0][2] == pytest.approx(1e10 if hardness is None else two_scale.HARDNESS_SHARE * hardness)
