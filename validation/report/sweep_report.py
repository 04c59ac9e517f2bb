"""Report of a sweep directory written by ``contactlab sweep`` (:func:`validation.run.sweep.run_sweep`).

Reads ``summary.json`` (the table of points) and ``points/point-NNN.json`` (each point's scene
and full result, the axial section included) and builds: the problem statement of the first
point, a table of every point, the axial-section pressure of every point coloured by the swept
value, and the peak pressure, contact size and approach against that value. Units as in a run's
report (:mod:`validation.report.run_figures`): the scene's (mm and MPa for SI scenes) or
dimensionless (each point divided by its own scales).
"""

from __future__ import annotations

import json
import logging
import math
from pathlib import Path

import numpy as np

from bem.checks import InputError, check_choice

from .build import Progress, draw_and_build
from .results import UNIT_CHOICES, RunResults, parse_units, report_unit
from .run_figures import PAD, contact_edge, scales_of
from .run_problem import problem_statement
from .sections import Figure, Section, Table, fmt

__all__ = ["is_sweep_dir", "load_sweep", "sweep_sections", "report_sweep_dir", "SWEEP_FILES"]

log = logging.getLogger(__name__)

#: what marks a sweep directory
SWEEP_FILES = ("summary.json", "points")


def is_sweep_dir(directory):
    """True when ``directory`` holds a sweep's ``summary.json`` and ``points/``."""
    d = Path(directory)
    return (d / "summary.json").is_file() and (d / "points").is_dir()


def _read(path):
    try:
        return json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise InputError(f"{path} is not allowed: it must be a readable JSON file ({exc}).") from None


def load_sweep(directory, *, units="auto"):
    """The summary of a sweep directory and a :class:`RunResults` per computed point.

    Returns
    -------
    summary : dict
        ``summary.json``.
    points : list of (row, RunResults or None)
        One per row of the summary, in order; ``None`` for a point without a result file.
    """
    directory = Path(directory)
    if not is_sweep_dir(directory):
        raise InputError(f"directory = {str(directory)!r} is not allowed: it must be a sweep directory "
                         "(summary.json and points/, written by contactlab sweep).")
    units = check_choice("units", units, UNIT_CHOICES)
    summary = _read(directory / "summary.json")
    if not isinstance(summary, dict) or not isinstance(summary.get("points"), list):
        raise InputError(f"{directory / 'summary.json'} is not allowed: it must hold the points of a sweep.")
    label = parse_units(summary.get("units"))
    points = []
    for row in summary["points"]:
        res = None
        if row.get("file") and (directory / row["file"]).is_file():
            point = _read(directory / row["file"])
            res = RunResults(directory=directory, data=dict(point.get("result") or {}),
                             scene=dict(point.get("scene") or {}), units=label,
                             dimensionless=units == "dimensionless" or (units == "auto" and not label.known))
        points.append((row, res))
    return summary, points


def _numeric(values):
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def _table(summary, points):
    u = next((res.units for _, res in points if res is not None), parse_units(summary.get("units")))
    columns = (str(summary.get("key", "value")), "status", f"p_max [{u.of('pressure')}]",
               f"contact radius or half-width x [{u.of('length')}]", f"approach [{u.of('length')}]",
               "iterations", "KKT residual", "BEM time [s]")
    rows = []
    for row, res in points:
        radius = row.get("contact_radius")
        if radius is None and res is not None:
            radius = (res.get("contact_extent") or {}).get("x")
        rows.append((fmt(row.get("value")), row.get("status", "?"), row.get("p_max"), radius, row.get("approach"),
                     row.get("iterations"), row.get("kkt_residual"), row.get("wall_time_bem")))
    return Table(columns, tuple(rows), status_column="status",
                 caption=f"Every point of the sweep of {summary.get('key')} (summary.json); contact radius "
                         "sqrt(A / pi) for axisymmetric scenes, else the farthest loaded node along x.")


def _view(res):
    """``(x_factor, p_factor, x_label, p_label)`` of one point."""
    scales = scales_of(res)
    if scales is not None:
        p0, a, p_name, a_name = scales
        return a, p0, rf"$x\,/\,{a_name}$", rf"contact pressure $p\,/\,{p_name}$"
    (xu, xf), (pu, pf) = report_unit(res.units.length), report_unit(res.units.pressure)
    return xf, pf, "$x$" + (f" [{xu}]" if xu else ""), "contact pressure $p$" + (f" [{pu}]" if pu else "")


#: unit kind of the swept scene keys (their last part); the others are dimensionless
_KEY_KINDS = {"force": "force", "approach": "length", "R": "length", "Rx": "length", "Ry": "length",
              "length": "length", "a": "length", "edge_radius": "length", "crown_radius": "length",
              "step": "length", "extent": "length", "E1": "pressure", "E2": "pressure", "E_star": "pressure",
              "p_cr": "pressure", "p_star": "pressure", "lam": "compliance", "lam1": "compliance",
              "lam2": "compliance"}


