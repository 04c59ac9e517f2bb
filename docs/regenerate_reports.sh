#!/usr/bin/env bash
# Regenerate every report the repository keeps (about 8 minutes on 2 cores):
#   reports/paper/        the paper's test problem (Fig. 4-11 analogues, validation)
#   reports/hertz/        the built-in Hertz scene: BEM + FEM + closed form
#   reports/studies/      raw study output (error_time.*, stability.*)
#   reports/validation/   the report of the two studies (work-precision plots, stability table)
# Usage, from the repository root:  bash docs/regenerate_reports.sh
set -euo pipefail
cd "$(dirname "$0")/.."
contactlab --no-progress report paper --out reports/paper
contactlab --no-progress report hertz --out /tmp/contactlab-hertz
rm -rf reports/hertz && cp -r /tmp/contactlab-hertz/report reports/hertz
contactlab --no-progress study error-time --out reports/studies
contactlab --no-progress study stability --out reports/studies
contactlab --no-progress report reports/studies --out reports/validation
