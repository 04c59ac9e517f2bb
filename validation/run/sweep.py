"""Parameter sweeps of a scene: one scene parameter over a list of values, resumable.

Every point is a complete scene (the base scene with ``parameter = value``) validated before
any work. Points run in parallel on local cores (:func:`validation.run.pool.worker_pool`,
``workers`` = cores by default; the workers end with the sweep) or on a Dask cluster when a
scheduler address is given (``dask.distributed``, optional, imported only then). Each finished point is saved at once as
its own JSON file (atomically), ``points/point-NNN.json``, holding the point's full result
(``result.json`` content, the axial section profile included); a rerun skips the points
already on disk for the same scene (``fingerprint``: SHA-256 of the point's scene), so an
interrupted sweep resumes where it stopped. At the end a summary table is written as
``summary.json`` and ``summary.csv``.

The paper's sweeps (section 6): ``alpha_a`` in ``[0, 1]`` (elastic-rigid, Fig. 5/9),
``alpha_c`` (bilinear), ``alpha_b`` (root law, Fig. 10-11).
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import logging
import os
import traceback
from concurrent.futures import as_completed
from pathlib import Path

from bem.files import write_text

from ..extras import require as require_extra
from ..io import atomic_write_json, check_output_dir, write_marker
from ..scene.checks import SceneError
from ..scene.load import Scene, apply_overrides, load_scene, parse_scene
from .pool import worker_pool

__all__ = ["run_sweep", "sweep_points", "SweepPoint", "SUMMARY_COLUMNS", "parse_values", "SWEEP_NAMES"]

log = logging.getLogger(__name__)

SUMMARY_COLUMNS = ("index", "value", "status", "p_max", "force", "approach", "contact_radius", "contact_area",
                   "converged", "iterations", "kkt_residual", "alpha_b", "p_max_lambda", "wall_time_bem",
                   "wall_time_fem", "computed", "file")
#: What a sweep directory holds besides its marker ``.contactlab`` (:func:`validation.io.check_output_dir`).
SWEEP_NAMES = ("points", "summary.json", "summary.csv", "report")


class SweepPoint:
    """One point: its index, value, validated scene and file name."""

    def __init__(self, index, value, scene):
        self.index, self.value, self.scene = index, value, scene
        text = json.dumps(scene.raw, sort_keys=True, default=str)
        self.fingerprint = hashlib.sha256(text.encode()).hexdigest()
        self.file = f"point-{index:03d}.json"


def parse_values(text):
    """``"0,0.25,0.5"`` (TOML values) or ``"start:stop:num"`` (evenly spaced) -> list."""
    import tomllib

    import numpy as np

    text = text.strip()
    parts = text.split(":")
    if len(parts) == 3:
        try:
            start, stop, num = float(parts[0]), float(parts[1]), int(parts[2])
        except ValueError:
            raise SceneError(f"--values {text!r} is not allowed: start:stop:num needs two numbers and an "
                             "integer, e.g. 0:1:5.") from None
        if num < 1:
            raise SceneError(f"--values {text!r} is not allowed: num must be >= 1.")
        return [float(v) for v in np.linspace(start, stop, num)]
    try:
        values = tomllib.loads(f"v = [{text}]")["v"]
    except tomllib.TOMLDecodeError:
        raise SceneError(f"--values {text!r} is not allowed: give comma-separated numbers (0,0.25,0.5) or "
                         "start:stop:num (0:1:5).") from None
    if not values:
        raise SceneError(f"--values {text!r} is not allowed: it must hold at least one value.")
    return values


def sweep_points(scene, parameter=None, values=None, *, overrides=None):
    """Validate every point of a sweep (before any work); returns ``(parameter, key, points)``.

    Parameters
    ----------
    scene : Scene, str, path-like or dict
        The base scene.
    parameter : str, optional
        ``alpha_a``, ``alpha_b``, ``alpha_c`` or a dotted key (``layer.lam``, ``load.force``);
        default: the scene's ``[sweep]``.
    values : list, optional
        The values; default: the scene's ``[sweep] values``.
    overrides : dict or list of str, optional
        Applied to the base scene first.
    """
    base = scene if isinstance(scene, Scene) and not overrides else load_scene(scene, overrides=overrides)
    if parameter is None and values is None and base.sweep is not None:
        parameter, values = base.sweep["parameter"], base.sweep["values"]
    if parameter is None or values is None:
        raise SceneError(f"sweep parameter = {parameter!r}, values = {values!r} is not allowed: give both "
                         "(--param and --values), or neither to use the scene's [sweep] section.")
    raw = {k: v for k, v in base.raw.items() if k != "sweep"}
    raw["sweep"] = {"parameter": parameter, "values": list(values)}
    checked = parse_scene(raw, source=base.source)  # checks the parameter and every value
    key = checked.sweep["key"]
    raw.pop("sweep")
    points = []
    for i, value in enumerate(checked.sweep["values"]):
        point = parse_scene(apply_overrides(raw, {key: value}), source=base.source)
        points.append(SweepPoint(i, value, point))
    return parameter, key, points


def _solve_point(raw, source):
    """Worker: run one point's scene (BEM, and FEM/analytic when named) and return its result."""
    from .runner import run_scene

    return run_scene(parse_scene(raw, source=source))


