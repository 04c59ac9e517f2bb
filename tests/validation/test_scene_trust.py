"""What a scene file may reach: Python code it names is imported only with the opt-in
(``--allow-code``, ``allow_code=True``), never by ``contactlab check``; the files it names lie
inside its own folder unless ``--allow-outside-files``."""

import os

import numpy as np
import pytest
from tomli_w import dumps

from validation.scene import SceneError, check_scene, load_scene

from .conftest import cli

MODULE = '''\
import pathlib
pathlib.Path({marker!r}).write_text("imported")


def w(p):
    return 1e-12 * p


def gap(x, y):
    return (x**2 + y**2) / 0.02
'''
BASE = {"scene": {"name": "trusted", "units": "SI (m, Pa, N)"},
        "bodies": {"E1": 210e9, "nu1": 0.3, "E2": 210e9, "nu2": 0.3},
        "gap": {"type": "paraboloid", "R": 0.01}, "load": {"force": 100.0}, "bem": {"nodes_across": 16}}


@pytest.fixture
def code_module(tmp_path, monkeypatch):
    """An importable module ``marked_module`` whose import leaves a marker file; returns the marker."""
    marker = tmp_path / "imported.txt"
    (tmp_path / "marked_module.py").write_text(MODULE.format(marker=str(marker)))
    monkeypatch.syspath_prepend(str(tmp_path))
    yield marker
    import sys

    sys.modules.pop("marked_module", None)


def _write(tmp_path, raw, name="scene.toml"):
    path = tmp_path / name
    path.write_text(dumps(raw))
    return path


CUSTOM = {"law": "custom", "w": "marked_module:w", "p_scale": 1e9}
CALLABLE = {"type": "callable", "function": "marked_module:gap", "scale": 1e-4}


@pytest.mark.parametrize("part", ["layer", "gap", "series"])
def test_check_and_run_never_import_the_code_a_scene_names(tmp_path, code_module, part):
    raw = dict(BASE)
    if part == "layer":
        raw["layer"] = CUSTOM
    elif part == "series":
        raw["layer"] = {"law": "series", "a": {"law": "linear", "lam": 1e-12}, "b": CUSTOM}
    else:
        raw["gap"], raw["bem"] = CALLABLE, {"step": 1e-5, "extent": 2e-4}
    path = _write(tmp_path, raw)
    key = {"layer": "layer.w", "series": "layer.b.w", "gap": "gap.function"}[part]

    code, out, err = cli("check", path)
    assert code == 0 and err == "" and f"note: {key} = " in out and "--allow-code" in out
    code, out, err = cli("run", path, "--out", tmp_path / "out")
    assert code == 2 and err.startswith(f"contactlab: error: {key} = ") and "--allow-code" in err
    with pytest.raises(SceneError, match=key):
        load_scene(path)
    assert not code_module.exists() and not (tmp_path / "out").exists()

    scene = load_scene(path, allow_code=True)  # the opt-in imports it
    assert code_module.exists() and scene.allow_code


def test_os_system_named_by_a_scene_is_never_called(tmp_path, monkeypatch):
    calls = []
    monkeypatch.setattr(os, "system", lambda *a: calls.append(a) or 0)
    path = _write(tmp_path, {**BASE, "layer": {"law": "custom", "w": "os:system"}})
    assert cli("check", path)[0] == 0
    assert cli("run", path, "--out", tmp_path / "out")[0] == 2
    assert cli("sweep", path, "--param", "load.force", "--values", "50,100", "--out", tmp_path / "sw")[0] == 2
    with pytest.raises(SceneError, match="allow_code=True"):
        load_scene({**BASE, "layer": {"law": "custom", "w": "os:system"}})
    assert calls == []


