"""``contactlab study NAME``: the studies of the methods (:mod:`validation.studies`)."""

from __future__ import annotations

from .common import optional_import

PARSER = {"help": "error-time and stability studies",
          "description": "Studies of the methods (validation.studies) on their built-in problems "
                         "(no scene keys to override).",
          "epilog": "examples:\n  contactlab study error-time hertz --out reports/studies\n"
                    "  contactlab study stability --quick\n"
                    "  contactlab report reports/studies      (work-precision plot and tables)"}

#: study name -> module with ``main(args)``
STUDIES = {"error-time": "validation.studies.error_time", "stability": "validation.studies.stability",
           "robustness": "validation.studies.robustness"}


def add_args(p):
    p.add_argument("study", choices=tuple(STUDIES), metavar="{" + ",".join(STUDIES) + "}")
    p.add_argument("scene", nargs="?", metavar="SCENE",
                   help="problem for error-time: hertz or paper_root (default: both)")
    p.add_argument("--quick", action="store_true", help="a short ladder / case list (minutes instead of ~5)")
    p.add_argument("--out", metavar="DIR")


def run(args):
    mod = optional_import(STUDIES[args.study], f"the {args.study} study")
    if mod is None:
        return 2
    code = mod.main(args)
    return 0 if code is None else int(code)
