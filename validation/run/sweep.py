"""Parameter sweeps of a scene: one scene parameter over a list of values, resumable and extendable.

Every point is a complete scene (the base scene with ``parameter = value``) validated before
any work; a sweep holds at most :data:`~validation.scene.checks.MAX_SWEEP_POINTS` values. Points
run in parallel on local cores (:func:`validation.run.pool.worker_pool`, ``workers`` = cores by
default; the workers end with the sweep) or on a Dask cluster when a scheduler address is given
(:mod:`validation.run.cluster`; ``dask.distributed``, optional, imported only then).

A point is keyed by its scene and the contents of the files that scene names (every key
``file``, e.g. a measured surface's ``gap.file``: the SHA-256 of the file's bytes), its
``fingerprint``; it is saved, once finished, as ``points/point-<fingerprint[:16]>.json``
(atomically) holding the point's full result (``result.json`` content, the axial section
profile included). A sweep folder holds the points of one sweep: one parameter over one base
scene (the scene without the swept key, its files' contents included). A rerun into the same
folder reuses the points already there and computes the others, so an interrupted sweep
resumes where it stopped and a rerun with other values extends the folder; the summary
(``summary.json``, ``summary.csv``) lists every point of the folder, numbers in ascending order.
A folder holding points of another sweep (another parameter, another base scene, a changed
file) is refused before any work: no point is ever overwritten. The folder itself must be new,
empty or a sweep directory contactlab wrote (its marker ``.contactlab``).

The paper's sweeps (section 6): ``alpha_a`` in ``[0, 1]`` (elastic-rigid, Fig. 5/9),
``alpha_c`` (bilinear), ``alpha_b`` (root law, Fig. 10-11).
"""

from __future__ import annotations

import csv
import io
import json
import logging
import os
import re
import traceback
from concurrent.futures import as_completed
from pathlib import Path


from ..io import check_output_dir, json_text, write_marker
from ..scene.checks import SceneError, sweep_size
from ..scene.load import Scene, apply_overrides, load_scene, parse_scene
from ..scene.paper import ALIASES
from ..scene.study import refuse_study
from .cluster import DEFAULT_TIMEOUT, dask_client, scheduler_address
from .pool import worker_pool
from .record import RunResult
from .sweep_folder import (SWEPT, earlier_points, file_digests, fingerprint, keyed, other_point, remove_unfinished,
                           write_file, write_point)

__all__ = ["run_sweep", "sweep_points", "SweepPoint", "SUMMARY_COLUMNS", "parse_values", "SWEEP_NAMES"]

log = logging.getLogger(__name__)

SUMMARY_COLUMNS = ("index", "value", "status", "p_max", "force", "approach", "contact_radius", "contact_area",
                   "converged", "iterations", "kkt_residual", "alpha_b", "p_max_lambda", "wall_time_bem",
                   "wall_time_fem", "computed", "file")
_BARE_WORD = re.compile(r"^[^\s\"'\[\]{}=#,]+(\s+[^\s\"'\[\]{}=#,]+)*$")
#: What a sweep directory holds besides its marker ``.contactlab`` (:func:`validation.io.check_output_dir`).
SWEEP_NAMES = ("points", "summary.json", "summary.csv", "report")


class SweepPoint:
    """One point: its index, value, validated scene, the digests of its files and its file name.

    ``sweep`` is the identity of the sweep it belongs to (shared by its points): the swept
    ``key``, the base ``scene`` (the swept key replaced by a place holder), the digests of the
    base scene's ``files`` and their ``fingerprint``.
    """

    def __init__(self, index, value, scene, *, files=None, sweep=None):
        self.index, self.value, self.scene, self.files, self.sweep = index, value, scene, dict(files or {}), sweep
        self.fingerprint = fingerprint(keyed(scene.raw), self.files)
        self.file = f"point-{self.fingerprint[:16]}.json"


def _number(text):
    try:
        float(text)
    except ValueError:
        return False
    return True


def _item(text, item):
    """One comma-separated item of ``--values``: a TOML value, else a bare word (a string)."""
    import tomllib

    item = item.strip()
    try:
        return tomllib.loads(f"v = {item}")["v"]
    except tomllib.TOMLDecodeError:
        pass
    if not _BARE_WORD.match(item):
        raise SceneError(f"--values {text!r} is not allowed: the item {item!r} is neither a TOML value nor a "
                         "bare word; give comma-separated numbers or words (0,0.25,0.5 or none,tabulated) or "
                         "start:stop:num (0:1:5).")
    return item


