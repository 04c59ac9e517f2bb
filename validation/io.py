"""The one writer of validation: JSON of numpy data and output folders written whole or not at
all (the fields are written by :mod:`bem.files`).

Single files are written by :func:`bem.files.atomic_path` and the helpers built on it (a
temporary file in the target's directory moved over the target with :func:`os.replace`,
ordinary permissions). A folder is assembled in a hidden temporary folder beside the target
and renamed into place at the end (:func:`atomic_directory`); an exception or an interrupt
(``KeyboardInterrupt`` included) removes the temporary folder and leaves any previous result
untouched. Result folders and report folders both use it; sweep folders, written point by
point, are checked the same way (:func:`check_output_dir`).

The folder rule (which folder may be written, its marker :data:`MARKER`, the clean-up after a
killed writer) is :mod:`validation.folders`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import errno
import json
import logging
import math
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from bem.files import umask, write_text

from .folders import (KINDS, MARKER, NAME_MAX, OutputError, check_output_dir, leftover_prefixes, marked_files,
                      marker_kind, recover_output_dir, remove_marked, write_marker)
from .signals import signals_deferred

__all__ = ["atomic_write_json", "json_text", "atomic_directory", "to_jsonable", "OutputError",
           "write_marker", "marker_kind", "marked_files", "check_output_dir", "recover_output_dir", "output_errors"]

log = logging.getLogger(__name__)

_REASONS = {errno.EROFS: "the file system is read-only", errno.ENOSPC: "the file system is full",
            errno.EDQUOT: "the disk quota is exhausted", errno.EACCES: "no permission to write there",
            errno.EPERM: "no permission to write there", errno.ENOTDIR: "a part of the path is a file",
            errno.ENAMETOOLONG: "a name is longer than the file system allows", errno.EEXIST: "it exists"}


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


def json_text(obj):
    """``obj`` as indented JSON text (strict: NaN/inf written as null, :func:`to_jsonable`)."""
    return json.dumps(to_jsonable(obj), indent=2, allow_nan=False) + "\n"


def atomic_write_json(path, obj):
    """Write ``obj`` as indented JSON (strict: NaN/inf written as null) atomically."""
    return write_text(path, json_text(obj))


@contextlib.contextmanager
def output_errors(target, what="out_dir"):
    """Turn an :class:`OSError` raised while writing ``target`` into an :class:`OutputError` naming the
    path and the reason (read-only or full file system, no permission, a name too long)."""
    try:
        yield
    except OutputError:
        raise
    except OSError as exc:
        reason = _REASONS.get(exc.errno, exc.strerror or type(exc).__name__)
        if exc.errno == errno.ENAMETOOLONG:
            reason += f" ({NAME_MAX} bytes per name)"
        where = f" (writing {str(exc.filename)!r})" if exc.filename is not None else ""
        error = OutputError(f"{what} = {str(target)!r} cannot be written: {reason}{where}.")
        error.errno = exc.errno
        raise error from exc


@contextlib.contextmanager
def atomic_directory(target, kind="result", names=(), *, what="out_dir", keep=()):
    """Assemble a folder in a temporary place; move it to ``target`` only on success.

    Parameters
    ----------
    target : path-like
        The folder to create or replace.
    kind : str
        What the folder is (one of :data:`KINDS`); its marker (:data:`MARKER`) is written into it.
    names : iterable of str
        The names such a folder holds (:func:`check_output_dir`).
    what : str
        The argument named in error messages.
    keep : iterable of str
        Files of an existing ``target`` (top-level names its marker lists) copied into the new
        folder before the block runs: what a replacement keeps (the other studies of a study
        folder).

    Yields
    ------
    pathlib.Path
        The temporary folder (beside ``target``, permissions of a new folder). On success an
        existing ``target`` is replaced; on any exception the temporary folder is removed and
        ``target`` is left as it was. Leftovers of a killed earlier writer are cleaned up first
        (:func:`recover_output_dir`). The marker written at the end lists every file and folder
        of the new folder.

    Raises
    ------
    OutputError
        ``target`` may not be written (:func:`check_output_dir`), or writing failed (read-only
        or full file system, no permission): the message names the path and the reason.
    """
    target = Path(target).absolute()
    with output_errors(target, what):
        recover_output_dir(target)
        check_output_dir(target, kind, names, what=what)
        target.parent.mkdir(parents=True, exist_ok=True)
        prefix = f"{leftover_prefixes(target)[0]}{os.getpid()}-"
        tmp = Path(tempfile.mkdtemp(prefix=prefix, dir=target.parent))
    try:
        with output_errors(target, what):
            write_marker(tmp, kind)  # marks the hidden folder as contactlab's (recover_output_dir)
            os.chmod(tmp, 0o777 & ~umask())  # mkdtemp creates 0700
            listed = set(marked_files(target))
            for name in keep:
                if name in listed and (target / name).is_file():
                    shutil.copy2(target / name, tmp / name)
            yield tmp
            write_marker(tmp, kind, listed=True)
            _swap(tmp, target, kind)
        log.info("written: %s", target)
    finally:
        if tmp.exists():
            remove_marked(tmp)


def _swap(tmp, target, kind):
    """Move ``tmp`` onto ``target``; a previous ``target`` is moved aside first and removed after.

    An interrupt or ``SIGTERM`` is held back until the swap is over, so it never leaves the
    target missing; only a kill (``SIGKILL``) can, and :func:`recover_output_dir` repairs that.
    """
    with signals_deferred():
        old = None
        if target.exists():
            prefix = f"{leftover_prefixes(target)[1]}{os.getpid()}-"
            old = Path(tempfile.mkdtemp(prefix=prefix, dir=target.parent))
            write_marker(old, kind)  # marks the hidden folder as contactlab's (recover_output_dir)
        try:
            if old is not None:
                os.replace(target, old / "previous")
            os.replace(tmp, target)
        except BaseException:
            if old is not None and (old / "previous").is_dir() and not os.path.lexists(target):
                os.replace(old / "previous", target)
            raise
        finally:
            if old is not None and os.path.lexists(target):
                with contextlib.suppress(OSError):  # "previous" names only a complete folder
                    os.replace(old / "previous", old / "discarded")
                remove_marked(old)
