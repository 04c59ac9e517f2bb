"""The one writer of validation: JSON of numpy data and result directories written whole or not at
all (the fields are written by :mod:`bem.files`).

Single files are written by :func:`bem.files.atomic_path` and the helpers built on it (a
temporary file in the target's directory moved over the target with :func:`os.replace`,
ordinary permissions). A directory is assembled in a hidden temporary directory beside the
target and renamed into place at the end (:func:`atomic_directory`); an exception or an
interrupt (``KeyboardInterrupt`` included) removes the temporary directory and leaves any
previous result untouched. Result directories and report directories both use it.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import logging
import math
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from bem.files import umask, write_text

__all__ = ["atomic_write_json", "atomic_directory", "to_jsonable", "OutputError", "RESULT_MARKER",
           "check_result_dir"]

log = logging.getLogger(__name__)

#: A directory holding this file is a contactlab result directory (it may be replaced).
RESULT_MARKER = "result.json"


class OutputError(OSError):
    """The output location cannot be used (e.g. it is a non-empty foreign directory)."""


def to_jsonable(obj):
    """Plain JSON types from numpy scalars/arrays, tuples, paths, dataclasses and objects with
    ``to_dict()``; non-finite floats become None."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return to_jsonable(dataclasses.asdict(obj))
    if hasattr(obj, "to_dict") and callable(obj.to_dict):
        return to_jsonable(obj.to_dict())
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        value = float(obj)
        return value if math.isfinite(value) else None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def atomic_write_json(path, obj):
    """Write ``obj`` as indented JSON (strict: NaN/inf written as null) atomically."""
    text = json.dumps(to_jsonable(obj), indent=2, allow_nan=False) + "\n"
    return write_text(path, text)


def check_result_dir(target):
    """A result directory may be replaced if it does not exist, is empty, or holds ``result.json``.

    Raises
    ------
    OutputError
        ``target`` is a file, or a non-empty directory that is not a contactlab result.
    """
    if not target.exists():
        return
    if not target.is_dir():
        raise OutputError(f"out = {str(target)!r} is not allowed: it is a file; give a directory path.")
    if any(target.iterdir()) and not (target / RESULT_MARKER).is_file():
        raise OutputError(
            f"out = {str(target)!r} is not allowed: it is a non-empty directory that holds no "
            f"{RESULT_MARKER} (not a contactlab result); give a new or empty directory.")


@contextlib.contextmanager
def atomic_directory(target, *, check=check_result_dir):
    """Assemble a directory in a temporary place; move it to ``target`` only on success.

    Parameters
    ----------
    target : path-like
        The directory to create or replace.
    check : callable, optional
        ``check(target)`` raises if ``target`` may not be replaced (default
        :func:`check_result_dir`; the report builder passes its own rule).

    Yields
    ------
    pathlib.Path
        The temporary directory (beside ``target``, permissions of a new directory). On
        success an existing ``target`` is replaced; on any exception the temporary
        directory is removed and ``target`` is left as it was.

    Raises
    ------
    OutputError
        ``target`` is a file or a non-empty directory that is not a result directory.
    """
    target = Path(target).absolute()
    check(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.tmp-", dir=target.parent))
    try:
        os.chmod(tmp, 0o777 & ~umask())  # mkdtemp creates 0700
        yield tmp
        old = None
        if target.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{target.name}.old-", dir=target.parent))
            os.replace(target, old / "previous")
        try:
            os.replace(tmp, target)
        except BaseException:
            if old is not None:
                os.replace(old / "previous", target)
            raise
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
        log.info("written: %s", target)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
