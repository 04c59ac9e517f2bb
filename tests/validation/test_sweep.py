"""Sweeps: every point validated first, saved one file each, resumable, local or Dask parallel."""

import csv
import json
import sys
import types

import pytest

import bem
import validation.run.cluster as cluster
import validation.run.runner as runner
from validation.extras import MissingExtraError
from validation.run import run_scene
from validation.scene import SceneError
from validation.run.sweep import parse_values, run_sweep, sweep_points

from .conftest import cli

FAST = ["bem.nodes_across=16"]
FORCES = [50.0, 100.0, 200.0]


def _sweep(out, **kw):
    kw = {"parameter": "load.force", "values": FORCES, "workers": 1, "overrides": FAST, **kw}
    return run_sweep("elliptic", out, **kw)


def _point(out, summary, i):
    """The point file of row ``i`` of a summary."""
    return out / summary["points"][i]["file"]


def test_points_are_saved_with_profile_and_summary(tmp_path):
    summary = _sweep(tmp_path)
    assert summary["computed"] == [0, 1, 2] and summary["reused"] == [] and summary["failed"] == []
    assert len(list((tmp_path / "points").iterdir())) == 3
    for i, force in enumerate(FORCES):
        point = json.loads(_point(tmp_path, summary, i).read_text())
        assert point["value"] == force and point["key"] == "load.force"
        assert point["scene"]["load"] == {"force": force}
        r = point["result"]
        assert r["force"] == pytest.approx(force, rel=1e-12)
        assert len(r["profile"]["x"]) == len(r["profile"]["p"]) > 10
        assert max(r["profile"]["p"]) == pytest.approx(r["p_max"], rel=1e-12)  # the peak lies on y = 0
    # Hertz: p_max ~ P^(1/3) (an independent scaling law)
    p = [row["p_max"] for row in summary["points"]]
    assert p[2] / p[0] == pytest.approx(4 ** (1 / 3), rel=0.02)
    with open(tmp_path / "summary.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [float(r["p_max"]) for r in rows] == p
    assert json.loads((tmp_path / "summary.json").read_text())["points"][1]["value"] == 100.0


def test_sweep_tells_its_progress_as_label_done_total(tmp_path):
    """One progress protocol (validation.progress): the point and its status, then how many of all are done."""
    calls = []
    _sweep(tmp_path, progress=lambda *a: calls.append(a))
    assert sorted(c[1] for c in calls) == [1, 2, 3] and {c[2] for c in calls} == {3}
    assert {c[0] for c in calls} == {f"load.force = {f}: converged" for f in FORCES}


def test_sweep_resumes_recomputing_only_missing_points(tmp_path):
    first = _sweep(tmp_path)
    kept = {i: _point(tmp_path, first, i).stat().st_mtime_ns for i in (0, 2)}
    _point(tmp_path, first, 1).unlink()
    second = _sweep(tmp_path)
    assert second["computed"] == [1] and second["reused"] == [0, 2] and second["kept"] == []
    for i, mtime in kept.items():
        assert _point(tmp_path, first, i).stat().st_mtime_ns == mtime
    assert [r["p_max"] for r in second["points"]] == [r["p_max"] for r in first["points"]]


def test_changed_scene_is_not_reused(tmp_path):
    _sweep(tmp_path)
    again = _sweep(tmp_path / "other", overrides=["bem.nodes_across=18"])
    assert again["computed"] == [0, 1, 2]


def test_bad_value_refused_before_any_point_runs(tmp_path, monkeypatch):
    def no_work(*a, **k):
        raise AssertionError("a point ran before the sweep was validated")

    monkeypatch.setattr(runner, "run_scene", no_work)
    with pytest.raises(SceneError, match=r"sweep.values\[2\].*load.force"):
        _sweep(tmp_path, values=[50.0, 100.0, -1.0])
    assert not (tmp_path / "points").exists() or not any((tmp_path / "points").iterdir())


def test_failed_point_is_reported_and_retried(tmp_path, monkeypatch):
    real = runner.run_scene

    def flaky(scene, *a, **k):
        if scene.load["force"] == 100.0:
            raise RuntimeError("node crashed")
        return real(scene, *a, **k)

    monkeypatch.setattr(runner, "run_scene", flaky)
    summary = _sweep(tmp_path)
    assert summary["failed"] == [1]
    assert summary["points"][1]["status"] == "error" and "node crashed" in summary["points"][1]["error"]
    assert summary["points"][1]["file"] is None and len(list((tmp_path / "points").iterdir())) == 2
    monkeypatch.setattr(runner, "run_scene", real)
    assert _sweep(tmp_path)["computed"] == [1]


def test_paper_alpha_a_sweep_spans_smooth_to_linear(tmp_path):
    small = ["bem.nodes_across=16", "fem.n_contact_elements=8"]
    summary = run_sweep("paper_elastic_rigid", tmp_path, parameter="alpha_a", values=[0.0, 0.5, 1.0],
                        workers=1, overrides=small)
    p = [row["p_max"] for row in summary["points"]]
    point = json.loads(_point(tmp_path, summary, 0).read_text())["result"]
    smooth = bem.solve(bem.gaps.Paraboloid(0.01), E_star=point["bem"]["E_star"], force=100.0,
                       step=point["bem"]["step"], extent=point["bem"]["extent"])  # the same lattice
    linear = run_scene("paper_linear", overrides=small)
    assert p[0] == pytest.approx(smooth.p_max, rel=1e-9)  # alpha_a = 0: smooth bodies
    assert p[2] == pytest.approx(linear.p_max, rel=1e-6)  # alpha_a = 1: the linear layer
    assert p[0] > p[1] > p[2]


def test_local_processes_give_the_serial_results(tmp_path):
    serial = _sweep(tmp_path / "s", values=FORCES[:2])
    parallel = _sweep(tmp_path / "p", values=FORCES[:2], workers=2)
    assert [r["p_max"] for r in parallel["points"]] == [r["p_max"] for r in serial["points"]]


def _fake_dask(monkeypatch):
    """A synchronous stand-in for dask.distributed (Client.submit runs the function at once)."""

    class Future:
        def __init__(self, fn, args):
            self.status, self._exc, self._value = "finished", None, None
            try:
                self._value = fn(*args)
            except Exception as exc:  # noqa: BLE001
                self.status, self._exc = "error", exc

        def result(self):
            return self._value

        def exception(self):
            return self._exc

    class Client:
        made = []

        def __init__(self, address, timeout=None):
            self.address, self.closed = address, False
            Client.made.append(self)

        def submit(self, fn, *args, pure=True):
            return Future(fn, args)

        def close(self):
            self.closed = True

    distributed = types.ModuleType("dask.distributed")
    distributed.Client, distributed.as_completed = Client, lambda futures: iter(futures)
    dask = types.ModuleType("dask")
    dask.distributed = distributed
    monkeypatch.setitem(sys.modules, "dask", dask)
    monkeypatch.setitem(sys.modules, "dask.distributed", distributed)
    return Client


def test_dask_path_with_a_stand_in_client(tmp_path, monkeypatch):
    client = _fake_dask(monkeypatch)
    monkeypatch.setattr(cluster, "probe_scheduler", lambda address, timeout: None)  # no server behind it
    summary = _sweep(tmp_path, values=FORCES[:2], scheduler="tcp://scheduler:8786")
    assert summary["computed"] == [0, 1]
    assert [c.address for c in client.made] == ["tcp://scheduler:8786"] and client.made[0].closed
    local = _sweep(tmp_path / "local", values=FORCES[:2])
    assert [r["p_max"] for r in summary["points"]] == [r["p_max"] for r in local["points"]]


def test_dask_missing_is_a_clear_error(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "dask", None)  # import dask -> ImportError
    with pytest.raises(MissingExtraError, match=r"install contactlab\[dask\]"):
        _sweep(tmp_path, scheduler="tcp://nowhere:8786")
    assert not (tmp_path / "points").exists()  # stopped before any work
    code, _out, err = cli("sweep", "elliptic", "--param", "load.force", "--values", "50", "--scheduler",
                          "tcp://nowhere:8786", "--out", tmp_path / "c", "--set", "bem.nodes_across=16")
    assert code == 2 and "install contactlab[dask]" in err


def test_real_dask_local_cluster(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False) as cluster, \
            distributed.Client(cluster) as client:
        summary = _sweep(tmp_path, values=FORCES[:2], scheduler=client)
    assert summary["computed"] == [0, 1] and summary["failed"] == []


@pytest.mark.parametrize("text, values", [
    ("0,0.25,0.5", [0, 0.25, 0.5]),
    ("0:1:5", [0.0, 0.25, 0.5, 0.75, 1.0]),
    ("1e3, 2e3", [1000.0, 2000.0]),
    ('"log", "circular"', ["log", "circular"]),
])
def test_parse_values(text, values):
    assert parse_values(text) == values


@pytest.mark.parametrize("text", ["", "0:1", "0:1:0", "a:b:c", "1,,2"])
def test_parse_values_refuses(text):
    with pytest.raises(SceneError, match="--values"):
        parse_values(text)


def test_scene_sweep_section_is_the_default():
    param, key, points = sweep_points("paper_bilinear", overrides=["bem.nodes_across=16"])
    assert param == "alpha_c" and key == "layer.alpha_c"
    assert [p.value for p in points] == [0.0, 0.1, 0.4, 0.8, 1.2]
    assert [p.scene.layer_spec["alpha_c"] for p in points] == [0.0, 0.1, 0.4, 0.8, 1.2]


def test_cli_sweep(tmp_path):
    code, out, err = cli("sweep", "elliptic", "--param", "load.force", "--values", "50,100", "--workers", "1",
                         "--out", tmp_path, "--set", "bem.nodes_across=16")
    assert code == 0, err
    assert (tmp_path / "summary.csv").is_file() and "computed 2, reused 0, failed 0" in out
    code, out, _ = cli("sweep", "elliptic", "--param", "load.force", "--values", "50,100", "--out", tmp_path,
                       "--set", "bem.nodes_across=16")
    assert code == 0 and "computed 0, reused 2" in out


def test_cli_sweep_param_without_values(tmp_path):
    code, _out, err = cli("sweep", "elliptic", "--param", "load.force", "--out", tmp_path)
    assert code == 2 and "--values" in err


def test_a_point_that_did_not_converge_carries_its_solvers_status(tmp_path):
    """A sweep point's status is the run's: the BEM's own status word where it stopped early."""
    summary = _sweep(tmp_path, overrides=FAST + ["bem.maxiter=2"])
    rows = summary["points"]
    assert [r["status"] for r in rows] == ["maxiter"] * 3 and not any(r["converged"] for r in rows)
    point = json.loads(_point(tmp_path, summary, 0).read_text())
    assert point["result"]["bem"]["status"] == "maxiter"
