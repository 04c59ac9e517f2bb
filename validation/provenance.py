"""Provenance: what made a result or a report, recorded without machine paths.

:func:`provenance` is the ``provenance`` block of every ``result.json`` and the source of
every report footer (:func:`report_footer`)::

    {"contactlab": "0.1.0",
     "git": {"commit": "5db9e6a...", "dirty": false},      # null when not run from a git checkout
     "python": "3.11.7",
     "packages": {"numpy": "2.4.6", "scipy": "1.17.1", "meshio": "5.3.5",  # always
                  "gmsh": "4.15.2", "skfem": "12.0.2", ...},              # those this run loaded
     "platform": "Linux x86_64",
     "command": "contactlab run hertz --out results/hertz"}

Nothing kept names a machine path: :func:`display_path` writes a path relative to the
working directory when it lies inside it, else only its last two components
(``.../contactlab-hertz/result``); the command line goes through it token by token.
"""

from __future__ import annotations

import functools
import logging
import os
import platform
import subprocess
import sys
import time
from importlib import metadata
from pathlib import Path, PurePosixPath, PureWindowsPath

__all__ = ["provenance", "report_footer", "describe", "display_path", "command_line", "git_state",
           "OPTIONAL_PACKAGES"]

log = logging.getLogger(__name__)

#: module name -> distribution name of packages recorded when a run has loaded them
OPTIONAL_PACKAGES = {"gmsh": "gmsh", "skfem": "scikit-fem", "matplotlib": "matplotlib",
                     "PIL": "pillow", "dask": "dask", "distributed": "distributed", "cupy": "cupy-cuda12x",
                     "array_api_compat": "array-api-compat"}
_ROOT = Path(__file__).resolve().parents[1]  # the directory holding the packages


def _is_absolute(text):
    return PurePosixPath(text).is_absolute() or PureWindowsPath(text).is_absolute()


def display_path(path):
    """A path as it may appear in a kept file: never an absolute machine path.

    Parameters
    ----------
    path : path-like

    Returns
    -------
    str
        A relative path is returned as given (POSIX separators); an absolute one relative to
        the working directory when it lies inside it, else ``.../<parent>/<name>``.
    """
    text = os.fspath(path)
    if not _is_absolute(text):
        return Path(text).as_posix()
    p = Path(text)
    try:
        return p.resolve().relative_to(Path.cwd().resolve()).as_posix() or "."
    except ValueError:
        names = [part for part in p.parts if part not in (p.anchor, "")]
        return "/".join(["...", *names[-2:]])


def _display_token(token):
    if "=" in token and token.startswith("-"):
        key, value = token.split("=", 1)
        return f"{key}={_display_token(value)}"
    return display_path(token) if _is_absolute(token) else token


def command_line(argv=None, orig_argv=None):
    """The command that is running, without machine paths.

    Parameters
    ----------
    argv, orig_argv : list of str, optional
        Default :data:`sys.argv` and :data:`sys.orig_argv`.

    Returns
    -------
    str
        E.g. ``contactlab run hertz --out results/hertz`` or ``python -m validation.cli run
        hertz``; an interactive session gives ``python``.
    """
    argv = list(sys.argv if argv is None else argv)
    orig = list(getattr(sys, "orig_argv", []) if orig_argv is None else orig_argv)
    # the interpreter's own options come before the tokens that became sys.argv
    same = argv and len(orig) > len(argv) and orig[len(orig) - len(argv) + 1:] == argv[1:]
    head = orig[:len(orig) - len(argv) + 1] if same else []
    if len(head) >= 3 and head[-2] == "-m":
        prog = ["python", "-m", head[-1]]
    elif len(head) >= 3 and head[-2] == "-c":
        prog = ["python", "-c", "..."]
    elif argv and argv[0]:
        name = Path(argv[0]).name
        prog = ["python", name] if name.endswith(".py") else [name]
    else:
        prog = ["python"]
    return " ".join(prog + [_display_token(a) for a in argv[1:]])


@functools.lru_cache(maxsize=1)
def git_state():
    """``{"commit": sha, "dirty": bool}`` of the checkout the packages run from, or None.

    None when the packages are not in a git work tree (an installed wheel) or git is not
    available. ``dirty``: tracked files differ from the commit.
    """
    if not (_ROOT / ".git").exists():
        return None
    env = {k: v for k, v in os.environ.items() if not k.startswith("GIT_")}
    try:
        def git(*args):
            return subprocess.run(["git", "-C", str(_ROOT), *args], capture_output=True, text=True, timeout=10,
                                  env=env, check=True).stdout.strip()

        commit = git("rev-parse", "HEAD")
        dirty = bool(git("status", "--porcelain", "--untracked-files=no"))
    except (OSError, subprocess.SubprocessError) as exc:
        log.debug("no git provenance: %s", exc)
        return None
    return {"commit": commit, "dirty": dirty}


def _version(dist):
    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return None


def provenance(argv=None):
    """The provenance block of a result (see the module docstring).

    Parameters
    ----------
    argv : list of str, optional
        Command line to record (default :data:`sys.argv`).

    Returns
    -------
    dict
        JSON-ready.
    """
    import numpy
    import scipy

    packages = {"numpy": numpy.__version__, "scipy": scipy.__version__, "meshio": _version("meshio")}
    for module, dist in OPTIONAL_PACKAGES.items():
        if sys.modules.get(module) is not None:
            packages[module if module != "PIL" else "pillow"] = _version(dist) or getattr(
                sys.modules[module], "__version__", "unknown")
    return {
        "contactlab": _version("contactlab") or "unknown",
        "git": git_state(),
        "python": platform.python_version(),
        "packages": packages,
        "platform": f"{platform.system()} {platform.machine()}",
        "command": command_line(argv),
    }


def describe(prov):
    """One line naming a provenance block: version, commit, Python, packages, command.

    Parameters
    ----------
    prov : dict
        From :func:`provenance` (or a ``result.json``).

    Returns
    -------
    str
        E.g. ``contactlab 0.1.0 (git 5db9e6a, modified), Python 3.11.7, numpy 2.4.6, scipy
        1.17.1; command: contactlab report paper``.
    """
    git = prov.get("git")
    where = f" (git {git['commit'][:7]}{', modified' if git.get('dirty') else ''})" if git else ""
    packages = ", ".join(f"{name} {version}" for name, version in prov.get("packages", {}).items())
    return (f"contactlab {prov.get('contactlab', 'unknown')}{where}, Python {prov.get('python', '?')}, "
            f"{packages}; command: {prov.get('command', '?')}")


def report_footer(prov=None, *, when=None):
    """The footer of a report: ``Generated on <date> by <describe(prov)>.``

    Parameters
    ----------
    prov : dict, optional
        Default: :func:`provenance` of the running process.
    when : str, optional
        Date text; default the local time ``YYYY-MM-DD HH:MM``.
    """
    prov = provenance() if prov is None else prov
    when = time.strftime("%Y-%m-%d %H:%M") if when is None else when
    return f"Generated on {when} by {describe(prov)}."
