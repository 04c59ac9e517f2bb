"""``contactlab study NAME``: the studies of the methods (:mod:`validation.studies`)."""

from __future__ import annotations

import importlib
from pathlib import Path

from ..studies import STUDIES

PARSER = {"help": "studies: " + ", ".join(STUDIES),
          "description": "Studies of the methods (validation.studies) on their built-in problems "
                         "(no scene keys to override).\n"
                         "--out DIR is the study folder written (default results/STUDY); it must be new,\n"
                         "empty or a study folder contactlab wrote (marked by DIR/.contactlab): the study's\n"
                         "files there are replaced, those of the other studies kept.",
          "epilog": "examples:\n  contactlab study error-time hertz --out reports/studies\n"
                    "  contactlab study stability --quick\n"
                    "  contactlab study two-scale --quick    (rough_sphere_two_scale, the small two-scale check)\n"
                    "  contactlab study coating-winkler --quick    (the small map: coating against Winkler layer)\n"
                    "  contactlab study coating-fem --quick    (one case: the coated BEM against the FEM)\n"
                    "  contactlab report reports/studies      (work-precision plot and tables)"}


def add_args(p):
    p.add_argument("study", choices=tuple(STUDIES), metavar="{" + ",".join(STUDIES) + "}")
    p.add_argument("scene", nargs="?", metavar="SCENE",
                   help="problem for error-time: hertz or paper_root (default: both)")
    p.add_argument("--quick", action="store_true", help="a short ladder / case list, a fraction of the full study's time")
    p.add_argument("--out", metavar="DIR", help="the study folder written (default: results/STUDY)")


def study_files(name):
    """The files the study ``name`` (a key of :data:`STUDIES`) writes: ``STEM.json``, ``STEM.md`` and its figures."""
    module = importlib.import_module(STUDIES[name])
    return tuple(getattr(module, "OUTPUT_NAMES", (f"{module.STEM}.json", f"{module.STEM}.md")))


def write_study(name, out, **options):
    """Run the study ``name`` (a key of :data:`STUDIES`) with ``options`` into the folder ``out``: its
    JSON (the study), then its Markdown and figures (the report). Returns ``(StudyRun, markdown, figures)``."""
    from ..report.documents.studies import write_study_outputs

    study = importlib.import_module(STUDIES[name]).main(out=out, **options)
    return (study, *write_study_outputs(study))


def run(args):
    """Write the study into its folder (kind ``"study"``, :mod:`validation.folders`), whole or not at all."""
    from ..io import atomic_directory, check_output_dir, output_errors, recover_output_dir
    from .common import ProgressBar

    out, what = (Path(args.out), "--out") if args.out else (Path("results") / args.study, "out_dir")
    names = (*(name for study in STUDIES for name in study_files(study)), "report")
    others = [name for name in names if name not in study_files(args.study)]
    with output_errors(out, what):
        recover_output_dir(out)
        check_output_dir(out, "study", names, what=what)  # before the study runs
    bar = ProgressBar(args.study, "step", args.no_progress or None)
    try:
        with atomic_directory(out, "study", names, what=what, keep=others) as tmp:
            study, text, figures = write_study(args.study, tmp, scene=args.scene, quick=args.quick, progress=bar)
    finally:
        bar.close()
    print(text, end="" if text.endswith("\n") else "\n")
    for path in figures:
        print(f"figure: {out / Path(path).relative_to(tmp)}")
    return study.status
