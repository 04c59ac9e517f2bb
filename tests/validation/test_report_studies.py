"""The report of the validation studies (error-time and stability JSON files)."""

import json
from pathlib import Path

import html5lib
import numpy as np
import pytest

from bem.checks import InputError
from validation.report.documents.studies import report_studies_dir


def _rows():
    rows = []
    for solver, method, base in (("bem", "newton", 1.0), ("fem", "fem", 3.0)):
        for k, n in enumerate((10, 20, 40)):
            rows.append({"problem": "hertz", "solver": solver, "method": method, "resolution": n, "n": 100 * 4**k,
                         "error_l2": 0.02 / 4**k, "error_peak": 0.01 / 4**k, "wall_time_s": base * 0.01 * 4**k,
                         "iterations": 10, "converged": True, "solver_status": "converged", "relaxation": None,
                         "runs": 3, "message": "KKT residual below rtol"})
    rows.append({**rows[0], "method": "augmented_gap", "relaxation": 0.5, "converged": False,
                 "solver_status": "stalled", "error_l2": 2.0})
    return rows


def _write(tmp_path, error_time=True, stability=True):
    d = tmp_path / "studies"
    d.mkdir()
    if error_time:
        first = {"hertz": {"error_l2": {"0.01": {"solver": "bem", "method": "newton", "resolution": 20,
                                                  "wall_time_s": 0.04}, "0.001": None}}}
        (d / "error_time.json").write_text(json.dumps({"study": "error-time", "rows": _rows(), "first_to_reach": first,
                                                       "references": {"hertz": {"description": "Hertz"}},
                                                       "notes": ["a note"]}))
    if stability:
        rows = [{"case": "root k=1", "solver": "bem", "method": m, "status": s, "kkt_residual": 1e-11,
                 "error_vs_reference": 1e-9, "iterations": 5, "wall_time_s": 0.1, "message": "msg"}
                for m, s in (("newton", "converged"), ("augmented_gap", "reported failure"))]
        (d / "stability.json").write_text(json.dumps({"study": "stability", "rows": rows}))
    return d


def test_study_report_has_plots_tables_and_valid_html(tmp_path):
    built = report_studies_dir(_write(tmp_path), tmp_path / "out")
    html = Path(built.html).read_text(encoding="utf-8")
    html5lib.HTMLParser(strict=True).parse(html)
    assert "http://" not in html and "https://" not in html
    md = Path(built.markdown).read_text(encoding="utf-8")
    assert "Error against run time: hertz" in md and "Stability" in md
    assert "none reached it" in md  # the 0.1 % target nobody met
    assert "reported failure" in md
    from matplotlib.image import imread

    pngs = sorted((tmp_path / "out" / "figures").glob("*.png"))
    assert len(pngs) == 2  # L2 and peak work-precision plots
    for png in pngs:
        assert np.asarray(imread(png)).std() > 0.05


def test_only_present_studies_get_a_section(tmp_path):
    built = report_studies_dir(_write(tmp_path, stability=False), tmp_path / "out")
    md = Path(built.markdown).read_text(encoding="utf-8")
    assert "Error against run time" in md and "## Stability" not in md


def test_a_directory_without_studies_is_refused(tmp_path):
    (tmp_path / "empty").mkdir()
    with pytest.raises(InputError, match="directory"):
        report_studies_dir(tmp_path / "empty", tmp_path / "out")
