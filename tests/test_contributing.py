"""CONTRIBUTING.md runs: every Python snippet is executed and does what the page says, and every
module, name and file it points to exists."""

import importlib
import json
import math
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

import bem
from bem.layers import LAWS, from_dict

from .validation.figure_spy import drawn, lines_of  # noqa: F401 - drawn is a fixture

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "CONTRIBUTING.md"
#: what the page tells a contributor to create: the examples' own files and names
NEW = {"bem/layers/log.py", "bem/my_method.py", "bem/gaps/my_shape.py", "bem.layers.Log",
       "tests/test_contributing.py"}


def _snippets():
    """The ```python blocks of the page, in order."""
    return re.findall(r"```python\n(.*?)```", PAGE.read_text(encoding="utf-8"), re.S)


def _run(code):
    """The names a snippet defines, executed in a namespace of its own."""
    space = {"__name__": "contributing_snippet"}
    exec(compile(code, str(PAGE), "exec"), space)
    return space


def _defining(name):
    """The namespace of the one snippet that defines ``name``."""
    found = [space for space in map(_run, _snippets()) if name in space]
    assert len(found) == 1, f"CONTRIBUTING.md: {len(found)} snippets define {name!r}"
    return found[0]


def test_every_snippet_runs():
    snippets = _snippets()
    assert len(snippets) >= 3  # a layer law, a report section, a figure
    for code in snippets:
        _run(code)


# ---------------------------------------------------------------------------------- the layer law

def test_the_layer_law_of_the_page_meets_the_identities_of_a_law():
    Log = _defining("Log")["Log"]
    law = Log(2.0, 3.0)
    p = np.array([0.0, 0.1, 1.0, 5.0, 40.0])
    assert np.allclose(law.w(p), 2.0 * np.log(1.0 + p / 3.0))  # written out here, not by the law
    h = 1e-6
    assert np.allclose((law.energy(p + h) - law.energy(p)) / h, law.w(p + h / 2), rtol=1e-6, atol=1e-9)
    assert np.allclose((law.w(p + h) - law.w(p)) / h, law.dw(p + h / 2), rtol=1e-6)
    assert np.allclose(law.inverse(law.w(p)), p, rtol=1e-12, atol=1e-12)
    assert law.w(-1.0) == 0.0 and law.inverse(-1.0) == 0.0
    with pytest.raises(bem.InputError, match="p0 = -1"):
        Log(1.0, -1)


@pytest.fixture
def log_law(monkeypatch):
    """The page's law, registered in ``bem.layers.LAWS`` as the page says."""
    Log = _defining("Log")["Log"]
    monkeypatch.setitem(LAWS, "log", Log)
    return Log


def test_a_registered_law_is_a_scene_law_solved_by_both_solvers(log_law):
    from validation.run import execute_scene

    assert from_dict({"law": "log", "lam": 1e-7, "p0": 1e8}).to_dict() == {"law": "log", "lam": 1e-7, "p0": 1e8}
    scene = {"scene": {"name": "log", "title": "a sphere on a flat with the page's logarithmic layer"},
             "bodies": {"E1": 210e9, "nu1": 0.3, "E2": 210e9, "nu2": 0.3},
             "gap": {"type": "paraboloid", "R": 0.01}, "layer": {"law": "log", "lam": 1e-7, "p0": 1e8},
             "load": {"force": 100.0}, "bem": {"nodes_across": 16}, "fem": {"n_contact_elements": 8}}
    out = execute_scene(scene)
    assert isinstance(out.layer, log_law) and out.result.layer["parameters"]["law"] == "log"
    assert out.bem.converged and out.fem.converged
    assert out.bem.p_max == pytest.approx(out.fem.p_max, rel=0.02)  # measured: 0.2 %
    assert np.allclose(out.bem.closure, 1e-7 * np.log1p(out.bem.p / 1e8))


# ------------------------------------------------------------------- the report section and figure