def parse_values(text):
    """The values of ``--values``: a comma list or ``"start:stop:num"``; returns a list.

    Items of a comma list are TOML values (``0.25``, ``"log"``, ``[1e-3, 2e-3]``) or bare words,
    taken as strings (``none,tabulated``, ``mymodule:w``); ``start:stop:num`` gives ``num``
    evenly spaced numbers. At most :data:`~validation.scene.checks.MAX_SWEEP_POINTS` values,
    refused before any is made.
    """
    import tomllib

    import numpy as np

    text = text.strip()
    parts = text.split(":")
    if "," not in text and (len(parts) == 3 or (len(parts) == 2 and _number(parts[0]))):
        try:
            start, stop, num = float(parts[0]), float(parts[1]), int(parts[2])
        except (ValueError, IndexError):
            raise SceneError(f"--values {text!r} is not allowed: start:stop:num needs two numbers and an "
                             "integer, e.g. 0:1:5.") from None
        if num < 1:
            raise SceneError(f"--values {text!r} is not allowed: num must be >= 1.")
        sweep_size("--values", text, num)
        return [float(v) for v in np.linspace(start, stop, num)]
    try:
        values = tomllib.loads(f"v = [{text}]")["v"]
    except tomllib.TOMLDecodeError:
        values = None
    if values is None:
        items = text.split(",")
        sweep_size("--values", text, len(items))
        values = [_item(text, item) for item in items]
    if not values:
        raise SceneError(f"--values {text!r} is not allowed: it must hold at least one value.")
    sweep_size("--values", text, len(values))
    return values


