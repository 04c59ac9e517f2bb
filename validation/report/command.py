"""``contactlab report TARGET [--out DIR]``: the entry point the command line calls."""

from __future__ import annotations

import logging
from pathlib import Path

from bem.checks import InputError

from ..extras import require as require_extra

__all__ = ["main", "DEFAULT_PAPER_OUT"]

log = logging.getLogger(__name__)

#: where ``contactlab report paper`` writes without ``--out`` (relative to the working directory)
DEFAULT_PAPER_OUT = Path("reports") / "paper"


def main(args):
    """Write the report of ``args.target``; returns the exit status 0 (errors raise).

    Parameters
    ----------
    args : argparse.Namespace
        ``target``: ``"paper"`` (solve the paper's test problem and report it), a
        built-in scene name or a scene TOML file (run it into ``OUT/result``, report into
        ``OUT/report``, ``OUT`` defaulting to ``results/NAME``), a results directory
        holding ``result.json`` (see :mod:`validation.report.results`), or a directory of
        study files (``error_time.json``, ``stability.json``:
        :mod:`validation.report.study_report`);
        ``out`` (optional): the report directory (default ``reports/paper`` for ``paper``,
        ``TARGET/report`` for a results directory); ``quick`` (optional, bool): coarse
        preview of the paper report.

    Raises
    ------
    bem.InputError
        Unknown target (a scene must be run first with ``contactlab run``) or an output
        directory that holds other files.
    validation.extras.MissingExtraError
        matplotlib or pillow (``contactlab[report]``), or for ``paper`` gmsh or scikit-fem
        (``contactlab[fem]``), cannot be imported; nothing has run.
    """
    target = str(getattr(args, "target", "") or "")
    out = getattr(args, "out", None)
    require_extra("report", "contactlab report (figures)")
    if target == "paper":
        require_extra("fem", "contactlab report paper (the FEM validation)")
        from .paper_report import report_paper_problem

        quick = bool(getattr(args, "quick", False))
        built = report_paper_problem(DEFAULT_PAPER_OUT if out is None else out, quick=quick)
    elif Path(target).is_dir() and not (Path(target) / "result.json").is_file() and _studies(target):
        from .study_report import report_studies_dir

        built = report_studies_dir(target, out)
    elif Path(target).is_dir():
        from .run_report import report_results_dir

        built = report_results_dir(target, out)
    elif _is_scene(target):
        built = _report_scene(target, out)
    else:
        raise InputError(
            f"target = {target!r} is not allowed: it must be 'paper', a built-in scene name, a scene "
            "TOML file or a results directory holding result.json (see `contactlab scenes`)."
        )
    log.info("report written: %s and %s (%d figures)", built.html, built.markdown, len(built.figures))
    return 0


def _studies(target):
    from .study_report import is_study_dir

    return is_study_dir(target)


def _is_scene(target):
    from validation.scene import builtin_scenes

    return target in builtin_scenes() or (target.endswith(".toml") and Path(target).is_file())


def _report_scene(target, out):
    """Run the scene into ``OUT/result`` and report it into ``OUT/report``.

    ``OUT`` defaults to ``results/NAME``. The run writes its result directory
    atomically, the report is built from it as for any results directory.
    """
    from validation.runner import run_scene

    from .run_report import report_results_dir

    base = Path(out) if out is not None else Path("results") / Path(target).stem
    run_scene(target, base / "result")
    return report_results_dir(base / "result", base / "report")