def test_a_scene_given_code_by_override_or_sweep_is_refused(tmp_path, code_module):
    path = _write(tmp_path, {**BASE, "layer": {"law": "linear", "lam": 1e-12}})
    code, _, err = cli("run", path, "--set", 'layer.law="custom"', "--set", 'layer.w="marked_module:w"')
    assert code == 2 and "layer.w = 'marked_module:w'" in err
    raw = {**BASE, "layer": {"law": "custom", "w": lambda p: 1e-12 * p, "p_scale": 1e9},
           "sweep": {"parameter": "layer.w", "values": ["marked_module:w"]}}
    with pytest.raises(SceneError, match="layer.w = 'marked_module:w'"):
        load_scene(raw)
    assert not code_module.exists()


def test_check_refuses_a_code_name_of_the_wrong_form(tmp_path):
    path = _write(tmp_path, {**BASE, "layer": {"law": "custom", "w": "rm -rf /"}})
    code, out, err = cli("check", path)
    assert code == 2 and "layer.w = 'rm -rf /' is not allowed: it must name Python code as 'module:function'" in err


def test_a_callable_object_in_a_scene_dict_is_the_callers_own_code():
    scene = load_scene({**BASE, "layer": {"law": "custom", "w": lambda p: 1e-12 * p, "p_scale": 1e9}})
    assert scene.layer.w(np.array([2e9]))[0] == pytest.approx(2e-3)


def _measured(tmp_path, file):
    np.save(tmp_path / "z.npy", np.zeros((41, 41)) + np.add.outer(np.arange(41.0), np.arange(41.0)) ** 2 * 1e-3)
    return {**BASE, "gap": {"type": "measured", "file": file, "spacing": 5.0, "length_unit": "um"},
            "bem": {"step": 1e-5, "extent": 5e-5}}


@pytest.mark.parametrize("how", ["absolute", "dotdot", "symlink"])
def test_measured_files_outside_the_scene_folder_are_refused(tmp_path, how):
    outside = tmp_path / "outside"
    outside.mkdir()
    scene_dir = tmp_path / "scenes"
    scene_dir.mkdir()
    raw = _measured(outside, "z.npy")
    name = {"absolute": str(outside / "z.npy"), "dotdot": "../outside/z.npy", "symlink": "link.npy"}[how]
    if how == "symlink":
        (scene_dir / "link.npy").symlink_to(outside / "z.npy")
    raw["gap"]["file"] = name
    path = _write(scene_dir, raw)
    for load in (load_scene, check_scene):
        with pytest.raises(SceneError) as info:
            load(path)
        assert str(info.value).startswith(f"gap.file = {name!r} is not allowed") and "--allow-outside-files" in str(
            info.value)
    code, _, err = cli("check", path)
    assert code == 2 and "gap.file" in err
    assert cli("check", path, "--allow-outside-files")[0] == 0
    assert load_scene(path, allow_outside_files=True).gap_spec["file"] == str(scene_dir / name) or how == "absolute"


def test_measured_file_inside_the_scene_folder_and_its_reload(tmp_path):
    (tmp_path / "data").mkdir()
    raw = _measured(tmp_path / "data", "data/z.npy")
    scene = load_scene(_write(tmp_path, raw))
    assert load_scene(scene).gap_spec["file"] == str(tmp_path / "data" / "z.npy")  # re-validates in its folder


def test_file_errors_never_show_the_files_content(tmp_path):
    (tmp_path / "passwd.csv").write_text("root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1\n")
    (tmp_path / "passwd.asc").write_text("ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n"
                                         "root:x:0:0 secret\n1 2\n")
    for name, fmt in (("passwd.csv", "grid"), ("passwd.csv", "xyz"), ("passwd.asc", "asc")):
        gap = {"type": "measured", "file": name, "format": fmt}
        if fmt == "grid":
            gap["spacing"] = 1.0
        with pytest.raises(SceneError) as info:
            load_scene(_write(tmp_path, {**BASE, "gap": gap, "bem": {"step": 0.1, "extent": 0.3}}))
        message = str(info.value)
        assert message.startswith(f"gap.file = {str(tmp_path / name)!r} is not allowed")
        assert "root" not in message.replace(str(tmp_path), "") and "secret" not in message
