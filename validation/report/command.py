"""``contactlab report TARGET [--out DIR]``: the entry point the command line calls."""

from __future__ import annotations

import logging
from pathlib import Path

from bem._validate import InputError

__all__ = ["main", "DEFAULT_PAPER_OUT"]

log = logging.getLogger(__name__)

#: where ``contactlab report paper`` writes without ``--out`` (relative to the working directory)
DEFAULT_PAPER_OUT = Path("reports") / "paper"


def main(args):
    """Write the report of ``args.target``; returns the exit status 0 (errors raise).

    Parameters
    ----------
    args : argparse.Namespace
        ``target``: ``"paper"`` (solve the paper's test problem and report it) or a
        results directory holding ``result.json`` (see :mod:`validation.report.results`);
        ``out`` (optional): the report directory (default ``reports/paper`` for ``paper``,
        ``TARGET/report`` for a results directory); ``quick`` (optional, bool): coarse
        preview of the paper report.

    Raises
    ------
    bem._validate.InputError
        Unknown target (a scene must be run first with ``contactlab run``) or an output
        directory that holds other files.
    """
    target = str(getattr(args, "target", "") or "")
    out = getattr(args, "out", None)
    if target == "paper":
        from .paper_report import report_paper_problem

        quick = bool(getattr(args, "quick", False))
        built = report_paper_problem(DEFAULT_PAPER_OUT if out is None else out, quick=quick)
    elif Path(target).is_dir():
        from .run_report import report_results_dir

        built = report_results_dir(target, out)
    else:
        raise InputError(
            f"target = {target!r} is not allowed: it must be 'paper' or a results directory holding result.json. "
            f"To report a scene, run it first: contactlab run {target or 'SCENE'} --out DIR, "
            "then contactlab report DIR."
        )
    log.info("report written: %s and %s (%d figures)", built.html, built.markdown, len(built.figures))
    return 0
