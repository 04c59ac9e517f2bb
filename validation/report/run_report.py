"""The report of a results directory (``contactlab run SCENE --out DIR``): only the sections the
results support - no FEM section unless the FEM ran, no figure without its data."""

from __future__ import annotations

import logging
import tempfile
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from .build import build_report
from .sections import Figure, Section, Table, fmt, problem_section, quantity_rows, results_table, table_from_rows
from .style import axis_labels

__all__ = ["run_sections", "report_results_dir", "unit_map"]

log = logging.getLogger(__name__)


def unit_map(units):
    """Units of the scalars of result.json from the run's units (dict or label)."""
    u = units if isinstance(units, Mapping) else {}
    length, pressure, force = u.get("length", "length"), u.get("pressure", "pressure"), u.get("force", "force")
    return {"p_max": pressure, "force": force, "approach": length, "contact_area": f"{length}^2",
            "contact_radius": length, "iterations": "-", "converged": "-", "kkt_residual": "-", "wall_time_s": "s",
            "step": length, "n_nodes": "-", "n_contact": "-", "n_dofs": "-"}


def _layer_figure(scene, work, units):
    from bem.layers import from_dict

    from .figures_profiles import plot_layer_laws

    spec = scene.get("layer")
    if not isinstance(spec, Mapping):
        return None
    try:
        layer = from_dict(dict(spec))
    except (ValueError, TypeError, KeyError) as exc:
        log.warning("layer of the scene not drawn: %s", exc)
        return None
    p_top = scene.get("p_max_plot")
    if not p_top:
        p_top = getattr(layer, "p_scale", None) or 1.0
        p_top = 3.0 * float(p_top)
    u = units if isinstance(units, Mapping) else {}
    path = plot_layer_laws([(spec.get("law", spec.get("type", "layer")), layer)], work / "layer_law.png",
                           p_max=float(p_top), p_unit=u.get("pressure", ""), w_unit=u.get("length", ""),
                           title="interface layer law $w(p)$")
    return Figure(path, "The layer law w(p) of the scene, drawn from the bem.layers object rebuilt from the "
                        "scene file.")


def _problem(res, work):
    scene = res.scene
    if not scene:
        return None
    materials = scene.get("materials") or scene.get("bodies") or {}
    materials = {k: v for k, v in _flatten_one(materials).items() if not isinstance(v, Mapping)}
    load = scene.get("load") if isinstance(scene.get("load"), Mapping) else {}
    units = res.units or "as in the scene file"
    figure = _layer_figure(scene, work, units)
    text = (f"Scene: {scene['name']}.",) if scene.get("name") else ()
    gap = scene.get("gap") if isinstance(scene.get("gap"), Mapping) else {"type": "not recorded"}
    return problem_section(gap=gap, materials=materials, load=load, units=units, figure=figure, text=text,
                           layers=[("law", scene.get("layer"))] if isinstance(scene.get("layer"), Mapping) else ())


def _flatten_one(d):
    out = {}
    for k, v in (d.items() if isinstance(d, Mapping) else ()):
        if isinstance(v, Mapping):
            out.update({f"{k}.{kk}": vv for kk, vv in v.items()})
        else:
            out[k] = v
    return out


def _status(part):
    conv = part.get("converged")
    return "-" if conv is None else ("converged" if conv else "not converged")


def _bem(res, work):
    units = unit_map(res.units)
    values = {k: res.bem[k] for k in res.bem if k != "message"}
    items = [results_table(quantity_rows(values, units), caption="BEM results (result.json).")]
    if res.bem.get("message"):
        items[0] = Table(items[0].columns, items[0].rows + (("message", res.bem["message"], "-"),),
                         caption=items[0].caption)
    if res.bem_field is not None:
        from .figures_3d import plot_contact_map
        from .figures_profiles import plot_pressure_profiles

        x, y, p = res.bem_field
        labels = axis_labels(units=res.units if isinstance(res.units, Mapping) else {})
        on = np.abs(y) <= 1e-9 * float(np.abs(x).max(initial=1.0))
        if np.any(p[on] > 0):
            order = np.argsort(x[on])
            path = plot_pressure_profiles([("BEM", (x[on][order], p[on][order]))], work / "bem_profile.png",
                                          p0=1.0, a=1.0, labels=labels, title="contact pressure in the axial section")
            items.append(Figure(path, "BEM contact pressure along the axial section y = 0 (nodal values)."))
        if np.any(p > 0):
            path = plot_contact_map((x, y, p), work / "bem_contact_map.png", p0=1.0, a=1.0, labels=labels,
                                    title="contact pressure over the plane")
            items.append(Figure(path, "BEM contact pressure over the plane with the contact boundary."))
    return Section("BEM results", kind="results", items=tuple(items))


