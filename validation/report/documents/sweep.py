"""Report of a sweep directory written by ``contactlab sweep`` (:func:`validation.run.sweep.run_sweep`).

Reads ``summary.json`` (the table of points) and ``points/point-*.json`` (each point's scene
and full result, the axial section included) and builds: the problem statement of the first
point, the layer law ``w(p)`` of a layered scene (every point's when the sweep changes it), a
table of every point, the axial-section pressure of every point coloured by the swept value, and
the peak pressure, contact size and approach against that value. Units as in a run's
report (:meth:`validation.report.documents.results.RunResults.display`): readable ones (mm and
MPa for SI scenes) or the scene's, one per quantity in every table and figure; a dimensionless
report divides each point's profile by its own scales and shows the table, the swept values and
the scalar figure in readable units (the scales differ from point to point).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import NamedTuple

import numpy as np

from bem.checks import InputError, check_choice

from ...provenance import display_path
from ...run.record import RunResult
from ...units import Units
from ..figures.run import PAD, axis_label, contact_edge, scale
from ..render import Figure, Progress, Section, Table, draw_and_build, fmt
from .problem import scene_section
from .results import UNIT_CHOICES, RunResults, dimensionless_for, file_inside, is_number, read_json, units_of

__all__ = ["Sweep", "is_sweep_dir", "load_sweep", "sweep_section", "sweep_sections", "report_sweep_dir"]

#: unit kind of the swept scene keys (their last part); the others are dimensionless
_KEY_KINDS = {"force": "force", "approach": "length", "R": "length", "Rx": "length", "Ry": "length",
              "length": "length", "a": "length", "edge_radius": "length", "crown_radius": "length",
              "step": "length", "extent": "length", "E1": "pressure", "E2": "pressure", "E_star": "pressure",
              "p_cr": "pressure", "p_star": "pressure", "lam": "compliance", "lam1": "compliance",
              "lam2": "compliance", "thickness": "length", "E": "pressure"}


class Sweep(NamedTuple):
    """A loaded sweep: ``summary.json`` and ``(row, RunResults or None)`` per point, in order
    (``None``: a point without a result file)."""

    summary: dict
    points: list


def is_sweep_dir(directory):
    """True when ``directory`` holds a sweep's ``summary.json`` and ``points/``."""
    d = Path(directory)
    return (d / "summary.json").is_file() and (d / "points").is_dir()


def load_sweep(directory, *, units="auto"):
    """The :class:`Sweep` of a sweep directory.

    ``units``: as for :func:`validation.report.documents.results.load_results`.
    """
    directory = Path(directory)
    if not is_sweep_dir(directory):
        raise InputError(f"directory = {str(directory)!r} is not allowed: it must be a sweep directory "
                         "(summary.json and points/, written by contactlab sweep).")
    units = check_choice("units", units, UNIT_CHOICES)
    summary = read_json(directory / "summary.json")
    if not isinstance(summary, dict) or not isinstance(summary.get("points"), list):
        raise InputError(f"{directory / 'summary.json'} is not allowed: it must hold the points of a sweep.")
    points = []
    for i, row in enumerate(summary["points"]):
        res = None
        path = file_inside(directory, row["file"], f"points[{i}].file") if row.get("file") else None
        if path is not None and path.is_file():
            point = read_json(path)
            result = RunResult.from_json(point["result"], source=str(path))
            u = units_of(result)
            res = RunResults(directory=directory, result=result, scene=dict(point.get("scene") or {}), units=u,
                             dimensionless=dimensionless_for(units, u), scene_units=units == "scene")
        points.append((row, res))
    return Sweep(summary, points)


def _units(summary, points):
    """The first computed point's results (their units), or results holding only the summary's units."""
    return next((res for _, res in points if res is not None),
                RunResults(directory=Path("."), result=None,
                           units=Units.from_dict(summary.get("units"), summary.get("unit_symbols"))))