def _typed(raw, key, value):
    """``value`` in the type of the base scene's value at ``key``: an integer for a float key is a
    float, an integral float for an integer key an integer (``--values 50,100``, ``16:32:3``)."""
    node = raw
    for part in key.split("."):
        node = node.get(part) if isinstance(node, dict) else None
    if isinstance(node, bool) or isinstance(value, bool):
        return value
    if isinstance(node, float) and isinstance(value, int):
        return float(value)
    if isinstance(node, int) and isinstance(value, float) and value.is_integer():
        return int(value)
    return value


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
        The values (numbers or strings, each typed as the base scene's value of the key);
        default: the scene's ``[sweep] values``.
    overrides : dict or list of str, optional
        Applied to the base scene first.
    """
    base = scene if isinstance(scene, Scene) and not overrides else load_scene(scene, overrides=overrides)
    refuse_study(base, "a sweep")
    if parameter is None and values is None and base.sweep is not None:
        parameter, values = base.sweep["parameter"], base.sweep["values"]
    if parameter is None or values is None:
        raise SceneError(f"sweep parameter = {parameter!r}, values = {values!r} is not allowed: give both "
                         "(--param and --values), or neither to use the scene's [sweep] section.")
    raw = {k: v for k, v in base.raw.items() if k != "sweep"}
    if isinstance(parameter, str) and isinstance(values, list | tuple):
        values = [_typed(raw, ALIASES.get(parameter, parameter), v) for v in values]
    raw["sweep"] = {"parameter": parameter, "values": list(values)}
    checked = parse_scene(raw, source=base.source, **base.trust)  # checks the parameter and every value
    key = checked.sweep["key"]
    raw.pop("sweep")
    cache = {}
    held = apply_overrides(raw, {key: SWEPT})
    files = file_digests(held, cache)
    sweep = {"key": key, "scene": keyed(held), "files": files}
    sweep["fingerprint"] = fingerprint(key, sweep["scene"], files)
    points = []
    for i, value in enumerate(checked.sweep["values"]):
        point = parse_scene(apply_overrides(raw, {key: value}), source=base.source, **base.trust)
        points.append(SweepPoint(i, value, point, files=file_digests(point.raw, cache), sweep=sweep))
    return parameter, key, points


def _solve_point(raw, source, trust):
    """Worker: run one point's scene (BEM, and FEM/analytic when named) and return its result;
    ``trust`` is :attr:`Scene.trust` of the point."""
    from .runner import run_scene

    return run_scene(parse_scene(raw, source=source, **trust)).to_json()


def _ordered(values):
    """Summary positions of ``values``: ascending when all are numbers, else in the given order."""
    numeric = all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)
    order = sorted(range(len(values)), key=lambda i: values[i]) if numeric else range(len(values))
    return {i: pos for pos, i in enumerate(order)}


def point_status(result):
    """The status of a sweep point's :class:`~validation.run.record.RunResult`: ``"converged"`` when
    every part that ran converged, else the status of the first that did not (the BEM's, then the
    FEM's; :data:`bem.STATUSES`, :data:`fem_reference.STATUSES`). A point that raised is ``"error"``."""
    if result.converged:
        return "converged"
    return result.bem.status if not result.bem.converged else result.fem.status


def _row(index, value, file, result, *, computed, error=None):
    row = {"index": index, "value": value, "computed": computed, "file": f"points/{file}"}
    if error is not None:
        row.update(status="error", error=error, file=None)
        return row
    result = RunResult.from_json(result, source=row["file"])
    wall = result.wall_time_s_by_part
    row.update(
        status=point_status(result),
        p_max=result.p_max, force=result.force, approach=result.approach,
        contact_radius=result.contact_radius, contact_area=result.contact_area,
        converged=result.converged, iterations=result.iterations, kkt_residual=result.kkt_residual,
        alpha_b=result.alpha_b, p_max_lambda=result.layer.get("p_max_lambda"),
        wall_time_bem=wall["bem"], wall_time_fem=wall["fem"])
    return row


def _local_map(jobs, workers):
    """Yield ``(point, result, error)`` as local jobs finish (in-process when workers == 1)."""
    if workers == 1 or len(jobs) == 1:
        for point in jobs:
            try:
                yield point, _solve_point(point.scene.raw, point.scene.source, point.scene.trust), None
            except Exception:  # noqa: BLE001 - a failed point is reported, the sweep goes on
                yield point, None, traceback.format_exc(limit=3)
        return
    with worker_pool(workers) as pool:  # its workers end with this process
        futures = {pool.submit(_solve_point, p.scene.raw, p.scene.source, p.scene.trust): p for p in jobs}
        try:
            for fut in as_completed(futures):
                exc = fut.exception()
                error = None if exc is None else "".join(traceback.format_exception(exc, limit=3))
                yield futures[fut], None if exc else fut.result(), error
        except BaseException:
            for fut in futures:
                fut.cancel()
            raise


def _dask_map(jobs, client):
    """Yield ``(point, result, error)`` as Dask futures finish on ``client``."""
    from dask.distributed import as_completed as dask_completed

    futures = {client.submit(_solve_point, p.scene.raw, p.scene.source, p.scene.trust, pure=False): p for p in jobs}
    for fut in dask_completed(list(futures)):
        point = futures[fut]
        if fut.status == "error":
            yield point, None, "".join(traceback.format_exception(fut.exception(), limit=3))
        else:
            yield point, fut.result(), None


def _write_summary(out, meta, rows):
    rows = sorted(rows, key=lambda r: r["index"])
    write_file(out / "summary.json", json_text(dict(meta, points=rows)))
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=SUMMARY_COLUMNS, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: "" if row.get(k) is None else row.get(k) for k in SUMMARY_COLUMNS})
    write_file(out / "summary.csv", buf.getvalue())
    return rows


