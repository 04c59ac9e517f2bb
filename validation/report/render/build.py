"""Write a report directory whole or not at all.

``out_dir/report.html``, ``out_dir/report.md`` and ``out_dir/figures/`` (the PNG or SVG of
every figure, which both documents link, and the PDF beside a PNG drawn in ``"pdf"`` format:
each figure stored once) are first
written into a fresh temporary directory beside ``out_dir``; only when all of them are
complete is that directory renamed onto ``out_dir`` (a previous report there is
moved aside first and deleted afterwards: :func:`validation.io.atomic_directory`). An
interrupted build leaves the previous report, or nothing, never a mixture.
"""

from __future__ import annotations

import logging
import tempfile
from dataclasses import dataclass
from pathlib import Path

from bem.checks import InputError

from ...io import atomic_directory, check_output_dir, output_errors, recover_output_dir
from ...progress import Progress
from ...provenance import report_footer
from .content import Figure, Section
from .html import render_html
from .markdown import render_markdown
from .style import figure_format, vector_copy, vector_name

__all__ = ["build_report", "BuiltReport", "REPORT_FILES", "Progress", "draw_and_build", "check_report_dir"]

log = logging.getLogger(__name__)

#: what a report directory holds besides its marker ``.contactlab`` (anything else makes
#: :func:`build_report` refuse to replace it)
REPORT_FILES = ("report.html", "report.md", "figures")


@dataclass(frozen=True)
class BuiltReport:
    """Paths of a written report, and the notes its run has for the reader (``notes``: one
    sentence each, e.g. expected non-convergence the report discusses; the command prints them)."""

    out_dir: Path
    html: Path
    markdown: Path
    figures: tuple
    notes: tuple = ()


def draw_and_build(make_sections, out_dir, *, title, subtitle="", fmt="png", notify=None):
    """Draw the figures of ``make_sections(work)`` in ``fmt`` into a temporary folder and build the report.

    Parameters
    ----------
    make_sections : callable
        ``make_sections(work)`` -> list of Section, writing its figures into the folder ``work``.
    out_dir : path-like
        Report directory (:func:`build_report`).
    title, subtitle : str
        As for :func:`build_report`.
    fmt : {"png", "svg", "pdf"}
        Figure files (:func:`validation.report.render.style.figure_format`).
    notify : Progress, optional
        Told the stages ``"figures"`` and ``"writing"``, then :meth:`Progress.done`.

    Returns
    -------
    BuiltReport
    """
    notify = notify or Progress(("figures", "writing"))
    with figure_format(fmt), tempfile.TemporaryDirectory(prefix="contactlab-figures-") as work:
        notify("figures")
        sections = make_sections(work)
        notify("writing")
        built = build_report(sections, out_dir, title=title, subtitle=subtitle, root=work)
    notify.done()
    return built


def check_report_dir(out_dir, *, what="out_dir", value=None):
    """Clean up after a killed writer of ``out_dir`` and refuse it if it is not a report directory.

    Raises
    ------
    validation.io.OutputError
        :func:`validation.io.check_output_dir` (kind ``"report"``).
    """
    with output_errors(out_dir, what):
        recover_output_dir(out_dir)
        check_output_dir(out_dir, "report", REPORT_FILES, what=what, value=value)


def _figure_names(sections, root=None):
    """Unique ``figures/<name>.<png|svg>`` for every figure path, in order of appearance; a file in a
    folder below ``root`` is named after that folder too (``root/case/profile.png``: ``case_profile``)."""
    names, used = {}, set()
    for sec in sections:
        for item in sec.items:
            if isinstance(item, Figure) and item.path not in names:
                path = Path(item.path)
                path = path.relative_to(root) if root is not None and path.is_relative_to(root) else Path(path.name)
                stem, ext = "_".join(path.with_suffix("").parts) or "figure", path.suffix.lower()
                name, k = stem, 1
                while name in used:
                    k += 1
                    name = f"{stem}-{k}"
                used.add(name)
                names[item.path] = f"figures/{name}{ext}"
    return names


def build_report(sections, out_dir, *, title, subtitle="", footer=None, root=None):
    """Render ``sections`` to ``out_dir/report.html``, ``report.md`` and ``figures/``.

    Parameters
    ----------
    sections : sequence of Section
        The content (:mod:`validation.report.render.content`), in order.
    out_dir : path-like
        Report directory; created, or replaced if it holds a previous report (marked by
        ``.contactlab``, :mod:`validation.io`). A directory holding anything else is refused
        (nothing is deleted).
    title : str
        Report title.
    subtitle : str
        Line under the title.
    footer : str, optional
        Footer text; default :func:`validation.provenance.report_footer` (contactlab version,
        git commit, Python, numpy and scipy versions, the command line and the date).
    root : path-like, optional
        The folder the figures were drawn into: a figure in a folder below it is named after
        that folder too.

    Returns
    -------
    BuiltReport

    Raises
    ------
    bem.InputError
        No sections or a non-Section item.
    validation.io.OutputError
        ``out_dir`` is not a new, empty or report directory (:func:`check_report_dir`), or
        writing it failed.
    """
    sections = list(sections)
    if not sections:
        raise InputError("sections = [] is not allowed: a report needs at least one section.")
    for sec in sections:
        if not isinstance(sec, Section):
            raise InputError(f"section {sec!r} is not allowed: it must be a validation.report.Section.")
    out_dir = Path(out_dir).resolve()
    if footer is None:
        footer = report_footer()
    names = _figure_names(sections, root)
    images = {path: Path(path).read_bytes() for path in names}
    vectors = {vector_name(names[path]): Path(pdf).read_bytes() for path in names
               if (pdf := vector_copy(path)) is not None}
    with atomic_directory(out_dir, "report", REPORT_FILES) as tmp:
        (tmp / "figures").mkdir()
        for path, name in names.items():
            (tmp / name).write_bytes(images[path])
        for name, data in vectors.items():
            (tmp / name).write_bytes(data)
        (tmp / "report.html").write_text(
            render_html(sections, title=title, subtitle=subtitle, names=names, footer=footer, vectors=vectors),
            encoding="utf-8")
        (tmp / "report.md").write_text(
            render_markdown(sections, title=title, subtitle=subtitle, names=names, footer=footer,
                            vectors=vectors), encoding="utf-8")
    log.info("report written to %s (%d figures)", out_dir, len(names))
    return BuiltReport(out_dir, out_dir / "report.html", out_dir / "report.md",
                       tuple(out_dir / n for n in names.values()))