def _key_label(key, units):
    """Axis label of a swept key with its unit in the scene's units (``load.force [N]``)."""
    kind = _KEY_KINDS.get(key.rsplit(".", 1)[-1])
    unit = units.of(kind) if kind else "-"
    return key if unit == "-" else f"{key} [{unit}]"


def _figures(summary, points, work):
    from .figures_sweeps import plot_sweep, plot_sweep_scalars

    done = [(row, res) for row, res in points if res is not None and (res.get("profile") or {}).get("x")]
    if not done:
        return []
    values = [row["value"] for row, _ in done]
    numeric = _numeric(values)
    alpha = [float(v) for v in values] if numeric else list(range(len(values)))
    ticks = None if numeric else [str(v) for v in values]
    key = str(summary.get("key", "value"))
    xf, pf, x_label, p_label = _view(done[0][1])
    curves = []
    for a_i, (_, res) in zip(alpha, done):
        fx, fp, _, _ = _view(res)
        prof = res.get("profile")
        curves.append((a_i, np.asarray(prof["x"], float) * xf / fx, np.asarray(prof["p"], float) * pf / fp))
    u = done[0][1].units
    name = _key_label(key, u)
    edge = contact_edge([(x / xf, p) for _, x, p in curves])
    path = plot_sweep(curves, work / "sweep_profiles.png", p0=pf, a=xf, name=name, ticklabels=ticks,
                      labels={"x": x_label, "p": p_label}, cmap="viridis", xlim=(-PAD * edge, PAD * edge),
                      title=f"contact pressure on the axial section as {key} varies")
    (lu, lf), (pu, pfac) = report_unit(u.length), report_unit(u.pressure)

    def series(get, factor):
        return np.array([get(res) / factor if get(res) is not None else math.nan for _, res in done])

    radius = (lambda r: r.data.get("contact_radius") or (r.get("contact_extent") or {}).get("x"))
    scalars = [(f"$p_{{max}}$ [{pu}]" if pu else "$p_{max}$", series(lambda r: r.data.get("p_max"), pfac)),
               (f"contact size [{lu}]" if lu else "contact size", series(radius, lf)),
               (f"approach [{lu}]" if lu else "approach", series(lambda r: r.data.get("approach"), lf))]
    path2 = plot_sweep_scalars(alpha, scalars, work / "sweep_scalars.png", name=name, ticklabels=ticks,
                               title=f"results against {key}")
    how = (f"{len(done)} computed points of {len(points)}; BEM method {done[0][1].data.get('method', '?')}, "
           "each point a complete run of the scene with the swept key set (points/point-NNN.json).")
    return [Figure(path, "Contact pressure on the axial section y = 0 of every computed point, coloured by "
                         f"{key}. " + ("Each point divided by its own scales. " if scales_of(done[0][1]) else "")
                   + how),
            Figure(path2, f"Peak pressure, contact size (radius sqrt(A / pi) of an axisymmetric contact, else the "
                          f"half-width along x) and approach against {key}, in the scene's units. " + how)]


def sweep_sections(summary, points, work):
    """The report sections of a loaded sweep (:func:`load_sweep`); figures go to ``work``."""
    work = Path(work)
    first = next((res for _, res in points if res is not None), None)
    sections = []
    if first is not None:
        problem = problem_statement(first, work)
        text = problem.text + (f"The sweep sets {summary.get('key')} to each of the values "
                               f"{', '.join(fmt(v) for v in summary.get('values', []))}; the table above is the "
                               "first point's scene.",)
        sections.append(Section(problem.title, kind="problem", text=text, items=problem.items))
    failed = [str(row.get("value")) for row, _ in points if row.get("status") == "error"]
    text = [f"Sweep of {summary.get('key')} over {len(points)} values of scene '{summary.get('scene')}' "
            f"[units {summary.get('units')}]."]
    if failed:
        text.append(f"Points that failed (no result): {', '.join(failed)}.")
    items = [_table(summary, points), *_figures(summary, points, work)]
    sections.append(Section("Sweep results", kind="sweeps", text=tuple(text), items=tuple(items)))
    return sections


def report_sweep_dir(directory, out_dir=None, *, units="auto", fmt="png", progress=None):
    """Report of a sweep directory (default ``out_dir``: ``directory/report``).

    ``directory`` was written by ``contactlab sweep`` (``summary.json``, ``points/``);
    ``units``, ``fmt`` and ``progress`` are those of
    :func:`validation.report.run_report.report_results_dir`. Returns the
    :class:`validation.report.build.BuiltReport`.
    """
    from .run_report import STAGES

    notify = Progress(STAGES, progress)
    notify("reading")
    summary, points = load_sweep(directory, units=units)
    out_dir = Path(directory) / "report" if out_dir is None else Path(out_dir)
    title = f"{summary.get('title') or summary.get('scene')}: sweep of {summary.get('key')}"
    return draw_and_build(lambda work: sweep_sections(summary, points, work), out_dir, title=title,
                          subtitle=f"Sweep read from {Path(directory).resolve()}", fmt=fmt, notify=notify)
