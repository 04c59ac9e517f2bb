"""What several subcommands share: the ``--set`` option and the scene permissions."""

from __future__ import annotations

__all__ = ["add_set", "add_trust", "trust"]


def add_set(p, scope=""):
    """Add the repeatable ``--set KEY=VALUE`` scene override to the parser ``p``."""
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help=f"{scope}override a scene key, e.g. bem.nodes_across=20, layer.alpha_a=0.3, "
                        "load.force=250.0 (value parsed as TOML; repeatable)")



def add_trust(p, *, code=True, scope=""):
    """Add ``--allow-outside-files`` (and ``--allow-code``) to the parser ``p``
    (:mod:`validation.scene.trust`)."""
    if code:
        p.add_argument("--allow-code", action="store_true",
                       help=f"{scope}import and run the Python code the scene names (gap.function, layer.w, ...): "
                            "only for a scene file you trust")
    p.add_argument("--allow-outside-files", action="store_true",
                   help=f"{scope}read files the scene names outside its own folder (absolute names, '..', links)")


def trust(args):
    """The keywords of :func:`validation.scene.load_scene` that ``args`` give (:func:`add_trust`)."""
    return {"allow_code": bool(getattr(args, "allow_code", False)),
            "allow_outside_files": bool(getattr(args, "allow_outside_files", False))}


class ProgressBar:
    """A tqdm bar on stderr drawing the library's ``progress(label, done, total)`` (:mod:`validation.progress`).

    ``disable``: ``True`` draws nothing, ``None`` draws only on a terminal (tqdm's rule).
    """

    def __init__(self, desc, unit, disable):
        from tqdm import tqdm

        self.bar = tqdm(total=1, desc=desc, unit=unit, disable=disable, leave=False)

    def __call__(self, label, done, total):
        self.bar.total = total
        self.bar.n = done
        self.bar.set_description(label)
        self.bar.refresh()

    def close(self):
        self.bar.close()