def _table(summary, points):
    first = _units(summary, points)
    (lf, lu), (pf, pu) = first.engineering("length"), first.engineering("pressure")
    vf, key = _key_unit(str(summary.get("key", "value")), first)
    columns = (key, "status", f"p_max [{pu or '-'}]", f"contact radius or half-width x [{lu or '-'}]",
               f"approach [{lu or '-'}]", "iterations", "KKT residual", "BEM time [s]")

    def shown(value, factor):
        return value / factor if is_number(value) else value

    rows = []
    for row, res in points:
        radius = row.get("contact_radius")
        if radius is None and res is not None:
            radius = res.contact_size
        rows.append((fmt(shown(row.get("value"), vf)), row.get("status", "?"), shown(row.get("p_max"), pf),
                     shown(radius, lf), shown(row.get("approach"), lf), row.get("iterations"),
                     row.get("kkt_residual"), row.get("wall_time_bem")))
    return Table(columns, tuple(rows), status_column="status",
                 caption=f"Every point of the sweep of {summary.get('key')} (summary.json); contact radius "
                         "sqrt(A / pi) for axisymmetric scenes, else the farthest loaded node along x.")


def _key_unit(key, res):
    """``(factor, label)``: the swept values of ``key`` are shown as ``value / factor`` in the readable
    units of ``res`` (:meth:`RunResults.engineering`), labelled ``load.force [N]``."""
    kind = _KEY_KINDS.get(key.rsplit(".", 1)[-1])
    if kind == "compliance":
        power = {"root": 0.5, "power": float((res.section("layer") or {}).get("s", 1.0))}.get(
            res.law, 1.0)
        (lf, lu), (pf, pu) = res.engineering("length"), res.engineering("pressure")
        factor, unit = lf / pf**power, f"{lu}/{pu}" + ("" if power == 1.0 else f"^{power:g}") if lu and pu else ""
    else:
        factor, unit = res.engineering(kind) if kind else (1.0, "")
    return factor, (f"{key} [{unit}]" if unit else key)


def _figures(summary, points, work):
    from ..figures.periodic import sweep_curves
    from ..figures.sweeps import plot_sweep, plot_sweep_scalars

    if any(res is not None and res.result.periodic is not None for _, res in points):  # a rough surface's cell
        return sweep_curves(points, work, str(summary.get("key", "value")))
    done = [(row, res) for row, res in points if res is not None and res.result.profile is not None
            and res.result.profile.x]
    if not done:
        return []
    values = [row["value"] for row, _ in done]
    numeric = all(is_number(v) for v in values)
    vf, name = _key_unit(str(summary.get("key", "value")), done[0][1])
    alpha = [float(v) / vf for v in values] if numeric else list(range(len(values)))
    ticks = None if numeric else [str(v) for v in values]
    key, first = str(summary.get("key", "value")), done[0][1]
    x_scale, p_scale = scale(first, "length"), scale(first, "pressure")
    xf, pf = x_scale[0], p_scale[0]
    # each point divided by its own scales, drawn with the first's
    curves = [(a_i, np.asarray(res.result.profile.x, float) * xf / scale(res, "length")[0],
               np.asarray(res.result.profile.p, float) * pf / scale(res, "pressure")[0])
              for a_i, (_, res) in zip(alpha, done)]
    edge = contact_edge([(x / xf, p) for _, x, p in curves])
    path = plot_sweep(curves, work / "sweep_profiles.png", p0=pf, a=xf, name=name, ticklabels=ticks,
                      labels={"x": axis_label("x", x_scale), "p": axis_label("p", p_scale, "contact pressure ")},
                      cmap="viridis", xlim=(-PAD * edge, PAD * edge),
                      title=f"contact pressure on the axial section as {key} varies")
    (lf, lu), (pfac, pu) = first.engineering("length"), first.engineering("pressure")

    def series(get, factor):
        return np.array([get(res) / factor if get(res) is not None else math.nan for _, res in done])

    scalars = [(f"$p_{{max}}$ [{pu}]" if pu else "$p_{max}$", series(lambda r: r.result.p_max, pfac)),
               (f"contact size [{lu}]" if lu else "contact size", series(lambda r: r.contact_size, lf)),
               (f"approach [{lu}]" if lu else "approach", series(lambda r: r.result.approach, lf))]
    path2 = plot_sweep_scalars(alpha, scalars, work / "sweep_scalars.png", name=name, ticklabels=ticks,
                               title=f"results against {key}")
    how = (f"{len(done)} computed points of {len(points)}; BEM method {first.result.method}, "
           "each point a complete run of the scene with the swept key set (points/point-*.json).")
    return [Figure(path, "Contact pressure on the axial section y = 0 of every computed point, coloured by "
                         f"{key}. " + ("Each point divided by its own scales. " if first.scales() else "") + how),
            Figure(path2, f"Peak pressure, contact size (radius sqrt(A / pi) of an axisymmetric contact, else the "
                          f"half-width along x) and approach against {key}"
                          + (f", in {lu} and {pu}. " if lu and pu else ". ") + how)]


