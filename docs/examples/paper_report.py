"""Generate the report of the paper's test problem (paper section 6, Fig. 4-11).

Runs the paper's test problem - two steel paraboloids, smooth and with the interface laws of
the paper: linear Winkler (lam = 10 C_nn), elastic-rigid (alpha_a = 0.5), root, bilinear -
as the built-in scenes ``paper_*``, run by the runner (``validation.run.execute_scene``); the
paper's iterative methods with their histories, the alpha_a / alpha_b / alpha_c sweeps, the
stability table of every method, the subsurface stresses and the validation against Hertz and
the FEM reference; then writes ``report.html`` and ``report.md``, which both show the figures of
``figures/*.png``.

Usage (from the repository root)::

    python docs/examples/paper_report.py --out reports/paper          # about a minute
    python docs/examples/paper_report.py --out build/paper --quick    # coarse preview (times: docs/performance.md)

The same report: ``contactlab report paper --out reports/paper``.
"""

from __future__ import annotations

import argparse
import logging
import sys


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="results/paper/report",
                        help="report directory (default: results/paper/report)")
    parser.add_argument("--quick", action="store_true", help="coarse lattice and short sweeps (preview)")
    parser.add_argument("--no-fem", action="store_true", help="skip the FEM reference and the resolution study")
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details (INFO), scikit-fem's too")
    args = parser.parse_args(argv)
    level = logging.INFO if args.verbose else logging.WARNING
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
    for name in ("bem", "fem_reference", "validation", "skfem"):
        logging.getLogger(name).setLevel(level)

    from validation.report import report_paper_problem

    built = report_paper_problem(args.out, quick=args.quick, fem=not args.no_fem)
    print(f"{built.html}\n{built.markdown}\n{len(built.figures)} figures in {built.out_dir / 'figures'}")
    for note in getattr(built, "notes", ()):
        print(f"note: {note}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
