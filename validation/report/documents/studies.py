"""Report of the validation studies: error against run time, stability and robustness.

Reads what ``contactlab study error-time|stability|robustness --out DIR`` write
(``error_time.json``, ``stability.json``, ``robustness.json``) and builds a report with the
work-precision plot per problem, the "first to reach" table, the stability table coloured by
status and the robustness tables. Only the studies present in ``DIR`` get a section.
"""

from __future__ import annotations

from pathlib import Path

from bem.checks import InputError

from ...provenance import display_path
from ...studies import STUDY_FILES
from ..render import Figure, Progress, Section, Table, draw_and_build, table_from_rows
from .results import read_json
from .coating_fem import coating_fem_sections
from .coating_winkler import coating_winkler_sections
from .two_scale import two_scale_sections

__all__ = ["STUDY_FILES", "is_study_dir", "study_sections", "study_markdown", "write_study_outputs",
           "report_studies_dir"]


def is_study_dir(directory):
    """True when ``directory`` holds at least one study file."""
    return any((Path(directory) / name).is_file() for name in STUDY_FILES)


def _label(row):
    from validation.studies.error_time import method_with_relaxation

    return method_with_relaxation(row["method"], row.get("relaxation"))


def _error_time_sections(data, work):
    rows = data.get("rows", [])
    sections = []
    for problem in dict.fromkeys(r["problem"] for r in rows):
        mine = [r for r in rows if r["problem"] == problem]
        ref = data.get("references", {}).get(problem, {})
        ref_text = ref.get("description") if isinstance(ref, dict) else str(ref)
        items = []
        for metric, label in (("error_l2", "relative L2 error of p over the contact"),
                              ("error_peak", "relative error of the peak pressure")):
            wp = [{"solver": r["solver"], "method": _label(r), "resolution": r["resolution"], "N": r["n"],
                   "error": r[metric], "wall_time_s": r["wall_time_s"], "wall_times_s": r.get("wall_times_s")}
                  for r in mine if r["converged"]]
            if not wp or work is None:
                continue
            from ..figures.precision import plot_work_precision

            path = plot_work_precision(wp, Path(work) / f"work_precision_{problem}_{metric}.png",
                                       error_label=label, title=f"{problem}: {label} against run time")
            items.append(Figure(path, f"Work-precision, {problem}: {label} against the wall time of every "
                                      "converged run; the marker is the median of its repeats, the bar spans "
                                      "the fastest to the slowest repeat (runs slower than the study's slow_s "
                                      "are timed once); one line per solver and method, a marker per "
                                      "resolution (nodes across the contact for the BEM, elements across the "
                                      "contact radius for the FEM); dotted lines at 1 % and 0.1 %."))
        items.append(Table(
            ("solver", "method", "resolution", "N", "L2 error", "peak error", "time [s]", "iterations", "status"),
            tuple((r["solver"], _label(r), r["resolution"], r["n"], r["error_l2"], r["error_peak"], r["wall_time_s"],
                   r["iterations"], r["solver_status"]) for r in mine),
            caption=f"Every run of the {problem} ladder.", status_column="status"))
        text = [f"Reference: {ref_text}."] if ref_text else []
        sections.append(Section(f"Error against run time: {problem}", "validation", text, items))
    first = data.get("first_to_reach", {})
    if first:
        flat = [{"problem": problem, "error": metric.replace("error_", ""), "target": f"{float(target):.1%}",
                 "first": " ".join(str(hit[k]) for k in ("solver", "method") if hit.get(k)) or "none reached it",
                 "resolution": hit.get("resolution", "-"), "time [s]": hit.get("wall_time_s")}
                for problem, metrics in first.items() for metric, targets in metrics.items()
                for target, found in targets.items() for hit in [found or {}]]
        table = table_from_rows(flat, caption="The fastest converged run that reaches each target and stays "
                                              "below it at every finer level of the same method.", status="")
        notes = [str(n) for n in data.get("notes", [])]
        sections.append(Section("Which method reaches 1 % and 0.1 % first", "validation", notes, (table,)))
    return sections


def _stability_sections(data, work=None):
    rows = data.get("rows", [])
    columns = [c for c in ("case", "solver", "method", "status", "kkt_residual", "error_vs_reference", "reference",
                           "iterations", "wall_time_s", "message") if any(c in r for r in rows)]
    statuses = ("converged", "reported failure", "wrong")
    summary = Table(("solver / method",) + statuses,
                    tuple((k, *(c.get(st, 0) for st in statuses)) for k, c in data.get("counts", {}).items()),
                    caption="Outcomes per solver and method: converged (and agreeing with the reference), "
                            "reported failure (converged = false with a reason), wrong (a converged answer "
                            "that disagrees with the reference, or NaN anywhere).")
    detail = table_from_rows(rows, columns=columns, caption="Every case and method.", status="status")
    text = ["Stiff and extreme cases: layer compliance over six decades, power exponents from 0.2 to 3, "
            "a tiny elastic-rigid threshold, a contact of a few nodes, a contact filling the region, very "
            "dissimilar moduli, and Poisson's ratio near 0.5 in the FEM. The study raises on any NaN or "
            "wrong answer."]
    tol = data.get("settings", {})
    if "method_tol" in tol:
        text.append(f"Tolerances: the paper's methods and the QP against Newton on the same lattice "
                    f"{tol['method_tol']:g}; the FEM against Hertz or BEM Newton on a 4x finer lattice "
                    f"{tol['fem_tol']:g}; Newton against the case's closed form at the case's tolerance.")
    return [Section("Stability", "stability", text, (summary, detail))]