def sweep_section(sweep, work):
    """The section "Sweep results" of a :class:`Sweep` (``None`` for other results)."""
    if not isinstance(sweep, Sweep):
        return None
    summary, points = sweep
    failed = [str(row.get("value")) for row, _ in points if row.get("status") == "error"]
    text = [f"Sweep of {summary.get('key')} over {len(points)} values of scene '{summary.get('scene')}' "
            f"[units {summary.get('units')}]: {', '.join(fmt(v) for v in summary.get('values', []))}; the problem "
            "statement is the first point's scene."]
    if failed:
        text.append(f"Points that failed (no result): {', '.join(failed)}.")
    return Section("Sweep results", kind="sweeps", text=tuple(text),
                   items=(_table(summary, points), *_figures(summary, points, Path(work))))


def _layer_section(summary, points, work):
    """The section "Interface layer law" of a layered sweep: the first computed point's law ``w(p)``
    as in a run's report, or, when the points' laws differ (a swept layer key), every point's law."""
    from ..figures.profiles import plot_layer_laws
    from ..figures.run import Scaled, layer_law

    done = [(row, res) for row, res in points if res is not None and res.layer is not None]
    if not done:
        return None
    laws = {repr(res.layer.to_dict()): (row, res) for row, res in done}
    if len(laws) == 1:
        figure = layer_law(done[0][1], work)
    else:  # readable units, the same for every point
        first, key = done[0][1], str(summary.get("key", "value"))
        (pf, pu), (lf, lu), (vf, _) = first.engineering("pressure"), first.engineering("length"), _key_unit(key, first)
        top = 1.25 * max(float(v or 0.0) for _, res in laws.values()  # as the run's figure: peaks and kinks
                         for v in (res.result.p_max, *map(res.layer.to_dict().get, ("p_cr", "p_star"))))
        drawn = [(f"{key} = {fmt(row['value'] / vf if is_number(row['value']) else row['value'])}",
                  Scaled(res.layer, pf, lf)) for row, res in laws.values()]
        for _, law in drawn:
            law.law = None  # coloured by point, not by the law's name (one name for all)
        path = plot_layer_laws(drawn, work / "sweep_layer_laws.png", p_max=top / pf, p_unit=pu, w_unit=lu,
                               title=f"interface layer law w(p) as {key} varies")
        figure = Figure(path, f"The layer law w(p) of each computed point ({len(laws)} laws), rebuilt from the "
                              "points' results with bem.layers.from_dict, from 0 to 1.25 times the largest peak "
                              "pressure or kink pressure of the points.")
    return Section("Interface layer law", kind="problem", items=(figure,)) if figure is not None else None


def sweep_sections(summary, points, work):
    """The report sections of a loaded sweep: the first point's problem statement, the layer law(s) w(p)
    of a layered scene, and the sweep."""
    first = next((res for _, res in points if res is not None), None)
    layer = _layer_section(summary, points, Path(work))
    return (([scene_section(first, work)] if first is not None else []) + ([layer] if layer is not None else [])
            + [sweep_section(Sweep(summary, points), work)])


def report_sweep_dir(directory, out_dir=None, *, units="auto", fmt="png", progress=None):
    """Report of a sweep directory (default ``out_dir``: ``directory/report``).

    ``directory`` was written by ``contactlab sweep`` (``summary.json``, ``points/``);
    ``units``, ``fmt`` and ``progress`` are those of
    :func:`validation.report.documents.sections.report_results_dir`. Returns the
    :class:`validation.report.render.BuiltReport`.
    """
    from .sections import STAGES

    notify = Progress(STAGES, progress)
    notify("reading")
    summary, points = load_sweep(directory, units=units)
    title = f"{summary.get('title') or summary.get('scene')}: sweep of {summary.get('key')}"
    return draw_and_build(lambda work: sweep_sections(summary, points, work),
                          Path(directory) / "report" if out_dir is None else out_dir, title=title,
                          subtitle=f"Sweep read from {display_path(directory)}", fmt=fmt, notify=notify)
