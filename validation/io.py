"""The one writer of validation: JSON of numpy data and output folders written whole or not at
all (the fields are written by :mod:`bem.files`).

Single files are written by :func:`bem.files.atomic_path` and the helpers built on it (a
temporary file in the target's directory moved over the target with :func:`os.replace`,
ordinary permissions). A folder is assembled in a hidden temporary folder beside the target
and renamed into place at the end (:func:`atomic_directory`); an exception or an interrupt
(``KeyboardInterrupt`` included) removes the temporary folder and leaves any previous result
untouched. Result folders and report folders both use it; sweep folders, written point by
point, are checked the same way (:func:`check_output_dir`).

Every folder contactlab writes holds a marker file, :data:`MARKER` (``.contactlab``: JSON with
the folder's ``kind``, ``"result"``, ``"report"``, ``"sweep"``, ``"layer-law"`` or ``"surface"``
(:mod:`validation.layer_law`), and the contactlab
``version``). contactlab writes only into a new or empty folder, or into a folder that holds
the marker of the same kind and nothing but the files of that kind; any other folder is
refused (:class:`OutputError`), so a user's files are never replaced.

A process killed while it replaces a folder (``SIGKILL``, a power cut) leaves hidden folders
``.contactlab-tmp-*`` (the new folder, incomplete) and ``.contactlab-old-*`` (the previous
folder, moved aside) beside the target. The next write of the same target removes them and,
when the target itself is missing, first moves the previous folder back
(:func:`recover_output_dir`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import errno
import glob
import hashlib
import json
import logging
import math
import os
import shutil
import signal
import tempfile
import threading
from pathlib import Path

import numpy as np

from bem.files import umask, write_text

__all__ = ["atomic_write_json", "atomic_directory", "to_jsonable", "OutputError", "MARKER", "KINDS",
           "write_marker", "marker_kind", "check_output_dir", "recover_output_dir", "output_errors"]

log = logging.getLogger(__name__)

#: The marker file of every folder contactlab writes: JSON ``{"kind": ..., "version": ...}``.
MARKER = ".contactlab"
#: The kinds of folder contactlab writes.
KINDS = ("result", "report", "sweep", "layer-law", "surface")
#: Longest file or folder name in bytes when the file system does not say (POSIX ``NAME_MAX``).
NAME_MAX = 255
_TMP, _OLD = ".contactlab-tmp-", ".contactlab-old-"
_REASONS = {errno.EROFS: "the file system is read-only", errno.ENOSPC: "the file system is full",
            errno.EDQUOT: "the disk quota is exhausted", errno.EACCES: "no permission to write there",
            errno.EPERM: "no permission to write there", errno.ENOTDIR: "a part of the path is a file",
            errno.ENAMETOOLONG: "a name is longer than the file system allows", errno.EEXIST: "it exists"}


class OutputError(OSError):
    """The output location cannot be used (a foreign folder, a file, an unwritable or full file system)."""


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


def _contactlab_version():
    from importlib import metadata

    try:
        return metadata.version("contactlab")
    except metadata.PackageNotFoundError:  # pragma: no cover - a source tree without installation
        return "unknown"


def write_marker(directory, kind):
    """Write the marker file (:data:`MARKER`) of a ``kind`` folder into ``directory``; returns its path."""
    if kind not in KINDS:
        raise ValueError(f"kind = {kind!r} is not allowed: it must be one of {KINDS}.")
    return atomic_write_json(Path(directory) / MARKER, {"kind": kind, "version": _contactlab_version()})


def marker_kind(directory):
    """The ``kind`` in the marker file of ``directory``, or None (no marker, or not one contactlab wrote)."""
    try:
        data = json.loads((Path(directory) / MARKER).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    kind = data.get("kind") if isinstance(data, dict) else None
    return kind if kind in KINDS else None


def _shown(value, target):
    text = str(target) if value is None else str(value)
    return repr(text if len(text) <= 200 else text[:40] + "..." + text[-20:])


def _name_max(path):
    """The file system's longest name in bytes, asked of the nearest existing ancestor of ``path``."""
    for parent in path.parents:
        try:
            if parent.is_dir():
                return os.pathconf(parent, "PC_NAME_MAX")
        except (OSError, ValueError):
            break
    return NAME_MAX