def _load_point(path, fingerprint):
    try:
        with open(path, encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, ValueError):
        return None
    return data if data.get("fingerprint") == fingerprint else None


def _row(point, result, *, computed, error=None):
    row = {"index": point.index, "value": point.value, "computed": computed, "file": f"points/{point.file}"}
    if error is not None:
        row.update(status="error", error=error, file=None)
        return row
    layer = result.get("layer") or {}
    wall = result.get("wall_time_s") or {}
    row.update(
        status="ok" if result["converged"] else "not_converged",
        p_max=result["p_max"], force=result["force"], approach=result["approach"],
        contact_radius=result.get("contact_radius"), contact_area=result["contact_area"],
        converged=result["converged"], iterations=result["iterations"], kkt_residual=result["kkt_residual"],
        alpha_b=result.get("alpha_b"), p_max_lambda=layer.get("p_max_lambda"),
        wall_time_bem=wall.get("bem"), wall_time_fem=wall.get("fem"))
    return row


def _local_map(jobs, workers):
    """Yield ``(point, result, error)`` as local jobs finish (in-process when workers == 1)."""
    if workers == 1 or len(jobs) == 1:
        for point in jobs:
            try:
                yield point, _solve_point(point.scene.raw, point.scene.source), None
            except Exception:  # noqa: BLE001 - a failed point is reported, the sweep goes on
                yield point, None, traceback.format_exc(limit=3)
        return
    with worker_pool(workers) as pool:  # its workers end with this process
        futures = {pool.submit(_solve_point, p.scene.raw, p.scene.source): p for p in jobs}
        try:
            for fut in as_completed(futures):
                exc = fut.exception()
                error = None if exc is None else "".join(traceback.format_exception(exc, limit=3))
                yield futures[fut], None if exc else fut.result(), error
        except BaseException:
            for fut in futures:
                fut.cancel()
            raise


def _dask_client(scheduler):
    """A ``dask.distributed.Client`` for an address (or a Client/cluster object); owned flag."""
    if isinstance(scheduler, str):
        require_extra("dask", f"--scheduler {scheduler!r} (a Dask cluster; without it the sweep runs on local cores)")
    from dask import distributed

    if isinstance(scheduler, distributed.Client):
        return scheduler, False
    return distributed.Client(scheduler), True


def _dask_map(jobs, client):
    """Yield ``(point, result, error)`` as Dask futures finish on ``client``."""
    from dask.distributed import as_completed as dask_completed

    futures = {client.submit(_solve_point, p.scene.raw, p.scene.source, pure=False): p for p in jobs}
    for fut in dask_completed(list(futures)):
        point = futures[fut]
        if fut.status == "error":
            yield point, None, "".join(traceback.format_exception(fut.exception(), limit=3))
        else:
            yield point, fut.result(), None


