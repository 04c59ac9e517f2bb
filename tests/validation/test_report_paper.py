"""The paper report (quick version): every figure, valid offline HTML, and the trends the paper
describes (section 6) checked on the cases, run as scenes by the runner."""

import logging
import math
import re

import numpy as np
import pytest

from validation.report import command
from validation.report.documents.paper import TITLE, paper_sections
from validation.studies.paper_problem import run_paper_problem
from validation.report.render import build_report
from validation.report.render.content import Figure

from .test_report_build import PNG_MAGIC, assert_valid_offline_html, figure_sources
from .test_report_figures import check_png


class _Collect(logging.Handler):
    """Keeps the messages of the records it is given."""

    def __init__(self):
        super().__init__(logging.WARNING)
        self.messages = []

    def emit(self, record):
        self.messages.append(record.getMessage())


@pytest.fixture(scope="module")
def paper_run():
    """The quick paper problem, the stages it reported (in order) and the solver's warnings meanwhile."""
    stages, handler, logger = [], _Collect(), logging.getLogger("bem")
    logger.addHandler(handler)
    try:
        return run_paper_problem(quick=True, progress=lambda *a: stages.append(a)), stages, handler.messages
    finally:
        logger.removeHandler(handler)


@pytest.fixture(scope="module")
def paper(paper_run):
    return paper_run[0]


@pytest.fixture(scope="module")
def sections(paper, tmp_path_factory):
    return paper_sections(paper, tmp_path_factory.mktemp("work"))


@pytest.fixture(scope="module")
def report(sections, tmp_path_factory):
    return build_report(sections, tmp_path_factory.mktemp("out") / "paper", title=TITLE)


def _figures(sections, *, fem=True):
    return [item for s in sections if fem or s.kind != "fem" for item in s.items if isinstance(item, Figure)]


def test_paper_report_files(report, sections):
    from PIL import Image

    text = report.html.read_text(encoding="utf-8")
    assert_valid_offline_html(text)
    figures = _figures(sections)
    analogues = {int(n) for f in figures for n in re.findall(r"analogue of (?:the paper's )?Fig\. (\d+)", f.caption)}
    assert analogues == set(range(4, 12))  # every figure of the paper's section 6 has its analogue
    assert any(s.kind == "fem" and _figures([s]) for s in sections)
    # every figure drawn is in the report once: a file of its own, which the HTML shows
    assert len(set(report.figures)) == len(report.figures) == len(figures)
    assert [report.out_dir / src for src in figure_sources(text)] == list(report.figures)
    for path in report.figures:
        assert path.read_bytes().startswith(PNG_MAGIC)
        check_png(path)
        with Image.open(path) as img:
            assert img.mode == "P"  # saved as a palette image (save_figure's colors=256)
    for kind in ("problem", "results", "iterations", "sweeps", "stability", "fem"):
        assert f'class="kind-{kind}"' in text
    md = report.markdown.read_text(encoding="utf-8")
    for link in re.findall(r"!\[[^\]]*\]\(([^)]+)\)", md):
        assert (report.out_dir / link).is_file()


def test_paper_report_without_fem_has_no_fem_section(paper, sections, tmp_path):
    import dataclasses

    bem_only = dataclasses.replace(paper, validation={}, work_precision=[])
    without = paper_sections(bem_only, tmp_path / "w")
    built = build_report(without, tmp_path / "out", title=TITLE)
    text = built.html.read_text(encoding="utf-8")
    assert "kind-fem" not in text and "FEM reference" not in text
    # the same figures as the full report, less those of its FEM section
    assert [f.caption for f in _figures(without)] == [f.caption for f in _figures(sections, fem=False)]
    assert len(built.figures) == len(_figures(without))


