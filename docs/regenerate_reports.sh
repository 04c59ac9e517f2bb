#!/usr/bin/env bash
# Regenerate every report the repository keeps (its run time: docs/performance.md):
#   reports/paper/        the paper's test problem (Fig. 4-11 analogues, validation)
#   reports/hertz/        the built-in Hertz scene: BEM + FEM + closed form
#   reports/studies/      raw study output (error_time.*, stability.*, robustness.*, two_scale.* of the
#                         quick run, coating_winkler.*, coating_fem.*)
#   reports/validation/   the report of the studies (work-precision plots, stability and robustness tables)
# Usage, from the repository root:  bash docs/regenerate_reports.sh
# Every path given is relative: the reports name their sources relative to the working
# directory and record the command in their footer, so nothing kept names a machine path.
set -euo pipefail
cd "$(dirname "$0")/.."
contactlab --no-progress report paper --out reports/paper
contactlab --no-progress report hertz --out reports/hertz   # its result goes to results/hertz/ (not kept)
contactlab --no-progress study error-time --out reports/studies
contactlab --no-progress study stability --out reports/studies
contactlab --no-progress study robustness --out reports/studies
contactlab --no-progress study two-scale --quick --out reports/studies
contactlab --no-progress study coating-winkler --out reports/studies
contactlab --no-progress study coating-fem --out reports/studies
contactlab --no-progress report reports/studies --out reports/validation
if grep -rlE --include="*.md" --include="*.json" "(/tmp/|/home/|/root/|/work/|/Users/)" reports/; then
    echo "regenerate_reports.sh: the files above name machine paths" >&2
    exit 1
fi
