"""What several subcommands share: the ``--set`` option, the scene permissions, the progress bar and the
options named in the library's messages."""

from __future__ import annotations

import contextlib
import re

from bem.checks import InputError

__all__ = ["add_set", "add_trust", "trust", "option_names"]


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


@contextlib.contextmanager
def option_names(names):
    """Name the command's options in the library's messages.

    ``names`` maps a library argument to the option the user wrote (``{"E_star": "--E-star"}``;
    an entry of a pair as ``"physical_sizes[1]": "--size LY"``). An :class:`InputError` whose
    message begins with such an argument (the form of :mod:`bem.checks`: ``"E_star = -1.0 is not
    allowed: ..."``, ``"physical_sizes is missing: ..."``) is raised again beginning with the option.
    """
    try:
        yield
    except InputError as exc:
        msg = str(exc)
        for argument in sorted(names, key=len, reverse=True):  # "x[0]" before "x"
            if re.match(re.escape(argument) + r"(?= |\[)", msg):
                raise InputError(names[argument] + msg[len(argument):]) from None
        raise


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
