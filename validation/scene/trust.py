"""What a scene file may make contactlab do beyond reading numbers: import code, open files.

A scene file is data, possibly downloaded. Two things in it reach beyond the file itself and
are refused unless the user opts in:

- **Python code**: a ``"module:function"`` string in ``gap.function`` (``type = "callable"``)
  or in ``layer.w``, ``layer.dw``, ``layer.energy``, ``layer.inverse`` (``law = "custom"``,
  also nested in a series, ``layer.a.w``). Importing a module runs it. Only
  ``load_scene(..., allow_code=True)`` or ``contactlab run/sweep/report --allow-code`` import
  it; ``contactlab check`` checks the form of the name and never imports it.
- **Files outside the scene's folder**: ``gap.file`` of a measured surface (and ``layer.file`` of a
  tabulated law, :mod:`validation.scene.layer_file`) is a name relative
  to the scene file's folder (to the current directory for a scene given as a dict). A name
  that leads out of that folder (an absolute name elsewhere, ``..``, a symbolic link pointing
  outside) is refused unless ``allow_outside_files=True`` (``--allow-outside-files``).

A callable object (not a string) given in a scene dict through the Python API is the caller's
own code, not a name to import: it is always accepted.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from pathlib import Path

from bem.checks import check_file_name

from . import checks as ck
from .checks import SceneError

__all__ = ["code_names", "check_code_name", "refuse_code", "scene_file", "CODE_FLAG", "FILES_FLAG"]

CODE_FLAG = "--allow-code"
FILES_FLAG = "--allow-outside-files"
_LAW_CODE_KEYS = ("w", "dw", "energy", "inverse")
_DOTTED = r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*"
_NAME = re.compile(f"^{_DOTTED}:{_DOTTED}$")


def _layer_names(d, path):
    if not isinstance(d, Mapping):
        return []
    out = []
    if d.get("law") == "custom":
        out += [(f"{path}.{k}", d[k]) for k in _LAW_CODE_KEYS if isinstance(d.get(k), str)]
    elif d.get("law") == "series":
        for part in ("a", "b"):
            out += _layer_names(d.get(part), f"{path}.{part}")
    return out


def code_names(raw):
    """``[(dotted key, "module:function")]`` of the Python code a scene dict names (module docstring)."""
    out = []
    gap = raw.get("gap") if isinstance(raw, Mapping) else None
    if isinstance(gap, Mapping) and gap.get("type") == "callable" and isinstance(gap.get("function"), str):
        out.append(("gap.function", gap["function"]))
    if isinstance(raw, Mapping):
        out += _layer_names(raw.get("layer"), "layer")
    return out


def check_code_name(key, value):
    """The form of a code name, ``module.sub:function``, without importing anything."""
    if not _NAME.match(value):
        raise SceneError(f"{key} = {value!r} is not allowed: it must name Python code as 'module:function' "
                         "(dotted identifiers on both sides of one colon).")
    return value


def refuse_code(key, value):
    """The error for code named by a scene that may not import it."""
    return (f"{key} = {value!r} is not allowed without {CODE_FLAG}: it names Python code, and a scene file "
            f"imports and runs code only when you trust it (contactlab run/sweep/report {CODE_FLAG}, or "
            "load_scene(..., allow_code=True)).")


def scene_file(key, name, base_dir, *, allow_outside=False):
    """The absolute path of the file ``name`` a scene names, relative to ``base_dir``.

    Parameters
    ----------
    key : str
        The dotted key, for messages (``gap.file``).
    name : str
        The file name as the scene gives it (``~`` is expanded only with ``allow_outside``); an
        absolute name is accepted when it lies inside ``base_dir``.
    base_dir : path-like
        The scene file's folder.
    allow_outside : bool
        Accept absolute names and names leading out of ``base_dir``.

    Raises
    ------
    SceneError
        A name whose real path (symbolic links followed) leaves ``base_dir``, without
        ``allow_outside``.
    """
    with ck.scene_errors():
        check_file_name(key, name)
    base = Path(base_dir).absolute()
    if allow_outside:
        return str(base / Path(name).expanduser())
    rule = (f"a scene reads files only inside its own folder ({base}); give the name relative to it, or "
            f"pass {FILES_FLAG} (allow_outside_files=True) to read a file elsewhere")
    path = base / name
    real, root = os.path.realpath(path), os.path.realpath(base)
    if os.path.commonpath([real, root]) != root:
        raise SceneError(f"{key} = {name!r} is not allowed: it leads to {real}, outside the scene's folder; "
                         f"{rule}.")
    return str(path)
