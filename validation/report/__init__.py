"""Reports: the paper's figures, validation tables and error-time plots, as HTML and Markdown.

Figure functions take plain data or result objects and a path, write one figure atomically
and return the written file (matplotlib with the Agg canvas, mplot3d for the 3-D surfaces,
imported inside the functions): a 300 dpi PNG, or SVG or PDF within
:func:`figure_format`. :func:`build_report` renders a list of :class:`Section` to a
self-contained ``report.html`` and a ``report.md`` with ``figures/``, written whole or not at
all. :func:`report_paper_problem` solves the paper's test problem and reports it;
:func:`report_results_dir` reports a ``contactlab run`` results directory,
:func:`report_sweep_dir` a ``contactlab sweep`` directory; :func:`main` is ``contactlab
report``.
"""

from .build import BuiltReport, build_report
from .command import main
from .figures_3d import plot_contact_map, plot_pressure_surfaces
from .figures_fem import plot_section_field, plot_von_mises
from .figures_iterations import plot_convergence, plot_iteration_profiles
from .figures_profiles import axial_section, plot_layer_laws, plot_pressure_profiles
from .figures_sweeps import edge_radius, plot_sweep, plot_sweep_scalars, plot_transition_line, transition_radius
from .figures_validation import plot_profile_comparison, plot_work_precision
from .paper import PaperProblem, solve_paper_problem
from .paper_report import report_paper_problem
from .results import load_results
from .run_report import report_results_dir
from .sections import Figure, Section, Table, problem_section, results_table, table_from_rows
from .style import FORMATS, figure_format
from .sweep_report import report_sweep_dir

__all__ = [
    "build_report", "BuiltReport", "Section", "Figure", "Table", "problem_section", "results_table", "table_from_rows",
    "plot_pressure_profiles", "plot_layer_laws", "axial_section", "plot_iteration_profiles", "plot_convergence",
    "plot_pressure_surfaces", "plot_contact_map", "plot_sweep", "plot_sweep_scalars", "plot_transition_line",
    "transition_radius",
    "edge_radius", "plot_profile_comparison", "plot_work_precision", "plot_von_mises", "plot_section_field",
    "PaperProblem", "solve_paper_problem", "report_paper_problem", "load_results", "report_results_dir",
    "report_sweep_dir", "figure_format", "FORMATS", "main",
]
