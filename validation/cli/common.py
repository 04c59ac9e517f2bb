"""What several subcommands share: the ``--set`` option and optional imports."""

from __future__ import annotations

import importlib
import sys

__all__ = ["add_set", "optional_import"]


def add_set(p, scope=""):
    """Add the repeatable ``--set KEY=VALUE`` scene override to the parser ``p``."""
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help=f"{scope}override a scene key, e.g. bem.nodes_across=20, layer.alpha_a=0.3, "
                        "load.force=250.0 (value parsed as TOML; repeatable)")


def optional_import(module, what):
    """``module`` imported, or ``None`` after saying on stderr that it is not installed."""
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name is not None and module.startswith(exc.name):
            print(f"contactlab: error: {what} is not available in this installation ({module} is missing).",
                  file=sys.stderr)
            return None
        raise
