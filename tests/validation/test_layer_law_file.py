"""A scene's tabulated layer read from a law file ([layer] law = "tabulated", file = ...): the law
of a topography solves as the same table inline, under the scene's trust rules, errors by key."""

import numpy as np
import pytest
import tomli_w

from validation.run import execute_scene
from validation.scene import SceneError, load_scene
from validation.run.sweep_folder import file_digests

pytest.importorskip("SurfaceTopography")

from bem import rough  # noqa: E402

E_STEEL = 210e9 / (2 * (1 - 0.3**2))  # steel on steel [Pa]
SCENE = {"scene": {"name": "rough_file"}, "bodies": {"E1": 210e9, "nu1": 0.3, "E2": 210e9, "nu2": 0.3},
         "gap": {"type": "paraboloid", "R": 0.01}, "load": {"force": 100.0}, "bem": {"nodes_across": 16}}


@pytest.fixture(scope="module")
def topography_law():
    surface = rough.self_affine((64, 64), (100e-6, 100e-6), hurst=0.8, rms_height=0.5e-6, long_cutoff=25e-6,
                                short_cutoff=100e-6 / 16, seed=1)
    p = np.geomspace(3e-3, 0.3, 8) * E_STEEL * surface.stats.rms_slope
    return rough.layer_from_topography(surface, E_STEEL, pressures=p, n_cols=64)


def _scene_file(folder, layer, name="scene.toml"):
    path = folder / name
    path.write_text(tomli_w.dumps(dict(SCENE, layer=layer)))
    return path


def test_a_scene_loads_a_topography_law_file_and_solves_as_the_inline_table(topography_law, tmp_path):
    topography_law.save(tmp_path / "law.toml")
    by_file = execute_scene(load_scene(_scene_file(tmp_path, {"law": "tabulated", "file": "law.toml"})))
    inline = execute_scene(load_scene(_scene_file(tmp_path, topography_law.layer_table(), "inline.toml")))
    assert by_file.bem.converged and inline.bem.converged
    assert by_file.bem.approach == inline.bem.approach
    assert np.array_equal(by_file.bem.p, inline.bem.p)
    assert by_file.bem.closure.max() > 0.3 * topography_law.closure[0]  # the layer takes part
    assert by_file.result.layer["parameters"] == topography_law.layer_table()


def test_the_law_file_is_hashed_as_a_file_the_scene_names(topography_law, tmp_path):
    topography_law.save(tmp_path / "law.toml")
    scene = load_scene(_scene_file(tmp_path, {"law": "tabulated", "file": "law.toml"}))
    assert scene.raw["layer"]["file"] == str(tmp_path / "law.toml")
    first = file_digests(scene.raw, {})
    (tmp_path / "law.toml").write_text((tmp_path / "law.toml").read_text() + "# edited\n")
    assert file_digests(scene.raw, {})["layer.file"] != first["layer.file"]


def test_a_law_file_outside_the_scene_folder_is_refused_unless_allowed(topography_law, tmp_path):
    topography_law.save(tmp_path / "law.toml")
    inner = tmp_path / "scene"
    inner.mkdir()
    path = _scene_file(inner, {"law": "tabulated", "file": "../law.toml"})
    with pytest.raises(SceneError, match=r"^layer.file = '../law.toml' is not allowed: .*outside the scene's folder"):
        load_scene(path)
    assert load_scene(path, allow_outside_files=True).layer.to_dict() == topography_law.layer_table()


@pytest.mark.parametrize("layer, text, match", [
    ({"law": "tabulated", "file": "none.toml"}, None, r"layer.file = '.*none.toml' is not allowed: there is no such"),
    ({"law": "tabulated", "file": "law.toml"}, "p = [", r"layer.file = .* is not valid TOML"),
    ({"law": "tabulated", "file": "law.toml"}, "[layer]\nlaw = 'tabulated'\np = [0.0, 1.0]\nw = [0.0, 1e-6]\n"
     "x = " + "[" * 5000 + "]" * 5000 + "\n", r"layer.file = .* nests arrays or tables more than 32 levels deep"),
    ({"law": "tabulated", "file": "la\x00w.toml"}, None, r"layer.file = 'la\\x00w.toml' is not allowed: .* NUL byte"),
    ({"law": "tabulated", "file": "law.toml"}, "[layer]\nlaw = 'linear'\nlam = 1e-12\n",
     r"layer.file = .* a \[layer\] table with law = 'tabulated', p and w"),
    ({"law": "tabulated", "file": "law.toml", "p": [0.0, 1.0]}, "",
     r"layer.p = \[0.0, 1.0\] is not allowed together with layer.file"),
    ({"law": "tabulated", "file": 3}, "", r"layer.file = 3 is not allowed"),
    ({"law": "tabulated", "file": "law.toml"}, "[layer]\nlaw = 'tabulated'\np = [0.0, 1.0]\nw = [0.0, -1.0]\n",
     r"^layer.w"),
])
def test_bad_law_files_are_refused_naming_the_key(tmp_path, layer, text, match):
    if text is not None:
        (tmp_path / "law.toml").write_text(text)
    with pytest.raises(SceneError, match=match):
        load_scene(_scene_file(tmp_path, layer))


def test_a_law_made_with_another_modulus_is_refused(topography_law, tmp_path):
    topography_law.save(tmp_path / "law.toml")
    scene = dict(SCENE, bodies={"E_star": 1.2 * E_STEEL}, layer={"law": "tabulated", "file": "law.toml"})
    (tmp_path / "scene.toml").write_text(tomli_w.dumps(scene))
    with pytest.raises(SceneError, match=r"layer.file = .* made with E_star = .*the scene's E_star is"):
        load_scene(tmp_path / "scene.toml")


def test_a_scene_loaded_beyond_its_law_file_notes_it_in_the_result_messages(topography_law, tmp_path):
    """The law's ladder stops below the peak pressure: the result says so, the answer is kept."""
    p, w = topography_law.mean_pressure[:3], topography_law.closure[:3]
    (tmp_path / "short.toml").write_text(tomli_w.dumps({"layer": {"law": "tabulated", "p": p.tolist(),
                                                                  "w": w.tolist()}}))
    run = execute_scene(load_scene(_scene_file(tmp_path, {"law": "tabulated", "file": "short.toml"})))
    assert run.bem.converged and run.bem.p_max > p[-1]
    notes = [m for m in run.result.messages if "exceeds the tabulated layer law's range" in m]
    assert len(notes) == 1 and notes[0].startswith("BEM: the peak pressure")
    assert f"0 <= p <= {p[-1]:.6g}" in notes[0] and f"p_max = {run.bem.p_max:.6g}" in notes[0]
    inline = execute_scene(load_scene(_scene_file(tmp_path, topography_law.layer_table(), "inline.toml")))
    assert not any("exceeds" in m for m in inline.result.messages)


def test_set_layer_file_replaces_an_inline_table_and_back(topography_law, tmp_path):
    topography_law.save(tmp_path / "law.toml")
    inline = _scene_file(tmp_path, {"law": "tabulated", "p": [0.0, 1e9], "w": [0.0, 1e-6]})
    scene = load_scene(inline, overrides=['layer.file="law.toml"'])
    assert scene.layer.to_dict() == topography_law.layer_table()
    by_file = _scene_file(tmp_path, {"law": "tabulated", "file": "law.toml"}, "by_file.toml")
    scene = load_scene(by_file, overrides=["layer.p=[0.0, 1e9]", "layer.w=[0.0, 1e-6]"])
    assert scene.layer.to_dict() == {"law": "tabulated", "p": [0.0, 1e9], "w": [0.0, 1e-6]}
