"""Scene loading: built-ins, overrides, normalisation, sizing, round trip of the written scene."""

import copy
import math
import tomllib

import pytest
from tomli_w import dumps

from validation.scene import (SceneError, apply_overrides, builtin_path, builtin_scenes, load_scene,
                              parse_override, parse_scene)

from .conftest import STEEL_E, STEEL_NU, e_star, hertz

BUILTINS = ("hertz", "paper_smooth", "paper_linear", "paper_elastic_rigid", "paper_bilinear", "paper_root",
            "roller", "punch", "rough_sphere", "elliptic")


def test_builtin_scenes_listed_with_descriptions():
    scenes = builtin_scenes()
    assert set(BUILTINS) <= set(scenes)
    assert all(desc.strip() for desc in scenes.values())


@pytest.mark.parametrize("name", BUILTINS)
def test_builtin_scene_loads_and_names_itself(name):
    scene = load_scene(name)
    assert scene.name == name
    assert scene.units.label == "SI (m, Pa, N)"
    assert scene.units.as_dict() == {"length": "m", "pressure": "Pa", "force": "N"}
    assert scene.source == f"builtin:{name}"
    assert load_scene(builtin_path(name)).raw == scene.raw  # by path, the same scene


@pytest.mark.parametrize("name", BUILTINS)
def test_validating_a_scene_evaluates_its_gap_a_handful_of_times(name, monkeypatch):
    """Sizing samples the radial profile once (bem.reference.estimate) and keeps it for every
    estimate; only the points of a [sweep], each a scene of its own, sample their own gap.
    (Before: 35,760 evaluations for paper_root, 42,912 for paper_bilinear.)"""
    import bem.gaps

    calls = []
    evaluate = bem.gaps.Gap.__call__
    monkeypatch.setattr(bem.gaps.Gap, "__call__", lambda self, x, y: calls.append(1) or evaluate(self, x, y))
    scene = load_scene(name)
    assert len(calls) <= 1 + (len(scene.sweep["values"]) if scene.sweep else 0)


def test_only_what_is_named_is_present():
    roller = load_scene("roller")
    assert roller.fem is None and roller.analytic is None and roller.sweep is None
    hz = load_scene("hertz")
    assert hz.fem == {"n_contact_elements": 16} and hz.analytic == {"kind": "hertz"}


def test_bodies_give_johnson_modulus():
    scene = load_scene("punch")
    assert scene.E_star == pytest.approx(e_star(210e9, 0.3, 70e9, 0.33), rel=1e-14)


def test_nodes_across_sizes_the_lattice_from_hertz():
    scene = load_scene("hertz", overrides=["bem.nodes_across=30", "bem.extent_factor=1.25"])
    a, _p0, _d = hertz(100.0, 0.01, e_star(STEEL_E, STEEL_NU, STEEL_E, STEEL_NU))
    assert scene.bem["step"] == pytest.approx(2 * a / 30, rel=1e-9)
    assert scene.bem["extent"] == pytest.approx((1.25 * a, 1.25 * a), rel=1e-9)
    assert scene.bem["extent_auto"] is True


def test_explicit_lattice_is_kept():
    scene = load_scene("hertz", overrides=["bem.step=1e-5", "bem.extent=[3e-4, 4e-4]"])
    assert scene.bem["step"] == 1e-5 and scene.bem["extent"] == (3e-4, 4e-4)
    assert scene.bem["extent_auto"] is False


def test_roller_region_stays_inside_the_roller():
    scene = load_scene("roller")
    ex, ey = scene.bem["extent"]
    assert ex < 0.005 and ex == pytest.approx(0.005, rel=2e-3)
    Es = e_star(STEEL_E, STEEL_NU, STEEL_E, STEEL_NU)
    b = math.sqrt(4 * 5000.0 * 0.004 / (math.pi * 0.01 * Es))  # Hertz line contact half-width
    assert ey == pytest.approx(1.6 * b, rel=1e-9)
    assert scene.gap.A == pytest.approx(7500.0 / (math.pi * 0.01 * Es), rel=1e-12)  # E* from [bodies]


def test_override_replaces_its_alternative():
    scene = load_scene("paper_elastic_rigid", overrides={"layer.p_cr": 5e8})
    assert "alpha_a" not in scene.layer_spec and scene.layer_spec["p_cr"] == 5e8
    scene = load_scene("hertz", overrides=["load.approach=2e-6"])
    assert scene.load == {"force": None, "approach": 2e-6}
    scene = load_scene("roller", overrides=["bodies.E_star=1e11"])
    assert scene.materials is None and scene.E_star == 1e11 and "E1" not in scene.raw["bodies"]
    with pytest.raises(SceneError, match="fem"):  # the FEM needs E1..nu2: refused
        load_scene("hertz", overrides=["bodies.E_star=1e11"])


def test_override_law_none_removes_the_layer():
    scene = load_scene("paper_linear", overrides=['layer.law="none"'])
    assert scene.layer_spec is None
    scene = load_scene("paper_linear", overrides=["layer.law=none"])  # bare word: a string
    assert scene.layer_spec is None


def test_short_alias_for_paper_parameters():
    scene = load_scene("paper_elastic_rigid", overrides=["alpha_a=0.25"])
    assert scene.layer_spec["alpha_a"] == 0.25


@pytest.mark.parametrize("text, expected", [
    ("bem.nodes_across=20", ("bem.nodes_across", 20)),
    ("load.force = 2.5e3", ("load.force", 2500.0)),
    ("bem.extent=[1e-3, 2e-3]", ("bem.extent", [1e-3, 2e-3])),
    ("bem.precondition=false", ("bem.precondition", False)),
    ('layer.law="root"', ("layer.law", "root")),
    ("layer.law=root", ("layer.law", "root")),
])
def test_parse_override(text, expected):
    assert parse_override(text) == expected


def test_inputs_are_not_modified():
    raw = tomllib.loads(builtin_path("paper_bilinear").read_text())
    before = copy.deepcopy(raw)
    apply_overrides(raw, ["alpha_c=0.3", "bem.step=1e-5"])
    parse_scene(raw, overrides={"bem.nodes_across": 20})
    assert raw == before
    overrides = ["load.force=50.0"]
    scene = load_scene("hertz", overrides=overrides)
    assert overrides == ["load.force=50.0"] and scene.raw["load"]["force"] == 50.0


def test_written_scene_reloads_identically():
    scene = load_scene("rough_sphere", overrides=["bem.nodes_across=20"])
    again = parse_scene(tomllib.loads(dumps(scene.raw)))
    assert again.raw == scene.raw
    assert again.bem["step"] == scene.bem["step"]


def test_toml_writer_round_trips_odd_values():
    data = {"scene": {"name": "x", "title": 'quote " and \\ back\nline'},
            "gap": {"h": [[0.0, 1e-300], [float("inf"), -2.5]], "flag": True, "n": -3},
            "layer": {"law": "series", "a": {"law": "linear", "lam": 0.1 + 0.2}}}
    assert tomllib.loads(dumps(data)) == data


def test_layer_sweep_points_all_validated():
    with pytest.raises(SceneError, match=r"sweep.values\[2\]"):
        load_scene("paper_bilinear", overrides={"sweep.values": [0.0, 0.5, 1.6]})