def test_paper_trends(paper):
    """Section 6 of the paper: alpha_a moves the distribution from smooth to linear, region I
    shrinks as alpha_a grows, the root law lowers the peak as it softens, alpha_c -> 0 is the
    elastic-rigid law and alpha_c growing lowers the peak."""
    from validation.report.figures import profiles as fpr
    from validation.report.figures import sweeps as fsw

    p_lin, p0 = paper.p_lin, paper.p0
    alphas = [al for al, _ in paper.sweep_a]
    assert alphas[0] == 0.0 and alphas[-1] == 1.0
    peaks = [r.p_max for _, r in paper.sweep_a]
    assert np.all(np.diff(peaks) < 0) and peaks[0] == pytest.approx(paper.base["smooth"].p_max)
    r_tr = [fsw.transition_radius(*fpr.section_of(r), al * p_lin) for al, r in paper.sweep_a[1:]]
    assert np.all(np.diff(r_tr) < 0) and r_tr[-1] < 0.2 * paper.a
    radii = [r.contact_radius for _, r in paper.sweep_a]
    assert np.all(np.diff(radii) >= 0)
    ab = [ab for _, ab, _ in paper.sweep_b]
    assert np.all(np.diff(ab) < 0)  # softer root layer (larger lam_b): lower peak
    # alpha_c = 0: the bilinear law with lam2 = 0 is the elastic-rigid law (two independent classes)
    t0, r0 = paper.sweep_c[0]
    assert t0 == 0.0
    np.testing.assert_allclose(r0.p, paper.sweep_a[alphas.index(0.5)][1].p, atol=1e-6 * p0)
    pc = [r.p_max for _, r in paper.sweep_c]
    assert np.all(np.diff(pc) < 0)
    # alpha_c = pi/4: lam2 = lam1, the linear layer
    r45 = dict(paper.sweep_c)[math.pi / 4]
    np.testing.assert_allclose(r45.p, paper.base["linear Winkler"].p, atol=1e-6 * p0)


def test_quick_paper_report_solves_the_scenes_problem_on_a_coarser_lattice(paper):
    """The layer is the scenes' physical compliance on the quick lattice a_H/8 as on the full one, so
    the quick report differs from the full one by the discretisation only: its p_max^lambda is within
    0.2 % of the one at 40 nodes across (measured 0.8144 p0 against 0.8134 p0)."""
    from validation.run import execute_scene
    from validation.scene import load_scene
    from validation.scene.paper import c_nn

    scene = load_scene("paper_linear")
    lam = scene.layer.lam
    assert paper.laws["linear Winkler"].lam == lam and paper.laws["elastic-rigid"].lam == lam
    assert paper.lam_over_cnn == pytest.approx(lam / c_nn(paper.a / 8, scene.E_star), rel=1e-12)
    raw = {k: v for k, v in scene.raw.items() if k not in ("fem", "report")}
    fine = execute_scene(raw, overrides={"bem.nodes_across": 40}).bem
    assert paper.p_lin == pytest.approx(fine.p_max, rel=2e-3)


def test_paper_methods_and_validation(paper):
    newton = [r for r in paper.stability if r["method"] == "Newton"]
    assert newton and all(r["status"] == "converged" for r in newton)
    conv = [r for r in paper.stability if r["status"] == "converged"]
    for row in conv:  # every converged method agrees with Newton on the same law
        ref = next(r for r in newton if r["law"] == row["law"])
        assert row["p_max/p0"] == pytest.approx(ref["p_max/p0"], rel=1e-4)
    for label, (b, f) in paper.fem.items():
        assert f.converged and b.p_max == pytest.approx(f.p_max, rel=0.01), label
    bem_err = [r["error"] for r in paper.work_precision if r["solver"] == "BEM"]
    fem_err = [r["error"] for r in paper.work_precision if r["solver"] == "FEM"]
    assert bem_err[-1] < bem_err[0] and fem_err[-1] < fem_err[0]


