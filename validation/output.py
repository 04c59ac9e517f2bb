"""Atomic output: files and result directories are written whole or not at all.

A file is written to a temporary name in its own directory and moved over the target
with :func:`os.replace` (atomic on POSIX and Windows within one file system). A result
directory is assembled in a hidden temporary directory beside the target and renamed into
place at the end (:func:`atomic_directory`); an exception or an interrupt (``KeyboardInterrupt``
included) removes the temporary directory and leaves any previous result untouched.
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

__all__ = ["atomic_write_bytes", "atomic_write_text", "atomic_write_json", "atomic_directory",
           "to_jsonable", "OutputError", "RESULT_MARKER"]

log = logging.getLogger(__name__)

#: A directory holding this file is a contactlab result directory (it may be replaced).
RESULT_MARKER = "result.json"


def _umask():
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


class OutputError(OSError):
    """The output location cannot be used (e.g. it is a non-empty foreign directory)."""


def atomic_write_bytes(path, data):
    """Write ``data`` to ``path`` via a temporary file and :func:`os.replace`. Returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp creates 0600; give the usual permissions
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return path


def atomic_write_text(path, text):
    """Write the string ``text`` (UTF-8) to ``path`` atomically. Returns the path."""
    return atomic_write_bytes(path, text.encode("utf-8"))


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
    return atomic_write_text(path, text)


def _check_replaceable(target):
    """A target may be replaced if it does not exist, is empty, or is a result directory."""
    if not target.exists():
        return
    if not target.is_dir():
        raise OutputError(f"out = {str(target)!r} is not allowed: it is a file; give a directory path.")
    if any(target.iterdir()) and not (target / RESULT_MARKER).is_file():
        raise OutputError(
            f"out = {str(target)!r} is not allowed: it is a non-empty directory that holds no "
            f"{RESULT_MARKER} (not a contactlab result); give a new or empty directory.")


@contextlib.contextmanager
def atomic_directory(target):
    """Assemble a directory in a temporary place; move it to ``target`` only on success.

    Yields the temporary directory (a :class:`pathlib.Path`). On success an existing
    ``target`` (empty, or a previous result directory holding ``result.json``) is
    replaced; on any exception the temporary directory is removed and ``target`` is
    left as it was.

    Raises
    ------
    OutputError
        ``target`` is a file or a non-empty directory that is not a result directory.
    """
    target = Path(target).absolute()
    _check_replaceable(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.tmp-", dir=target.parent))
    try:
        os.chmod(tmp, 0o777 & ~_umask())  # mkdtemp creates 0700
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
        log.info("results written to %s", target)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
