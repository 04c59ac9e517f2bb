"""A report of a result or sweep folder reads it as data: the Python code its layer names
(``layer.parameters.w = "module:function"``) is never imported or called; the w(p) plot is
left out with a warning that says why."""

import json
import os
import sys

import pytest

from .conftest import cli

FAST = ("--no-fem", "--set", "bem.nodes_across=16")
MODULE = 'import pathlib\npathlib.Path({marker!r}).write_text("imported")\n\n\ndef w(p):\n    return 1e-12 * p\n'


@pytest.fixture
def planted(tmp_path, monkeypatch):
    """An importable module ``planted_module`` whose import writes a file, and a record of ``os.system``
    calls; returns ``(marker file, calls)``."""
    marker = tmp_path / "imported.txt"
    (tmp_path / "planted_module.py").write_text(MODULE.format(marker=str(marker)))
    monkeypatch.syspath_prepend(str(tmp_path))
    calls = []
    monkeypatch.setattr(os, "system", lambda *a: calls.append(a) or 0)
    yield marker, calls
    sys.modules.pop("planted_module", None)


def _name_code(path, where, name):
    """Rewrite the layer of the run stored in the JSON file ``path`` (at the keys ``where``) to a custom
    law naming the code ``name``."""
    data = json.loads(path.read_text())
    result = data
    for key in where:
        result = result[key]
    result["layer"]["parameters"] = {"law": "custom", "w": name, "p_scale": 1e9}
    path.write_text(json.dumps(data))


@pytest.mark.parametrize("name", ["planted_module:w", "os:system"])
def test_a_report_of_a_result_folder_never_imports_the_code_it_names(tmp_path, planted, name):
    marker, calls = planted
    out = tmp_path / "r"
    assert cli("run", "paper_linear", "--out", out, *FAST)[0] == 0
    _name_code(out / "result.json", (), name)
    code, stdout, err = cli("report", out)
    assert code == 0 and "report written" in stdout
    assert not marker.exists() and "planted_module" not in sys.modules and calls == []
    assert not (out / "report" / "figures" / "layer_law.png").exists()
    assert f"layer.w = {name!r}" in err and "never imports" in err


def test_a_report_of_a_sweep_folder_never_imports_the_code_it_names(tmp_path, planted):
    marker, calls = planted
    out = tmp_path / "s"
    argv = ("sweep", "paper_linear", "--param", "load.force", "--values", "50,100", "--workers", "1", "--out", out)
    assert cli(*argv, *FAST)[0] == 0
    for point in (out / "points").glob("point-*.json"):
        _name_code(point, ("result",), "planted_module:w")
    code, stdout, err = cli("report", out)
    assert code == 0 and "report written" in stdout
    assert not marker.exists() and "planted_module" not in sys.modules and calls == []
    assert "layer.w = 'planted_module:w'" in err
