"""A sweep folder: points keyed by their value, scene and file contents; resumed, extended with other
values, and refused (never overwritten) when it holds another sweep; --values with words, typed as
the key; the size limit of a sweep."""

import csv
import hashlib
import json

import numpy as np
import pytest
from tomli_w import dumps

import validation.run.runner as runner
from validation.io import OutputError
from validation.run import run_scene
from validation.run.sweep import parse_values, run_sweep, sweep_points
from validation.scene import SceneError, load_scene

from .conftest import cli

FAST = ["bem.nodes_across=16"]


def _sweep(out, values, **kw):
    kw = {"parameter": "load.force", "workers": 1, "overrides": FAST, **kw}
    return run_sweep("elliptic", out, values=values, **kw)


def _files(out):
    """``{name: bytes}`` of the point files in ``out``."""
    return {p.name: p.read_bytes() for p in sorted((out / "points").iterdir())}


def _no_runs(monkeypatch):
    def no_work(*a, **k):
        raise AssertionError("a point ran")

    monkeypatch.setattr(runner, "run_scene", no_work)


def test_same_values_resume_without_running_or_rewriting(tmp_path, monkeypatch):
    first = _sweep(tmp_path, [50.0, 100.0])
    before = _files(tmp_path)
    _no_runs(monkeypatch)
    again = _sweep(tmp_path, [100.0, 50.0])
    assert again["computed"] == [] and again["reused"] == [0, 1] and again["kept"] == []
    assert _files(tmp_path) == before
    assert [r["p_max"] for r in again["points"]] == [r["p_max"] for r in first["points"]]