def _robustness_sections(data, work=None):
    from validation.studies import robustness as rb

    rows = rb.rows_from_json(data)
    tables = [Table(*map(tuple, (h, [tuple(r) for r in b])), caption=cap) for (h, b), cap in (
        (rb.summary_table(rows), "Outcomes per method and control over the whole grid; a converged answer is "
                                 "checked against the KKT conditions with the dense influence matrix."),
        *[(rb.matrix_table(rows, m), f"{m}: converged out of all (E*, control) per exponent s (rows) and "
                                     "compliance k (columns).") for m in rb.LAYER_METHODS],
        (rb.failure_table(rows), "Every outcome that is not converged."))]
    return [Section("Robustness of the layer methods", "stability", [rb.SETTING], tuple(tables))]


#: study file -> function(data, work) -> sections (``work``: the figures' folder, None for none), in the
#: order of :data:`validation.studies.STUDIES`
_SECTIONS = dict(zip(STUDY_FILES, (_error_time_sections, _stability_sections, _robustness_sections,
                                   two_scale_sections, coating_winkler_sections,
                                   coating_fem_sections)))


def study_sections(directory, work):
    """Sections for the study files present in ``directory``; figures go to ``work``."""
    directory = Path(directory)
    sections = [sec for name, make in _SECTIONS.items() if (directory / name).is_file()
                for sec in make(read_json(directory / name), work)]
    if not sections:
        raise InputError(f"directory = {str(directory)!r} is not allowed: it holds none of {list(STUDY_FILES)}.")
    return sections


def study_markdown(name, data):
    """The tables of one study as Markdown, without figures (what ``contactlab study`` prints and writes).

    ``name`` is its file in :data:`STUDY_FILES` (``"stability.json"``), ``data`` that file's content.
    """
    from ..render.markdown import render_markdown

    title = {"error_time.json": "Error against run time", "stability.json": "Stability on stiff and extreme cases",
             "robustness.json": "Robustness of the layer methods",
             "two_scale.json": "Two-scale check",
             "coating_winkler.json": "Coatings and the Winkler layer",
             "coating_fem.json": "The coated BEM against the FEM"}[name]
    return render_markdown(_SECTIONS[name](data, None), title=title, names={})


def write_study_outputs(run):
    """Beside the JSON file of a study's run (:class:`validation.studies.StudyRun`), its tables as
    ``<stem>.md`` and, for the two-scale check with its fields, the two figures of its first case; for
    the coating study, its map; for the coating-FEM study, its figure.

    Returns ``(markdown, figure files)``; the Markdown is made from the JSON as written.
    """
    from bem.files import write_text

    text = study_markdown(run.path.name, run.data)
    write_text(run.path.with_suffix(".md"), text)
    figures = []
    if run.stem == "two_scale" and run.fields is not None:
        from ...extras import require
        from ..figures.two_scale import plot_two_scale

        require("report", "the two-scale check (its figures)")

        figures = plot_two_scale(run.data, run.fields, run.path.parent)
    elif run.stem == "coating_winkler" and run.data.get("rows"):
        from ...extras import require
        from ..figures.coating_winkler import plot_coating_map

        require("report", "the coating study (its map)")
        figures = [plot_coating_map(run.data, run.path.parent)]
    elif run.stem == "coating_fem" and run.data.get("rows"):
        from ...extras import require
        from ..figures.coating_fem import plot_coating_fem

        require("report", "the coating-FEM study (its figure)")
        figures = [plot_coating_fem(run.data, run.path.parent)]
    return text, figures


def report_studies_dir(directory, out_dir=None, *, title="contactlab validation studies", fmt="png", progress=None):
    """Report of the study files in ``directory`` (default ``out_dir``: ``directory/report``).

    ``fmt`` (``"png"``, ``"svg"``, ``"pdf"``) chooses the figure files
    (:func:`validation.report.render.style.figure_format`); ``progress(stage, done, total)``
    hears the stages (:class:`validation.progress.Progress`).
    """
    from .sections import STAGES

    out_dir = Path(directory) / "report" if out_dir is None else Path(out_dir)
    return draw_and_build(lambda work: study_sections(directory, work), out_dir, title=title,
                          subtitle=f"Studies read from {display_path(directory)}", fmt=fmt,
                          notify=Progress(STAGES[1:], progress))