def run_sweep(scene, out_dir, *, parameter=None, values=None, workers=None, scheduler=None,
              scheduler_timeout=DEFAULT_TIMEOUT, progress=None, overrides=None):
    """Run a resumable, extendable sweep and write its point files and summary table.

    Parameters
    ----------
    scene : Scene, str, path-like or dict
        The base scene.
    out_dir : path-like
        Sweep directory: ``points/point-<fingerprint>.json``, ``summary.json``, ``summary.csv``
        and the marker ``.contactlab``; it must be new, empty or a sweep directory (a directory
        holding anything else is refused: :class:`validation.io.OutputError`). Points already
        there are reused; a folder holding points of another sweep is refused.
    parameter, values : optional
        See :func:`sweep_points` (default: the scene's ``[sweep]``).
    workers : int, optional
        Local worker processes (default: the number of cores; 1 runs in this process).
    scheduler : str or dask.distributed.Client, optional
        Dask scheduler address (``"tcp://host:8786"`` or ``"host:8786"``): run the points on
        that cluster (:func:`validation.run.cluster.dask_client`).
    scheduler_timeout : float, optional
        Seconds allowed to reach the scheduler, > 0.
    progress : callable, optional
        ``progress(label, done, total)`` (:mod:`validation.progress`) after each point of ``values``
        (reused points included); ``label`` is ``"KEY = VALUE: STATUS"`` of that point.
    overrides : dict or list of str, optional
        Applied to the base scene before sweeping.

    Returns
    -------
    dict
        The summary (``summary.json``): ``scene``, ``parameter``, ``key``, ``values`` (every value
        of the folder), ``points`` (one row per value, see :data:`SUMMARY_COLUMNS`; ``computed``
        says whether this run computed it), and the indices ``computed``, ``reused`` (values of
        this run found in the folder), ``kept`` (values of earlier runs only) and ``failed``.

    Raises
    ------
    SceneError
        A bad scene, parameter or value (every point is checked first).
    validation.io.OutputError
        ``out_dir`` holds points of another sweep.
    validation.run.cluster.SchedulerError
        ``scheduler`` is malformed, cannot be reached or is not a Dask scheduler.
    """
    parameter, key, points = sweep_points(scene, parameter, values, overrides=overrides)
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise SceneError(f"workers = {workers!r} is not allowed: it must be an integer >= 1.")
    if isinstance(scheduler, str):
        scheduler_address(scheduler)
    out = Path(out_dir)
    check_output_dir(out, "sweep", SWEEP_NAMES)  # new, empty or a sweep directory
    remove_unfinished(out)
    earlier = earlier_points(out, points[0].sweep)
    mine = {p.fingerprint for p in points}
    kept = [d for fp, d in earlier.items() if fp not in mine]
    by_value = {json.dumps(p.value): p for p in points}
    for data in kept:
        if json.dumps(data["value"]) in by_value:
            other_point(out, data, by_value[json.dumps(data["value"])])
    client = dask_client(scheduler, scheduler_timeout) if scheduler is not None else None  # before any work
    position = _ordered([p.value for p in points] + [d["value"] for d in kept])
    for i, point in enumerate(points):
        point.index = position[i]
    rows = [_row(position[len(points) + i], d["value"], d["file"], d["result"], computed=False)
            for i, d in enumerate(kept)]
    (out / "points").mkdir(parents=True, exist_ok=True)
    write_marker(out, "sweep")
    jobs, done = [], 0
    for point in points:
        cached = earlier.get(point.fingerprint)
        if cached is not None:
            rows.append(_row(point.index, point.value, cached["file"], cached["result"], computed=False))
            done += 1
            if progress is not None:
                progress(f"{key} = {rows[-1]['value']}: {rows[-1]['status']}", done, len(points))
        else:
            jobs.append(point)
    log.info("sweep of %s over %d values: %d on disk, %d to run, %d more from earlier runs", key, len(points),
             len(points) - len(jobs), len(jobs), len(kept))
    try:
        if client is not None:
            results = _dask_map(jobs, client[0])
        else:
            results = _local_map(jobs, min(workers or os.cpu_count() or 1, max(len(jobs), 1)))
        for point, result, error in results if jobs else ():
            if error is None:
                write_point(out / "points" / point.file, {
                    "parameter": parameter, "key": key, "value": point.value, "fingerprint": point.fingerprint,
                    "files": point.files, "sweep": point.sweep, "scene": point.scene.raw, "result": result})
            else:
                log.warning("sweep point %s = %r failed:\n%s", key, point.value, error)
            rows.append(_row(point.index, point.value, point.file, result, computed=True, error=error))
            done += 1
            if progress is not None:
                progress(f"{key} = {rows[-1]['value']}: {rows[-1]['status']}", done, len(points))
    finally:
        if client is not None and client[1]:
            client[0].close()
    base = points[0].scene
    meta = {"scene": base.name, "title": base.title, "units": base.units.label,
            "unit_symbols": base.units.as_dict(), "parameter": parameter, "key": key}
    rows = _write_summary(out, dict(meta, values=[r["value"] for r in sorted(rows, key=lambda r: r["index"])]),
                          rows)
    fresh = {p.index for p in points}
    return dict(meta, values=[r["value"] for r in rows], points=rows,
                computed=[r["index"] for r in rows if r["computed"]],
                reused=[r["index"] for r in rows if not r["computed"] and r["index"] in fresh],
                kept=[r["index"] for r in rows if r["index"] not in fresh],
                failed=[r["index"] for r in rows if r["status"] == "error"])