def test_other_values_extend_the_folder_and_the_summary_lists_all(tmp_path):
    first = _sweep(tmp_path, [100.0, 50.0])
    before = _files(tmp_path)
    second = _sweep(tmp_path, [200.0, 100.0])
    assert second["values"] == [50.0, 100.0, 200.0]
    assert second["computed"] == [2] and second["reused"] == [1] and second["kept"] == [0]
    after = _files(tmp_path)
    assert len(after) == 3 and all(after[name] == data for name, data in before.items())  # none overwritten
    p = {r["value"]: r["p_max"] for r in second["points"]}
    assert [p[50.0], p[100.0]] == [r["p_max"] for r in first["points"]]
    alone = _sweep(tmp_path / "alone", [200.0])
    assert p[200.0] == alone["points"][0]["p_max"]
    with open(tmp_path / "summary.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [float(r["value"]) for r in rows] == [50.0, 100.0, 200.0]
    assert all((tmp_path / r["file"]).is_file() for r in rows)
    saved = json.loads((tmp_path / "summary.json").read_text())
    assert [r["value"] for r in saved["points"]] == saved["values"] == [50.0, 100.0, 200.0]


def test_cli_reports_points_kept_from_earlier_runs(tmp_path):
    base = ("sweep", "elliptic", "--param", "load.force", "--workers", "1", "--out", tmp_path, "--set", FAST[0])
    assert cli(*base, "--values", "50")[0] == 0
    code, out, err = cli(*base, "--values", "100")
    assert code == 0, err
    assert "computed 1, reused 0, failed 0, 1 more from earlier runs" in out


def test_changed_scene_into_the_same_folder_is_refused(tmp_path, monkeypatch):
    _sweep(tmp_path, [50.0, 100.0])
    before = _files(tmp_path)
    _no_runs(monkeypatch)
    with pytest.raises(OutputError, match=r"--out = .*another sweep.*bem.nodes_across = 16 there, 18 here"):
        _sweep(tmp_path, [50.0, 100.0], overrides=["bem.nodes_across=18"])
    with pytest.raises(OutputError, match=r"sweep of load.force, not of bem.nodes_across"):
        _sweep(tmp_path, [16, 18], parameter="bem.nodes_across")
    assert _files(tmp_path) == before
    code, _out, err = cli("sweep", "elliptic", "--param", "load.force", "--values", "50", "--out", tmp_path,
                          "--set", "bem.nodes_across=18")
    assert code == 2 and err.count("\n") == 1 and "--out" in err and "Traceback" not in err


def _measured_scene(folder, R):
    """A scene whose gap is a measured paraboloid of radius ``R`` [m] in ``surface.npy`` [um]."""
    x = (np.arange(121) - 60) * 5.0  # um
    X, Y = np.meshgrid(x, x)
    np.save(folder / "surface.npy", (X**2 + Y**2) * 1e-6 / (2 * R))
    raw = {"scene": {"name": "measured"}, "bodies": {"E1": 210e9, "nu1": 0.3, "E2": 210e9, "nu2": 0.3},
           "gap": {"type": "measured", "file": "surface.npy", "length_unit": "um", "spacing": 5.0},
           "load": {"force": 100.0}, "bem": {"step": 1e-5, "extent": 2.5e-4}}
    (folder / "scene.toml").write_text(dumps(raw))
    return folder / "scene.toml"


def test_a_changed_measured_file_is_not_reused(tmp_path):
    scene = _measured_scene(tmp_path, R=0.01)
    out = tmp_path / "sweep"
    first = run_sweep(scene, out, parameter="load.force", values=[50.0, 100.0], workers=1)
    digest = hashlib.sha256((tmp_path / "surface.npy").read_bytes()).hexdigest()
    point = json.loads((out / first["points"][0]["file"]).read_text())
    assert point["files"] == {"gap.file": digest}
    before = _files(out)
    _measured_scene(tmp_path, R=0.002)  # same path, other contents
    with pytest.raises(OutputError, match=r"the contents of the file gap\.file"):
        run_sweep(scene, out, parameter="load.force", values=[50.0, 100.0], workers=1)
    assert _files(out) == before
    fresh = run_sweep(scene, tmp_path / "fresh", parameter="load.force", values=[50.0, 100.0], workers=1)
    assert fresh["computed"] == [0, 1]
    assert fresh["points"][1]["p_max"] > 1.5 * first["points"][1]["p_max"]  # Hertz: (R0/R)^(2/3) = 2.9


def test_a_swept_file_whose_contents_changed_is_refused(tmp_path):
    for name, R in (("a", 0.01), ("b", 0.005)):
        (tmp_path / name).mkdir()
        _measured_scene(tmp_path / name, R)
    files = [str(tmp_path / "a" / "surface.npy"), str(tmp_path / "b" / "surface.npy")]
    scene = load_scene(tmp_path / "a" / "scene.toml", allow_outside_files=True)  # b/ lies outside a/
    out = tmp_path / "sweep"
    first = run_sweep(scene, out, parameter="gap.file", values=files, workers=1)
    assert first["computed"] == [0, 1]
    assert run_sweep(scene, out, parameter="gap.file", values=files, workers=1)["reused"] == [0, 1]
    before = _files(out)
    _measured_scene(tmp_path / "b", 0.002)
    with pytest.raises(OutputError, match=r"gap.file = .*b/surface.npy.*another scene.*contents of the file gap.file"):
        run_sweep(scene, out, parameter="gap.file", values=files, workers=1)
    assert _files(out) == before


@pytest.mark.parametrize("text, values", [
    ("none,tabulated", ["none", "tabulated"]),
    ("linear, none", ["linear", "none"]),
    ("mymodule:w,mymodule:w2", ["mymodule:w", "mymodule:w2"]),
    ('none, "root", 0.5', ["none", "root", 0.5]),
])
def test_parse_values_takes_bare_words_as_strings(text, values):
    assert parse_values(text) == values


def test_values_are_typed_as_the_key():
    _p, _k, points = sweep_points("elliptic", "bem.nodes_across", parse_values("16:24:3"), overrides=FAST)
    assert [p.value for p in points] == [16, 20, 24] and all(type(p.value) is int for p in points)
    _p, _k, points = sweep_points("elliptic", "load.force", parse_values("50,100"), overrides=FAST)
    assert [p.scene.raw["load"]["force"] for p in points] == [50.0, 100.0]
    assert all(type(p.value) is float for p in points)


def test_cli_sweeps_a_string_key(tmp_path):
    small = ["bem.nodes_across=16", "fem.n_contact_elements=8"]
    args = ["sweep", "paper_linear", "--param", "layer.law", "--values", "linear,none", "--workers", "1",
            "--out", tmp_path]
    code, out, err = cli(*args, *(a for s in small for a in ("--set", s)))
    assert code == 0, err
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["values"] == ["linear", "none"]
    smooth = run_scene("paper_linear", overrides=[*small, "layer.law=none"])
    assert summary["points"][1]["p_max"] == pytest.approx(smooth.p_max, rel=1e-12)
    assert summary["points"][0]["p_max"] < summary["points"][1]["p_max"]  # the layer lowers the peak


@pytest.mark.parametrize("text, n", [("50:100:1000000000", 1000000000), ("50:100:10001", 10001),
                                     (",".join(str(50 + i) for i in range(100_000)), 100_000)],
                         ids=["range-1e9", "range-10001", "list-100000"])
def test_too_many_values_refused_before_they_are_made(text, n):
    with pytest.raises(SceneError, match=rf"--values = .* is not allowed: it gives {n} points, more than the "
                                         r"10000 points"):
        parse_values(text)


def test_too_many_values_refused_before_any_point(tmp_path, monkeypatch):
    _no_runs(monkeypatch)
    assert len(parse_values("0:1:10000")) == 10000
    with pytest.raises(SceneError, match=r"sweep.values = .* it gives 10001 points"):
        _sweep(tmp_path, [50.0 + i for i in range(10_001)])
    assert not (tmp_path / "points").exists()
    code, _out, err = cli("sweep", "elliptic", "--param", "load.force", "--values", "50:100:1000000000",
                          "--out", tmp_path)
    assert code == 2 and "--values" in err and "1000000000" in err and "10000" in err


def test_a_hidden_unfinished_write_does_not_block_the_folder(tmp_path):
    first = _sweep(tmp_path, [50.0])
    (tmp_path / "points" / ".point-0123.json.tmp4567.json").write_text("{")  # a write killed half-way
    assert _sweep(tmp_path, [50.0])["reused"] == [0] and first["computed"] == [0]
