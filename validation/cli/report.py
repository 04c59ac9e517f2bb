"""``contactlab report TARGET``: figures and an HTML/Markdown report (:mod:`validation.report`)."""

from __future__ import annotations

import os

from ..report.render.style import DPI, FORMATS
from .common import ProgressBar, add_set, add_trust, trust

PARSER = {"help": "figures and an HTML/Markdown report",
          "description": "Build a report (report.html, report.md, figures/) from the paper's test\n"
                         "problem, a scene (runs it first, into results/NAME/ as `contactlab run` does),\n"
                         "a result directory of `contactlab run`, a sweep directory of `contactlab sweep`\n"
                         "or a directory of study files. --out DIR is the report directory itself, for\n"
                         "every target; it must be new, empty or a report directory contactlab wrote\n"
                         "(marked by DIR/.contactlab), which is replaced.\n"
                         "Prints where it wrote report.html; a progress bar on stderr shows the stages.",
          "epilog": "examples:\n"
                    "  contactlab report hertz                     results/hertz/ and results/hertz/report/\n"
                    "  contactlab report hertz --out rep/hertz     results/hertz/ and rep/hertz/report.html\n"
                    "  contactlab report results/hertz --out rep/   rep/report.html\n"
                    "  contactlab report results/paper_elastic_rigid-sweep-alpha_a      (a sweep)\n"
                    "  contactlab report reports/studies                (study files)\n"
                    "  contactlab report paper --quick --out /tmp/paper\n"
                    "  contactlab report hertz --units dimensionless --format pdf"}


def add_args(p):
    p.add_argument("target", metavar="SCENE_OR_DIR",
                   help="'paper', a scene (built-in name or .toml), or a result, sweep or study directory")
    p.add_argument("--out", metavar="DIR", help="the report directory written (default: results/paper/report for "
                                                "'paper', DIR/report for a directory, results/NAME/report for "
                                                "a scene)")
    p.add_argument("--format", choices=FORMATS, default="png",
                   help=f"figure files: png ({DPI} dpi, default), svg (vector, shown in the HTML), or pdf "
                        "(vector, beside a PNG for the HTML)")
    p.add_argument("--units", choices=("auto", "scene", "dimensionless"),
                   help="units of a scene, result or sweep report, one per quantity in every table and figure: "
                        "auto (default): readable ones (mm, MPa, N for an SI scene; dimensionless when the "
                        "scene's units label names none); scene: the scene's own units; dimensionless: lengths "
                        "and pressures divided by the contact's scales (Hertz's a_H and p_H for a paraboloid, "
                        "else the contact half-width and p_max)")
    p.add_argument("--quick", action="store_true",
                   help="'paper' only: a coarse preview (a_H/c = 8, short sweeps) in a fraction of the full "
                        "report's time (measured times: docs/performance.md)")
    add_set(p, "scene targets only: ")
    add_trust(p, scope="scene targets only: ")


#: the option of each keyword of validation.report.command.build
_FLAGS = {"quick": "--quick", "units": "--units", "overrides": "--set", "allow_code": "--allow-code",
          "allow_outside_files": "--allow-outside-files"}


def run(args):
    from ..report import command

    options = dict(quick=args.quick, units=args.units, overrides=args.overrides, **trust(args))
    bar = ProgressBar("report", "stage", args.no_progress or None)
    try:
        built = command.build(args.target, out=args.out, fmt=args.format, progress=bar, what="--out", names=_FLAGS,
                              **options)
    finally:
        bar.close()
    print(f"report written to {built.html}")
    print(f"  (also {built.markdown.name} and {len(built.figures)} figures in {built.out_dir / 'figures'}{os.sep})")
    for note in built.notes:
        print(f"note: {note}")
    return 0
