"""Rendering: the content of a report (:mod:`.content`), its HTML (:mod:`.html`) and Markdown
(:mod:`.markdown`), the atomic build of a report directory (:mod:`.build`) and the look and the
atomic saving of every figure (:mod:`.style`)."""

from .build import REPORT_FILES, BuiltReport, Progress, build_report, draw_and_build
from .content import KINDS, Figure, Section, Table, fmt, problem_section, status_class, table_from_rows
from .style import FORMATS, figure_format, new_figure, save_figure

__all__ = ["build_report", "draw_and_build", "BuiltReport", "Progress", "REPORT_FILES", "Figure", "Table", "Section",
           "KINDS", "fmt", "status_class", "problem_section", "table_from_rows", "FORMATS", "figure_format",
           "new_figure", "save_figure"]
