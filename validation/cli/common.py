"""What several subcommands share: the ``--set`` option."""

from __future__ import annotations

__all__ = ["add_set"]


def add_set(p, scope=""):
    """Add the repeatable ``--set KEY=VALUE`` scene override to the parser ``p``."""
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help=f"{scope}override a scene key, e.g. bem.nodes_across=20, layer.alpha_a=0.3, "
                        "load.force=250.0 (value parsed as TOML; repeatable)")