def test_expected_augmented_gap_stalls_are_one_note_not_bare_warnings(paper_run, report):
    from validation.report.documents.paper import expected_stalls

    paper, _stages, solver_warnings = paper_run

    stalled = [r for r in paper.stability if r["method"].startswith("augmented gap") and r["status"] != "converged"]
    assert stalled, "the quick paper problem stalls the augmented gap method (its documented behaviour)"
    assert not [m for m in solver_warnings if m.startswith("augmented_gap")]
    (note,) = expected_stalls(paper)
    assert "expected, documented behaviour of the augmented gap method" in note
    assert f"in {len(stalled)} of its" in note and all(r["law"] in note for r in stalled)
    anchor = re.search(r"report\.html#([a-z-]+)", note).group(1)
    assert f'id="{anchor}"' in report.html.read_text(encoding="utf-8")


def test_report_command_prints_the_notes(monkeypatch, tmp_path):
    from validation.report.render import BuiltReport

    from .conftest import cli

    built = BuiltReport(tmp_path, tmp_path / "report.html", tmp_path / "report.md", (), notes=("stall expected",))
    monkeypatch.setattr(command, "build", lambda target, **kw: built)
    code, out, err = cli("report", "paper", "--out", tmp_path)
    assert code == 0 and "note: stall expected" in out.splitlines() and err == ""


def test_scikit_fem_info_lines_only_when_verbose(monkeypatch, tmp_path):
    from validation.report.render import BuiltReport

    from .conftest import cli

    def build(target, **kw):
        logging.getLogger("skfem.assembly").info("assembling a form")
        logging.getLogger("skfem.assembly").warning("a real problem")
        return BuiltReport(tmp_path, tmp_path / "report.html", tmp_path / "report.md", ())

    monkeypatch.setattr(command, "build", build)
    _code, _out, err = cli("report", "paper", "--out", tmp_path)
    assert "a real problem" in err and "assembling" not in err
    _code, _out, err = cli("-v", "report", "paper", "--out", tmp_path)
    assert "a real problem" in err and "assembling" in err


def test_main_dispatches_paper(monkeypatch, tmp_path):
    calls = []

    def fake(out, *, quick, fmt="png", progress=None):
        calls.append((str(out), quick, fmt))

        class Built:
            html = markdown = out
            figures = ()

        return Built()

    monkeypatch.setattr("validation.report.documents.paper.report_paper_problem", fake)
    command.main("paper", out=str(tmp_path), quick=True)
    command.main("paper", fmt="pdf")
    assert calls == [(str(tmp_path), True, "png"), (str(command.DEFAULT_PAPER_OUT), False, "pdf")]


def test_example_script_passes_its_options(monkeypatch, tmp_path):
    import runpy
    from pathlib import Path

    calls = []

    def fake(out, *, quick, fem):
        calls.append((out, quick, fem))

        class Built:
            html = markdown = out_dir = Path(out)
            figures = ()

        return Built()

    monkeypatch.setattr("validation.report.report_paper_problem", fake)
    script = Path(__file__).parents[2] / "docs" / "examples" / "paper_report.py"
    ns = runpy.run_path(str(script), run_name="example")
    levels = {name: logging.getLogger(name).level for name in ("bem", "fem_reference", "validation", "skfem")}
    try:
        assert ns["main"](["--out", str(tmp_path), "--quick", "--no-fem"]) == 0
        assert logging.getLogger("skfem").getEffectiveLevel() == logging.WARNING
        assert ns["main"](["--out", str(tmp_path), "--verbose"]) == 0
        assert logging.getLogger("skfem").getEffectiveLevel() == logging.INFO
    finally:
        for name, level in levels.items():
            logging.getLogger(name).setLevel(level)
    assert calls == [(str(tmp_path), True, False), (str(tmp_path), False, True)]


