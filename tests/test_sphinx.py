"""The documentation site (docs/conf.py): it builds with warnings as errors, and a bad docstring stops it.

Each build runs ``python -m sphinx`` in a subprocess (the ``docs`` extra), offline.
"""

import html
import importlib
import os
import re
import shutil
import subprocess
import sys
import textwrap
import types
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
#: the modules of the API reference (docs/api/)
DOCUMENTED = ("bem", "bem.options", "bem.checks", "bem.files", "bem.fft", "bem.backend", "bem.gaps", "bem.layers",
              "bem.periodic", "bem.rough", "bem.reference", "fem_reference", "validation.scene", "validation.run",
              "validation.run.parts",
              "validation.compare", "validation.io", "validation.extras", "validation.units", "validation.labels",
              "validation.provenance",
              "validation.studies", "validation.layer_law", "validation.report")


def _build(source, out, env=None):
    """``sphinx -W --keep-going -b html`` of ``source`` into ``out``: the completed process."""
    return subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-j", "1", "-b", "html", "-q",
                           str(source), str(out)], capture_output=True, text=True, cwd=ROOT, env=env, timeout=600)


def _text(page):
    """The visible text of an HTML page."""
    return html.unescape(re.sub(r"<[^>]+>", "", page.read_text(encoding="utf-8")))


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("site")
    done = _build(DOCS, out)
    assert done.returncode == 0, done.stdout + done.stderr
    return out


def test_site_builds_without_warnings(site):
    assert (site / "index.html").is_file()
    for page in ("method", "scenes", "results", "rough", "install", "performance", "verification", "examples"):
        assert (site / f"{page}.html").is_file(), page


def test_api_pages_document_the_public_names(site):
    bem = _text(site / "api" / "bem.html")
    solve = bem[bem.index("bem.solve("):]
    assert "rtol" in solve and "Tolerance on the KKT residual" in solve
    assert "Parameters" in solve and "Returns" in solve
    assert "bem.layers.Root" in _text(site / "api" / "bem.layers.html")
    assert "bem.periodic.solve_periodic" in _text(site / "api" / "bem.periodic.html")
    assert "fem_reference.solve" in _text(site / "api" / "fem_reference.html")
    assert "validation.scene.load_scene" in _text(site / "api" / "validation.html")


def test_every_public_name_has_an_entry(site):
    """Each name in the ``__all__`` of a documented module has an entry, there or in another
    documented module that holds the same object (``bem.solve_periodic`` under :mod:`bem.periodic`)."""
    ids = set()
    for page in (site / "api").glob("*.html"):
        ids |= set(re.findall(r'id="([^"]+)"', page.read_text(encoding="utf-8")))
    modules = {name: importlib.import_module(name) for name in DOCUMENTED}
    missing = []
    for name, module in modules.items():
        for attr in module.__all__:
            obj = getattr(module, attr)
            if isinstance(obj, types.ModuleType):
                found = f"module-{obj.__name__}" in ids
            else:
                found = any(f"{other}.{attr}" in ids and getattr(modules[other], attr, None) is obj
                            for other in modules)
            if not found:
                missing.append(f"{name}.{attr}")
    assert not missing, f"no entry in the API reference (docs/api/) for {missing}"


def test_examples_page_shows_the_scripts(site):
    text = _text(site / "examples.html")
    for script in sorted((DOCS / "examples").glob("*.py")):
        first = script.read_text(encoding="utf-8").splitlines()[0].strip('"')
        assert first in text, script.name


def test_markdown_links_resolve(site):
    """A link between pages reaches the page; a link to a report outside docs/ is a copied file."""
    page = (site / "verification.html").read_text(encoding="utf-8")
    assert 'href="performance.html"' in page
    downloads = re.findall(r'href="(_downloads/[^"]+\.md)"', page)
    assert downloads
    for link in downloads:
        assert (site / link).is_file(), link


def _planted(tmp_path, docstring):
    """Build a one-function project with docs/conf.py; ``docstring`` follows the summary line."""
    body = textwrap.indent(docstring, "    ")
    (tmp_path / "planted.py").write_text(f'def f(x):\n    """One line.\n\n{body}\n    """\n')
    source = tmp_path / "docs"
    source.mkdir()
    shutil.copy(DOCS / "conf.py", source / "conf.py")
    (source / "index.rst").write_text("planted\n=======\n\n.. automodule:: planted\n   :members:\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])}
    return _build(source, tmp_path / "out", env=env)


PARAMETERS = "Parameters\n----------\nx : float\n    A length [m].\n\n"


@pytest.mark.parametrize("section", ["Note\n----\nAn unknown section.", "Returns\n-----\nfloat"],
                         ids=["unknown-section", "short-underline"])
def test_malformed_numpydoc_docstring_fails_the_build(tmp_path, section):
    done = _planted(tmp_path, PARAMETERS + section)
    assert done.returncode != 0
    assert "planted" in done.stderr


def test_wellformed_docstring_builds(tmp_path):
    """The control of the test above: the same project with a correct section builds."""
    done = _planted(tmp_path, PARAMETERS + "Returns\n-------\nfloat")
    assert done.returncode == 0, done.stdout + done.stderr
