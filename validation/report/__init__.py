"""Reports: HTML and Markdown documents of runs, sweeps, studies and the paper's problem.

- :mod:`.render`: the content (:class:`Section`, :class:`Figure`, :class:`Table`), HTML,
  Markdown, the atomic build of a report directory (:func:`build_report`), the figure style;
- :mod:`.figures`: the drawing functions and :data:`FIGURES`, the figures of a run's report;
- :mod:`.documents`: the documents - a result directory (:func:`report_results_dir`, its
  sections in :data:`SECTIONS`, keyed by a scene's ``[report] sections``), a sweep
  (:func:`report_sweep_dir`), the studies (:func:`report_studies_dir`) and the paper's test
  problem (:func:`report_paper_problem`, its cases run as scenes by the runner);
- :mod:`.command`: ``contactlab report`` (:func:`main`).
"""

from .command import main
from .documents.paper import report_paper_problem
from .documents.results import load_results
from .documents.sections import SECTIONS, report_results_dir
from .documents.studies import report_studies_dir
from .documents.sweep import report_sweep_dir
from .figures import FIGURES
from .render import (FORMATS, BuiltReport, Figure, Section, Table, build_report, figure_format, problem_section,
                     table_from_rows)

__all__ = ["build_report", "BuiltReport", "Section", "Figure", "Table", "problem_section", "table_from_rows",
           "FIGURES", "SECTIONS", "report_results_dir", "report_sweep_dir", "report_studies_dir",
           "report_paper_problem", "load_results", "figure_format", "FORMATS", "main"]