def _write_summary(out, meta, rows):
    rows = sorted(rows, key=lambda r: r["index"])
    atomic_write_json(out / "summary.json", dict(meta, points=rows))
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=SUMMARY_COLUMNS, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: "" if row.get(k) is None else row.get(k) for k in SUMMARY_COLUMNS})
    write_text(out / "summary.csv", buf.getvalue())
    return rows


def run_sweep(scene, out_dir, *, parameter=None, values=None, workers=None, scheduler=None, progress=None,
              overrides=None):
    """Run a resumable sweep and write its point files and summary table.

    Parameters
    ----------
    scene : Scene, str, path-like or dict
        The base scene.
    out_dir : path-like
        Sweep directory: ``points/point-NNN.json``, ``summary.json``, ``summary.csv`` and the
        marker ``.contactlab``; it must be new, empty or a sweep directory (a directory holding
        anything else is refused: :class:`validation.io.OutputError`).
    parameter, values : optional
        See :func:`sweep_points` (default: the scene's ``[sweep]``).
    workers : int, optional
        Local worker processes (default: the number of cores; 1 runs in this process).
    scheduler : str or dask.distributed.Client, optional
        Dask scheduler address (``"tcp://host:8786"``): run the points on that cluster.
    progress : callable, optional
        ``progress(done, total, row)`` after each point (cached points included).
    overrides : dict or list of str, optional
        Applied to the base scene before sweeping.

    Returns
    -------
    dict
        The summary (``summary.json``): ``scene``, ``parameter``, ``key``, ``values``, ``points``
        (one row per point, see :data:`SUMMARY_COLUMNS`; ``computed`` says whether this run
        computed it), ``computed``, ``reused``, ``failed`` (indices).
    """
    parameter, key, points = sweep_points(scene, parameter, values, overrides=overrides)
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise SceneError(f"workers = {workers!r} is not allowed: it must be an integer >= 1.")
    client = _dask_client(scheduler) if scheduler is not None else None  # fails before any work
    out = Path(out_dir)
    check_output_dir(out, "sweep", SWEEP_NAMES)  # new, empty or a sweep directory
    (out / "points").mkdir(parents=True, exist_ok=True)
    write_marker(out, "sweep")
    rows, jobs = [], []
    for point in points:
        cached = _load_point(out / "points" / point.file, point.fingerprint)
        if cached is not None:
            rows.append(_row(point, cached["result"], computed=False))
            if progress is not None:
                progress(len(rows), len(points), rows[-1])
        else:
            jobs.append(point)
    log.info("sweep of %s over %d values: %d on disk, %d to run", key, len(points), len(rows), len(jobs))
    try:
        if client is not None:
            results = _dask_map(jobs, client[0])
        else:
            results = _local_map(jobs, min(workers or os.cpu_count() or 1, max(len(jobs), 1)))
        for point, result, error in results if jobs else ():
            if error is None:
                atomic_write_json(out / "points" / point.file, {
                    "index": point.index, "parameter": parameter, "key": key, "value": point.value,
                    "fingerprint": point.fingerprint, "scene": point.scene.raw, "result": result})
            else:
                log.warning("sweep point %d (%s = %r) failed:\n%s", point.index, key, point.value, error)
            rows.append(_row(point, result, computed=True, error=error))
            if progress is not None:
                progress(len(rows), len(points), rows[-1])
    finally:
        if client is not None and client[1]:
            client[0].close()
    base = points[0].scene
    meta = {"scene": base.name, "title": base.title, "units": base.units.label,
            "unit_symbols": base.units.as_dict(), "parameter": parameter, "key": key,
            "values": [p.value for p in points]}
    rows = _write_summary(out, meta, rows)
    return dict(meta, points=rows, computed=[r["index"] for r in rows if r["computed"]],
                reused=[r["index"] for r in rows if not r["computed"]],
                failed=[r["index"] for r in rows if r["status"] == "error"])