def _fem(res, work):
    units = unit_map(res.units)
    fem = {k: v for k, v in res.fem.items() if not isinstance(v, Mapping)}
    items = [results_table(quantity_rows(fem, units), caption="FEM reference results (result.json).")]
    if res.fem_field is not None:
        from .figures_fem import plot_section_field

        r, z, tri, vm = res.fem_field
        a = float(res.fem.get("contact_radius") or res.bem.get("contact_radius") or 1.0)
        labels = axis_labels(units=res.units if isinstance(res.units, Mapping) else {})
        u = res.units.get("pressure", "") if isinstance(res.units, Mapping) else ""
        path = plot_section_field(r, z, tri, vm, work / "fem_von_mises.png", a=1.0, scale=1.0, window=3.0 * a,
                                  label="von Mises stress" + (f" [{u}]" if u else ""), labels=labels,
                                  contact_radius=res.fem.get("contact_radius"),
                                  title="FEM reference: von Mises stress in the axial section")
        items.append(Figure(path, "Von Mises stress of the FEM reference in the (r, z) section, read from the "
                                  "run's .vtu file."))
    return Section("FEM reference", kind="fem", items=tuple(items))


def _comparison(res):
    rows = tuple((k, fmt(v) if not isinstance(v, str) else v) for k, v in res.comparison.items())
    return Section("Comparison metrics", kind="validation",
                   items=(Table(("metric", "value"), rows, caption="Comparison metrics recorded by the run."),))


def _study(title, study, work, k):
    from .figures_validation import plot_work_precision, work_precision_rows

    rows = study["rows"]
    items = []
    plottable = all(k in row for row in rows for k in ("solver", "error", "wall_time_s"))
    if plottable and work_precision_rows(rows):
        path = plot_work_precision(rows, work / f"study_{k}_work_precision.png",
                                   error_label=str(study.get("error_label", "error")), title=title)
        items.append(Figure(path, f"Work-precision of the study '{title}': error against wall time, one line per "
                                  "solver/method, one marker per resolution."))
    table = table_from_rows(rows, caption=f"Study '{title}'.")
    items.append(table)
    kind = "stability" if table.status_column else "validation"
    return Section(f"Study: {title}", kind=kind, items=tuple(items))


def run_sections(res, work):
    """Sections for :class:`validation.report.results.RunResults`; figures go to ``work``."""
    work = Path(work)
    sections = [s for s in (_problem(res, work),) if s is not None]
    sections.append(_bem(res, work))
    if res.fem is not None:
        sections.append(_fem(res, work))
    if res.comparison:
        sections.append(_comparison(res))
    for k, (title, study) in enumerate(res.studies, 1):
        sections.append(_study(title, study, work, k))
    if res.other:
        rows = tuple((k, fmt(v) if not isinstance(v, str) else v) for k, v in res.other.items())
        sections.append(Section("Other recorded values", kind="notes",
                                items=(Table(("key", "value"), rows, caption="Other scalars of result.json."),)))
    return sections


def report_results_dir(directory, out_dir=None, *, title=None):
    """Report of a results directory; default ``out_dir`` is ``directory/report``.

    Returns
    -------
    validation.report.build.BuiltReport
    """
    from .results import load_results

    res = load_results(directory)
    out_dir = Path(directory) / "report" if out_dir is None else Path(out_dir)
    name = res.scene.get("name") or Path(directory).resolve().name
    with tempfile.TemporaryDirectory(prefix="contactlab-figures-") as work:
        sections = run_sections(res, work)
        return build_report(sections, out_dir, title=title or f"contactlab report: {name}",
                            subtitle=f"Results read from {Path(directory).resolve()}")
