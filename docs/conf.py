"""Sphinx configuration of the contactlab API reference and documentation.

Build (needs the ``docs`` extra): ``python -m sphinx -b html docs docs/_build/html``. The build is
offline (no intersphinx) and its warnings are errors in ``tests/test_sphinx.py``.
"""

import inspect
import re
import sys
import warnings
from pathlib import Path

# the packages of this checkout, whatever is installed
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

project = "contactlab"
author = "the contactlab developers"
copyright = "the contactlab developers, BSD-3-Clause"

extensions = ["sphinx.ext.autodoc", "numpydoc", "myst_parser"]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "examples", "**/__pycache__"]

# autodoc: members in each module's ``__all__``, in source order; signatures without type hints
autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"
# numpydoc: the members are listed by autodoc, not again in a numpydoc table
numpydoc_show_class_members = False
numpydoc_attributes_as_param_list = False
numpydoc_xref_param_type = False
# numpydoc reports a malformed docstring (an unknown section, a wrong underline) as a Python
# warning, which ``-W`` does not see: as an error, autodoc reports it as a warning of the build
warnings.filterwarnings("error", category=UserWarning, module="numpydoc")
# Markdown pages: GitHub's heading anchors (``scenes.md#sweep-folders``)
myst_heading_anchors = 4

html_theme = "alabaster"
html_title = "contactlab"


def _report_links(app, docname, source):
    """Markdown links to files outside ``docs/`` (the generated reports) become file links.

    myst's ``path:`` scheme copies the file into the site, as GitHub shows it beside the page.
    """
    source[0] = re.sub(r"\]\((\.\./[^)#\s]+\.md)\)", r"](path:\1)", source[0])


def _defining_comment(package, name, obj):
    """The ``#:`` comment of ``package.name`` in the submodule that defines it, or ``None``."""
    from sphinx.errors import PycodeError
    from sphinx.pycode import ModuleAnalyzer

    for modname, module in sorted(sys.modules.items()):
        if modname.startswith(package + ".") and getattr(module, name, None) is obj:
            try:
                comment = ModuleAnalyzer.for_module(modname).find_attr_docs().get(("", name))
            except PycodeError:  # a compiled module, no source to read
                continue
            if comment:
                return list(comment)
    return None


def _data_doc(app, what, name, obj, options, lines):
    """The description of a constant: its ``#:`` comment, in the submodule that defines it for a
    package's re-export, and never the docstring of its type (``tuple``, ``str``)."""
    if what == "data":
        package, _, attr = name.rpartition(".")
        comment = _defining_comment(package, attr, obj)
        if comment is not None or " ".join(lines).split() == (inspect.getdoc(type(obj)) or "").split():
            lines[:] = comment or []


def setup(app):
    app.connect("source-read", _report_links)
    app.connect("autodoc-process-docstring", _data_doc, priority=100)
