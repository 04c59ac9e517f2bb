"""``contactlab study NAME``: the studies of the methods (:mod:`validation.studies`)."""

from __future__ import annotations

import importlib

from ..studies import STUDIES

PARSER = {"help": "studies: " + ", ".join(STUDIES),
          "description": "Studies of the methods (validation.studies) on their built-in problems "
                         "(no scene keys to override).",
          "epilog": "examples:\n  contactlab study error-time hertz --out reports/studies\n"
                    "  contactlab study stability --quick\n"
                    "  contactlab study two-scale --quick    (rough_sphere_two_scale, the small two-scale check)\n"
                    "  contactlab report reports/studies      (work-precision plot and tables)"}


def add_args(p):
    p.add_argument("study", choices=tuple(STUDIES), metavar="{" + ",".join(STUDIES) + "}")
    p.add_argument("scene", nargs="?", metavar="SCENE",
                   help="problem for error-time: hertz or paper_root (default: both)")
    p.add_argument("--quick", action="store_true", help="a short ladder / case list, a fraction of the full study's time")
    p.add_argument("--out", metavar="DIR")


def write_study(name, out=None, **options):
    """Run the study ``name`` (a key of :data:`STUDIES`) with ``options`` into the folder ``out``: its
    JSON (the study), then its Markdown and figures (the report). Returns ``(StudyRun, markdown, figures)``."""
    from ..report.documents.studies import write_study_outputs

    study = importlib.import_module(STUDIES[name]).main(out=out, **options)
    return (study, *write_study_outputs(study))


def run(args):
    from .common import ProgressBar

    bar = ProgressBar(args.study, "step", args.no_progress or None)
    try:
        study, text, figures = write_study(args.study, args.out, scene=args.scene, quick=args.quick, progress=bar)
    finally:
        bar.close()
    print(text, end="" if text.endswith("\n") else "\n")
    for path in figures:
        print(f"figure: {path}")
    return study.status