@pytest.fixture(scope="module")
def linear_dir(tmp_path_factory):
    """A small run with a layer (its closure profile), written as ``contactlab run`` writes it."""
    from validation.run import run_scene

    out = tmp_path_factory.mktemp("contributing") / "paper_linear"
    run_scene("paper_linear", out, overrides=["bem.nodes_across=12", "fem.n_contact_elements=8"])
    return out


def test_the_section_of_the_page_shows_the_mean_pressure(linear_dir, tmp_path, monkeypatch):
    from validation.report import SECTIONS, report_results_dir
    from validation.report.documents.results import load_results
    from validation.report.render import fmt

    section = _defining("mean_pressure")["mean_pressure"]
    data = json.loads((linear_dir / "result.json").read_text())
    p_mean = data["force"] / data["contact_area"]  # [Pa]; an SI scene's report shows MPa
    rows = {row[0]: row[1:] for row in section(load_results(linear_dir), tmp_path).items[0].rows}
    assert rows["mean pressure P / A"] == (fmt(p_mean / 1e6), "MPa")
    assert rows["peak over mean, p_max / (P / A)"] == (fmt(data["p_max"] / p_mean), "-")
    monkeypatch.setitem(SECTIONS, "mean_pressure", section)  # the page's one registry line
    run = tmp_path / "run"
    shutil.copytree(linear_dir, run)
    data["report"] = {"sections": ["summary", "mean_pressure"], "format": "html"}  # a scene's [report]
    (run / "result.json").write_text(json.dumps(data))
    built = report_results_dir(run, tmp_path / "report")
    html = built.html.read_text(encoding="utf-8")
    assert re.findall(r"<h2>(.*?)</h2>", html) == ["Results", "Mean contact pressure"]
    assert fmt(p_mean / 1e6) in html


def test_the_figure_of_the_page_draws_the_closure_of_the_result(linear_dir, tmp_path, drawn):  # noqa: F811
    from validation.report.documents.results import load_results

    closure = _defining("closure")["closure"]
    res = load_results(linear_dir)
    figure = closure(res, tmp_path)
    assert Path(figure.path).is_file()
    data = json.loads((linear_dir / "result.json").read_text())["profile"]
    (x, w), = lines_of(drawn[-1].axes[0]).values()
    top = max(data["closure"])
    factor = 10.0 ** (3 * math.floor(math.log10(top) / 3))  # the SI prefix that shows it in [1, 1000)
    assert np.allclose(w, np.asarray(data["closure"]) / factor) and 1.0 <= max(w) < 1000.0
    assert len(x) == len(data["x"])


# ------------------------------------------------------------------------- what the page names

def _resolves(name):
    from validation.scene.schema import scene_keys

    parts = name.split(".")
    if len(parts) == 2 and parts[1] in scene_keys().get(parts[0], {}).get("", ()):
        return True  # a scene key (bem.step)
    for n in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:n]))
        except ImportError:
            continue
        for attr in parts[n:]:
            if not hasattr(obj, attr):
                return False
            obj = getattr(obj, attr)
        return True
    return False


def test_every_module_name_and_file_the_page_names_exists():
    text = PAGE.read_text(encoding="utf-8")
    spans = set(re.findall(r"`([^`\n]+)`", text))
    names = {s for s in spans if re.fullmatch(r"(bem|validation|fem_reference)(\.\w+)+", s)}
    paths = {s for s in spans if re.fullmatch(r"[\w./-]+/[\w.-]+\.(py|md|toml)", s)}
    assert len(names) > 20 and len(paths) > 20
    missing = sorted(n for n in names - NEW if not _resolves(n))
    assert not missing, f"CONTRIBUTING.md names what does not exist: {missing}"
    absent = sorted(p for p in paths - NEW if not (ROOT / p).exists())
    assert not absent, f"CONTRIBUTING.md points to files that do not exist: {absent}"