def test_paper_report_tells_its_stages(paper_run, monkeypatch, tmp_path):
    from validation.report.documents import paper as paper_report
    from validation.studies.paper_problem import SOLVE_STAGES
    from validation.report.render import Section

    paper, stages, _warnings = paper_run
    n = len(SOLVE_STAGES)  # the real runs, in order, told as every job of the library tells its progress
    assert stages == [(s, k, n) for k, s in enumerate(SOLVE_STAGES)] + [("done", n, n)]

    def fake_solve(*, quick, fem, progress):
        for stage in SOLVE_STAGES[:3 + fem]:
            progress(stage)
        return paper

    monkeypatch.setattr(paper_report, "run_paper_problem", fake_solve)
    monkeypatch.setattr(paper_report, "paper_sections", lambda res, work: [Section("x", text="y")])
    for fem, stages in ((True, paper_report.STAGES), (False, [s for s in paper_report.STAGES if "FEM" not in s])):
        calls = []
        paper_report.report_paper_problem(tmp_path / f"p{fem}", quick=True, fem=fem,
                                          progress=lambda *a: calls.append(a))
        n = len(stages)
        assert calls == [(s, k, n) for k, s in enumerate(stages)] + [("done", n, n)]


def test_paper_stresses_every_layer_lowers_the_subsurface_maximum(paper):
    """Smooth: Hertz's 0.62 p0 at 0.48 a_H; every law of Fig. 5 lowers the maximum at the same force."""
    st = paper.stress
    assert set(st) == set(paper.laws)
    smooth = st["smooth"]
    assert smooth.max_von_mises / paper.p0 == pytest.approx(0.620, rel=0.01)
    assert smooth.depth_of_max / paper.a == pytest.approx(0.481, abs=0.02)
    for label, s in st.items():
        if label != "smooth":
            assert s.max_von_mises < smooth.max_von_mises, label
    # the linear and root layers flatten the pressure most: the maximum moves deeper
    assert st["linear Winkler"].depth_of_max > smooth.depth_of_max
    assert st["root"].depth_of_max > smooth.depth_of_max


def test_quick_report_is_marked_a_coarse_preview(paper, monkeypatch, tmp_path):
    from validation.report.documents import paper as paper_report
    from validation.report.render import Section

    monkeypatch.setattr(paper_report, "run_paper_problem", lambda *, quick, fem, progress: paper)
    monkeypatch.setattr(paper_report, "paper_sections", lambda res, work: [Section("x", text="y")])
    for quick in (True, False):
        built = paper_report.report_paper_problem(tmp_path / f"q{quick}", quick=quick)
        heading = re.search(r"<h1>(.*?)</h1>", built.html.read_text(encoding="utf-8")).group(1)
        title = re.search(r"<title>(.*?)</title>", built.html.read_text(encoding="utf-8")).group(1)
        md_heading = built.markdown.read_text(encoding="utf-8").splitlines()[0]
        for text in (heading, title, md_heading):
            assert ("COARSE PREVIEW" in text) == quick, text


def test_one_name_for_the_hertz_peak(report):
    """The paper report calls Hertz's peak p_0 in its text, tables and figures (no p_H, no p0)."""
    for text in (report.markdown.read_text(encoding="utf-8"), report.html.read_text(encoding="utf-8")):
        assert "p_0" in text and "p_H" not in text and not re.search(r"(?<![\w.])p0\b", text)
    assert "Normalised by Hertz's peak p_0" in report.markdown.read_text(encoding="utf-8")


def test_the_paper_study_takes_the_scenes_override_syntax():
    """Its cases take dotted keys and the short names of ``--set``; a wrong key is named as a scene names it."""
    from validation.scene import SceneError
    from validation.studies.paper_problem import CaseRunner

    run = CaseRunner(6)
    short = run("elastic-rigid", {"alpha_a": 0.3}).result
    dotted = run("elastic-rigid", {"layer.alpha_a": 0.3}).result
    assert short.layer["alpha_a"] == dotted.layer["alpha_a"] == 0.3
    assert short.p_max == dotted.p_max and short.layer["parameters"] == dotted.layer["parameters"]
    with pytest.raises(SceneError, match="bem.methd"):
        run("smooth", {"bem.methd": "newton"})