def check_output_dir(target, kind, names=(), *, what="out_dir", value=None):
    """Refuse an output folder contactlab may not write.

    ``target`` may be written when it does not exist (and no part of its path is a file), is an
    empty folder, or holds the marker of a ``kind`` folder (:data:`MARKER`) and nothing but
    ``names`` (the files contactlab writes into such a folder).

    Parameters
    ----------
    target : path-like
        The folder to write.
    kind : str
        What will be written there, one of :data:`KINDS`.
    names : iterable of str
        The names a ``kind`` folder holds.
    what : str
        The argument named in the message (``"--out"``, ``"scene.name"``).
    value : optional
        The value shown in the message (default: ``target``).

    Raises
    ------
    OutputError
        ``target`` is a file, lies under a file, has a name longer than the file system allows,
        or is a folder holding anything contactlab did not write there.
    """
    target = Path(target).absolute()
    shown = _shown(value, target)
    limit = _name_max(target)
    for part in target.parts:
        size = len(os.fsencode(part))
        if size > limit:
            raise OutputError(f"{what} = {shown} is not allowed: the folder name {part[:20]!r}... is {size} bytes "
                              f"long; the file system allows at most {limit} bytes per name: choose a shorter name"
                              + (" or give --out." if what == "scene.name" else "."))
    for parent in target.parents:
        if parent.exists():
            if not parent.is_dir():
                raise OutputError(f"{what} = {shown} is not allowed: {str(parent)!r} is a file, not a folder.")
            break
    if not target.exists():
        return
    if not target.is_dir():
        raise OutputError(f"{what} = {shown} is not allowed: it is a file; give a folder.")
    entries = sorted(p.name for p in target.iterdir())
    if not entries:
        return
    found = marker_kind(target)
    if found is not None and found != kind:
        reason = f"it is a contactlab {found} folder, not a {kind} folder"
    else:
        own = set(names) if found == kind else set()
        # .NAME.* is the temporary file of an own file NAME (bem.files.atomic_path) a killed writer left
        foreign = [name for name in entries if name != MARKER and name not in own
                   and not any(name.startswith(f".{n}.") for n in own)]
        if not foreign:
            return
        reason = (f"it holds files contactlab did not write ({', '.join(foreign[:4])}"
                  f"{', ...' if len(foreign) > 4 else ''})")
    raise OutputError(f"{what} = {shown} is not allowed: {reason}; contactlab writes only into a new or empty "
                      f"folder or replaces a {kind} folder it wrote itself (marked by {MARKER}).")


def _tag(name):
    return hashlib.sha256(os.fsencode(name)).hexdigest()[:16]


def _owner_alive(path):
    """Whether the process that made the hidden folder ``path`` (its name holds the pid) still runs."""
    if not path.name.startswith((_TMP, _OLD)):
        return False
    try:
        pid = int(path.name.split("-")[3])
    except (IndexError, ValueError):
        return False
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


def recover_output_dir(target):
    """Clean up after a process killed while it wrote ``target`` (:func:`atomic_directory`).

    A previous folder moved aside is moved back when ``target`` is missing (the process was
    killed between the two renames), else removed; incomplete new folders are removed. Hidden
    folders of a process that still runs are left alone.

    Returns
    -------
    bool
        True when a previous folder was moved back to ``target``.
    """
    target = Path(target).absolute()
    parent, tag = target.parent, _tag(target.name)
    if not parent.is_dir():
        return False
    restored = False
    legacy = glob.escape(f".{target.name}")  # also the form .NAME.tmp-*, .NAME.old-*
    for old in sorted([*parent.glob(f"{_OLD}{tag}-*"), *parent.glob(f"{legacy}.old-*")]):
        if _owner_alive(old):
            continue
        previous = old / "previous"
        if previous.is_dir() and not os.path.lexists(target):
            os.replace(previous, target)
            restored = True
            log.warning("restored %s: a process writing it was killed before it finished", target)
        shutil.rmtree(old, ignore_errors=True)
    for tmp in [*parent.glob(f"{_TMP}{tag}-*"), *parent.glob(f"{legacy}.tmp-*")]:
        if not _owner_alive(tmp):
            shutil.rmtree(tmp, ignore_errors=True)
    return restored


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
def atomic_directory(target, kind="result", names=(), *, what="out_dir"):
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

    Yields
    ------
    pathlib.Path
        The temporary folder (beside ``target``, permissions of a new folder). On success an
        existing ``target`` is replaced; on any exception the temporary folder is removed and
        ``target`` is left as it was. Leftovers of a killed earlier writer are cleaned up first
        (:func:`recover_output_dir`).

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
        prefix = f"{_TMP}{_tag(target.name)}-{os.getpid()}-"
        tmp = Path(tempfile.mkdtemp(prefix=prefix, dir=target.parent))
    try:
        with output_errors(target, what):
            os.chmod(tmp, 0o777 & ~umask())  # mkdtemp creates 0700
            yield tmp
            write_marker(tmp, kind)
            _swap(tmp, target)
        log.info("written: %s", target)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)


@contextlib.contextmanager
def _signals_deferred():
    """Hold ``SIGINT`` and ``SIGTERM`` back while the block runs (main thread); handle them after it."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received = []
    saved = {signum: signal.signal(signum, lambda n, frame: received.append((n, frame)))
             for signum in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for signum, handler in saved.items():
            signal.signal(signum, handler)
        for signum, frame in received:
            handler = saved[signum]
            if callable(handler):
                handler(signum, frame)
            elif handler == signal.SIG_DFL:
                os.kill(os.getpid(), signum)


def _swap(tmp, target):
    """Move ``tmp`` onto ``target``; a previous ``target`` is moved aside first and removed after.

    An interrupt or ``SIGTERM`` is held back until the swap is over, so it never leaves the
    target missing; only a kill (``SIGKILL``) can, and :func:`recover_output_dir` repairs that.
    """
    with _signals_deferred():
        old = None
        if target.exists():
            old = Path(tempfile.mkdtemp(prefix=f"{_OLD}{_tag(target.name)}-{os.getpid()}-", dir=target.parent))
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
                shutil.rmtree(old, ignore_errors=True)
