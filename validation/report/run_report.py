"""The report of a result directory written by ``contactlab run`` (:func:`validation.run.runner.run_scene`).

Only the sections the results support: the problem statement (from ``scene.toml``), the
results table, the pressure profiles against the FEM and the closed form when they ran,
the contact map, the convergence history, the FEM reference only when the FEM ran, the
subsurface stresses only when the scene asked for them and the comparison metrics only when
they were recorded. Units are the scene's (``[scene] units``).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from pathlib import Path

from ..provenance import display_path
from . import run_figures as rf
from .build import Progress, draw_and_build
from .run_problem import method_text, problem_statement, rebuild_layer
from .run_stress import stress_section
from .sections import Section, Table, fmt

__all__ = ["run_sections", "report_results_dir", "results_rows", "comparison_tables", "STAGES"]

log = logging.getLogger(__name__)

#: the stages of :func:`report_results_dir`, as reported to its ``progress``
STAGES = ("reading", "figures", "writing")

#: rows of the results table: (key in result.json / fem / analytic, label, unit kind)
_QUANTITIES = (("p_max", "peak pressure p_max", "pressure"),
               ("force", "total force P", "force"),
               ("approach", "approach delta", "length"),
               ("contact_area", "contact area A", "area"),
               ("contact_radius", "contact radius r_c", "length"))
#: ratio rows: (key, label, key in result["scales"])
_RATIOS = (("p_max", "p_max / p_H (Hertz peak)", "p_hertz"), ("contact_radius", "r_c / a_H (Hertz radius)", "a_hertz"),
           ("approach", "delta / delta_H (Hertz approach)", "approach_hertz"))
_FEM_TIMES = (("mesh", "mesh generation"), ("assembly", "assembly"), ("factorize", "factorisation"),
              ("compliance", "contact-node compliance"), ("newton", "contact iterations"),
              ("recover", "stress recovery"), ("total", "total"))


def _num(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def results_rows(res):
    """``(columns, rows)`` of the results table: one column per solver that ran, then the unit.

    Every cell is a formatted scalar (:func:`validation.report.sections.fmt`) or ``"-"``.
    """
    parts = [("BEM", res.data)]
    if res.fem is not None:
        parts.append(("FEM", res.fem))
    if res.get("analytic"):
        parts.append(("closed form", res.get("analytic")))
    rows = []
    for key, label, kind in _QUANTITIES:
        cells = [part.get(key) for _, part in parts]
        if any(_num(c) for c in cells):
            rows.append((label, *(fmt(c) if _num(c) else "-" for c in cells), res.units.of(kind)))
    ext = res.get("contact_extent")
    if ext and not res.axisymmetric:
        cells = {"closed form": "{}, {}".format(*map(fmt, (ref.get("a"), ref.get("b"))))
                 for ref in [res.get("analytic") or {}] if _num(ref.get("a")) and _num(ref.get("b"))}
        rows.append(("contact half-widths along x, y", f"{fmt(ext.get('x'))}, {fmt(ext.get('y'))}",
                     *(cells.get(name, "-") for name, _ in parts[1:]), res.units.of("length")))
    scales = res.get("scales")
    if scales:
        for key, label, skey in _RATIOS:
            if _num(scales.get(skey)) and scales[skey] > 0:
                cells = [part.get(key) for _, part in parts]
                rows.append((label, *(fmt(c / scales[skey]) if _num(c) else "-" for c in cells), "-"))
    if _num(res.data.get("alpha_b")):
        rows.append(("alpha_b = p_max / p_max^lambda", fmt(res.data["alpha_b"]), *("-" for _ in parts[1:]), "-"))
    return ("quantity", *(name for name, _ in parts), "unit"), tuple(rows)


def _run_rows(res):
    """How the BEM ran: method, lattice, iterations, residual, times."""
    d, b, u = res.data, res.bem, res.units
    law = getattr(rebuild_layer(res), "law", None)
    rows = [("method", method_text(d.get("method"), law), "-"),
            ("status", "converged" if d.get("converged") else "not converged", "-"),
            ("solver message", str(d.get("message", "-")), "-"),
            ("iterations (finest lattice)", fmt(d.get("iterations")), "-"),
            ("KKT residual", fmt(d.get("kkt_residual")), "-")]
    if _num(b.get("step")):
        rows.append(("lattice step c", fmt(b["step"]), u.of("length")))
    ext = b.get("extent")
    if isinstance(ext, list) and len(ext) == 2:
        rows.append(("candidate region |x| <= X, |y| <= Y (X, Y)", f"{fmt(ext[0])}, {fmt(ext[1])}", u.of("length")))
    for key, label in (("n_nodes", "candidate nodes"), ("n_contact", "nodes in contact"),
                       ("nodes_across_contact", "nodes across the contact, 2 sqrt(A / pi) / c")):
        if _num(b.get(key)):
            rows.append((label, fmt(b[key], 3), "-"))
    times = res.get("wall_time_s") or {}
    for key, label in (("layer_reference", "wall time: reference solve of the layer"), ("bem", "wall time: BEM"),
                       ("fem", "wall time: FEM"), ("stress", "wall time: subsurface stresses"),
                       ("total", "wall time: whole run")):
        if _num(times.get(key)):
            rows.append((label, fmt(times[key], 3), "s"))
    return tuple(rows)


def _results(res, work):
    columns, rows = results_rows(res)
    solvers = ", ".join(columns[1:-1])
    status = "The run converged." if res.data.get("converged") else "The run did NOT converge."
    text = [f"Computed: {solvers}. {status}"]
    messages = [str(m) for m in res.data.get("messages") or ()]
    if messages:
        text.append("Run messages: " + "; ".join(messages) + ".")
    caption = "Key results in the scene's units."
    if res.axisymmetric:
        caption += " BEM: r_c = sqrt(A / pi), A = loaded node count times the node area"
        caption += ("; FEM: edge of the loaded zone, interpolated between the interface nodes."
                    if res.fem is not None else ".")
    else:
        caption += " Half-widths: the farthest loaded node along each axis."
    if res.get("scales"):
        caption += (" Ratios: to Hertz's peak, radius and approach of the smooth paraboloid at the same load "
                    "(the scale of the figures).")
    items = [Table(columns, rows, caption=caption),
             Table(("quantity", "value", "unit"), _run_rows(res), caption="How the BEM solution was computed.",
                   status_column=None)]
    items.extend(rf.profile_figures(res, work))
    fig = rf.contact_map_figure(res, work)
    if fig is not None:
        items.append(fig)
    return Section("Results", kind="results", text=tuple(text), items=tuple(items))


def _convergence(res, work):
    fig = rf.convergence_figure(res, work)
    if fig is None:
        return None
    return Section("Convergence of the BEM", kind="iterations", items=(fig,))


def _fem(res, work):
    fem, u = res.fem, res.units
    mesh, penalty, trunc = (fem.get(k) if isinstance(fem.get(k), Mapping) else {}
                            for k in ("mesh", "penalty", "truncation"))
    rows = [("status", "converged" if fem.get("converged") else "not converged", "-"),
            ("stopping reason", str(fem.get("message", "-")), "-"),
            ("contact iterations", fmt(fem.get("iterations")), "-"),
            ("degrees of freedom", fmt(fem.get("n_dofs")), "-"),
            ("elements", fmt(fem.get("n_elements")), "-"),
            ("elements across the contact radius", fmt(fem.get("n_elements_across_contact"), 3), "-")]
    if _num(mesh.get("h_fine")):
        rows.append(("element size at the contact", fmt(mesh["h_fine"]), u.of("length")))
    if _num(mesh.get("extent_factor")):
        rows.append(("mesh half-size / estimated contact radius", fmt(mesh["extent_factor"]), "-"))
    if _num(penalty.get("relative_penetration")):
        rows.append(("penalty: largest penetration / approach", fmt(penalty["relative_penetration"]), "-"))
    if "applied" in trunc:
        rows.append(("far-field (truncation) correction applied", fmt(bool(trunc["applied"])), "-"))
    timings = fem.get("timings") if isinstance(fem.get("timings"), Mapping) else {}
    for key, label in _FEM_TIMES:
        if _num(timings.get(key)):
            rows.append((f"wall time: {label}", fmt(timings[key], 3), "s"))
    items = [Table(("quantity", "value", "unit"), tuple(rows),
                   caption="FEM reference (fem_reference, axisymmetric, quadratic triangles): mesh, solver and "
                           "time split. Its pressure, force, approach and radius are in the results table.")]
    fig = rf.von_mises_figure(res, work)
    if fig is not None:
        items.append(fig)
    return Section("FEM reference", kind="fem", items=tuple(items))


_METRICS = {"l2_rel": "relative L2 error of p", "max_rel": "max |p - p_ref| / max p_ref",
            "peak_rel": "peak pressure (a - b) / b", "contact_radius_rel": "contact radius (a - b) / b",
            "approach_rel": "approach (a - b) / b", "force_rel": "force (a - b) / b",
            "n_points": "nodes compared (union of contacts)"}


def _metric_cell(key, value):
    if not _num(value):
        return "-" if value is None else str(value)
    if key == "n_points" or isinstance(value, int):
        return str(value)
    return f"{100.0 * value:.3g} %"


def _pair_name(key):
    """``"bem_vs_analytic"`` -> ``"BEM vs closed form"``."""
    names = {"bem": "BEM", "fem": "FEM", "analytic": "closed form"}
    return " vs ".join(names.get(part, part.replace("_", " ")) for part in key.split("_vs_"))


def comparison_tables(comparison, units):
    """Tables of ``result["comparison"]``: one column per compared pair, then the force balance.

    Relative values are shown in per cent; nested containers never reach a cell.
    """
    pairs = {k: v for k, v in comparison.items() if isinstance(v, Mapping) and k != "force_balance"}
    tables = []
    if pairs:
        keys = list(dict.fromkeys(k for v in pairs.values() for k, x in v.items()
                                  if not isinstance(x, (Mapping, list))))
        rows = tuple((_METRICS.get(k, k), *(_metric_cell(k, v.get(k)) for v in pairs.values())) for k in keys)
        tables.append(Table(("metric", *(_pair_name(k) for k in pairs)), rows,
                            caption="Comparison metrics of the run (candidate vs reference at the candidate's "
                                    "nodes; signed differences are (candidate - reference) / reference)."))
    balance = comparison.get("force_balance")
    rows = []
    if isinstance(balance, Mapping):
        for key, value in balance.items():
            if key == "target" and _num(value):
                rows.append(("target force P", fmt(value), units.of("force")))
            elif _num(value):
                rows.append((f"force balance |F - P| / P ({key.upper()})", _metric_cell(key, value), "-"))
    rows += [(k, _metric_cell(k, v), "-") for k, v in comparison.items() if _num(v)]
    if rows:
        tables.append(Table(("quantity", "value", "unit"), tuple(rows), caption="Force balance of the solvers."))
    return tables


def run_sections(res, work):
    """The report sections of :class:`validation.report.results.RunResults`; figures go to ``work``."""
    work = Path(work)
    sections = [problem_statement(res, work), _results(res, work)]
    conv = _convergence(res, work)
    if conv is not None:
        sections.append(conv)
    if res.fem is not None:
        sections.append(_fem(res, work))
    stress = stress_section(res, work)
    if stress is not None:
        sections.append(stress)
    comparison = res.get("comparison")
    if comparison:
        tables = comparison_tables(comparison, res.units)
        if tables:
            sections.append(Section("Comparison metrics", kind="validation", items=tuple(tables)))
    return sections


def report_results_dir(directory, out_dir=None, *, title=None, units="auto", fmt="png", progress=None):
    """Report of a result directory; default ``out_dir`` is ``directory/report``.

    Parameters
    ----------
    directory : path-like
        Written by ``contactlab run`` (``result.json``, ``scene.toml``, fields).
    out_dir : path-like, optional
        Report directory (``report.html``, ``report.md``, ``figures/``).
    title : str, optional
        Default: the scene's title.
    units : {"auto", "scene", "dimensionless"}
        Axes in the scene's units (lengths in mm, pressures in MPa for SI scenes) or divided
        by the contact's scales (:func:`validation.report.results.load_results`).
    fmt : {"png", "svg", "pdf"}
        Figure files (:func:`validation.report.style.figure_format`).
    progress : callable, optional
        ``progress(stage, done, total)`` (:class:`validation.report.build.Progress`).

    Returns
    -------
    validation.report.build.BuiltReport
    """
    from .results import load_results

    notify = Progress(STAGES, progress)
    notify("reading")
    res = load_results(directory, units=units)
    out_dir = Path(directory) / "report" if out_dir is None else Path(out_dir)
    source = res.data.get("source")
    subtitle = f"Scene '{res.name}'" + (f" ({source})" if source else "") + \
        f"; results read from {display_path(directory)}"
    return draw_and_build(lambda work: run_sections(res, work), out_dir, title=title or res.title,
                          subtitle=subtitle, fmt=fmt, notify=notify)
