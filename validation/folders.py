"""The folder rule: which folder contactlab may write, its marker, and the clean-up after a killed writer.

Every folder contactlab writes holds a marker file, :data:`MARKER` (``.contactlab``: JSON with
the folder's ``kind``, ``"result"``, ``"report"``, ``"sweep"``, ``"layer-law"``
(:mod:`validation.layer_law`) or ``"study"``, the contactlab ``version`` and, for a folder written
whole, ``files`` and ``folders``: every file and sub-folder contactlab wrote there, as paths
relative to the folder). contactlab writes only into a new or empty folder, or into a folder
that holds the marker of the same kind and nothing else than what that marker lists (a sweep
folder, written in place: nothing but the names of a sweep folder); any other folder is
refused (:class:`OutputError`), so a user's file is never replaced, inside a sub-folder neither.

A process killed while it replaces a folder (``SIGKILL``, a power cut) leaves hidden folders
``.contactlab-tmp-*`` (the new folder, incomplete) and ``.contactlab-old-*`` (the previous
folder, moved aside) beside the target, each holding a marker from its creation on. The next
write of the same target removes those of a process that no longer runs and, when the target
itself is missing, first moves the previous folder back (:func:`recover_output_dir`); a hidden
folder without the marker is never removed (unless it is empty).

The folders themselves are written by :func:`validation.io.atomic_directory`.
"""

from __future__ import annotations

import contextlib
import glob
import hashlib
import json
import logging
import os
import shutil
from pathlib import Path

from bem.files import write_text

__all__ = ["OutputError", "MARKER", "KINDS", "IN_PLACE", "NAME_MAX", "write_marker", "marker_kind", "marked_files",
           "check_output_dir", "recover_output_dir", "leftover_prefixes", "process_running",
           "remove_marked"]

log = logging.getLogger(__name__)

#: The marker file of every folder contactlab writes: JSON ``{"kind": ..., "version": ...}``.
MARKER = ".contactlab"
#: The kinds of folder contactlab writes.
KINDS = ("result", "report", "sweep", "layer-law", "study", "surface")
#: The kinds of folder written in place (point by point) rather than replaced whole.
IN_PLACE = ("sweep",)
#: Longest file or folder name in bytes when the file system does not say (POSIX ``NAME_MAX``).
NAME_MAX = 255
_TMP, _OLD = ".contactlab-tmp-", ".contactlab-old-"


class OutputError(OSError):
    """The output location cannot be used (a foreign folder, a file, an unwritable or full file system)."""


def _contactlab_version():
    from importlib import metadata

    try:
        return metadata.version("contactlab")
    except metadata.PackageNotFoundError:  # pragma: no cover - a source tree without installation
        return "unknown"


def _listing(directory):
    """``(files, folders)``: the relative POSIX paths of every file and sub-folder below ``directory``
    (its marker left out), sorted."""
    files, folders = [], []
    for root, dirs, names in os.walk(directory):
        rel = Path(root).relative_to(directory)
        folders += [(rel / name).as_posix() for name in dirs]
        files += [(rel / name).as_posix() for name in names if not (rel == Path(".") and name == MARKER)]
    return sorted(files), sorted(folders)


def write_marker(directory, kind, *, listed=False):
    """Write the marker file (:data:`MARKER`) of a ``kind`` folder into ``directory``; returns its path.

    With ``listed`` it lists every file and sub-folder ``directory`` holds (``files``, ``folders``):
    what a later replacement of the folder may remove (:func:`check_output_dir`).
    """
    if kind not in KINDS:
        raise ValueError(f"kind = {kind!r} is not allowed: it must be one of {KINDS}.")
    data = {"kind": kind, "version": _contactlab_version()}
    if listed:
        data["files"], data["folders"] = _listing(directory)
    return write_text(Path(directory) / MARKER, json.dumps(data, indent=2) + "\n")


def _marker(directory):
    """The content of the marker file of ``directory`` (a dict with a known ``kind``), or None."""
    try:
        data = json.loads((Path(directory) / MARKER).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) and data.get("kind") in KINDS else None


def marker_kind(directory):
    """The ``kind`` in the marker file of ``directory``, or None (no marker, or not one contactlab wrote)."""
    data = _marker(directory)
    return None if data is None else data["kind"]


def marked_files(directory):
    """The files (relative POSIX paths) the marker of ``directory`` lists; empty without such a list."""
    data = _marker(directory) or {}
    files = data.get("files")
    return [f for f in files if isinstance(f, str)] if isinstance(files, list) else []


def _unlisted(directory, data, names=()):
    """What ``directory`` holds beyond what its marker ``data`` lists (paths; a folder ends with ``/``).

    A file must be listed as a file and a folder as a folder (a link is never listed). A folder
    named in ``names`` but not listed may be a marked folder of its own (a result folder's
    ``report``), checked against its own marker.
    """
    files, folders = data.get("files"), data.get("folders")
    if not (isinstance(files, list) and isinstance(folders, list)):
        return [f"{MARKER} (it lists no files)"]
    files, folders, found = set(map(str, files)), set(map(str, folders)), []

    def walk(path, rel):
        for entry in sorted(os.scandir(path), key=lambda e: e.name):
            name = rel + entry.name
            if not rel and entry.name == MARKER:
                continue
            if entry.is_symlink() or not (entry.is_dir() or entry.is_file()):
                found.append(name)
            elif entry.is_dir() and name in folders:
                walk(entry.path, name + "/")
            elif entry.is_dir() and not rel and name in names and _marker(entry.path) is not None:
                found.extend(f"{name}/{inner}" for inner in _unlisted(entry.path, _marker(entry.path)))
            elif entry.is_dir() or name not in files:
                found.append(name + ("/" if entry.is_dir() else ""))

    walk(directory, "")
    return found


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
    empty folder, or holds the marker of a ``kind`` folder (:data:`MARKER`) and nothing but what
    that marker lists (a file where it lists a file, a folder where it lists a folder, in
    sub-folders too) and, among ``names``, marked folders of their own (a result folder's
    ``report``, checked against its own marker). A folder written in place (:data:`IN_PLACE`, a
    sweep) holds nothing but ``names``.

    Parameters
    ----------
    target : path-like
        The folder to write.
    kind : str
        What will be written there, one of :data:`KINDS`.
    names : iterable of str
        The names a ``kind`` folder holds at its top.
    what : str
        The argument named in the message (``"--out"``, ``"scene.name"``).
    value : optional
        The value shown in the message (default: ``target``).

    Raises
    ------
    OutputError
        ``target`` is a file, lies under a file, has a name longer than the file system allows,
        or is a folder holding anything contactlab did not write there (or a marker that lists
        nothing, of a folder written whole).
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
    data = _marker(target)
    found = None if data is None else data["kind"]
    if found is not None and found != kind:
        reason = f"it is a contactlab {found} folder, not a {kind} folder"
    else:
        if found is None:
            foreign = [name for name in entries if name != MARKER]
        elif kind in IN_PLACE:
            # .NAME.* is the temporary file of an own file NAME (bem.files.atomic_path) a killed writer left
            foreign = [name for name in entries if name != MARKER and name not in names
                       and not any(name.startswith(f".{n}.") for n in names)]
        else:
            foreign = _unlisted(target, data, tuple(names))
        if not foreign:
            return
        reason = (f"it holds files contactlab did not write ({', '.join(foreign[:4])}"
                  f"{', ...' if len(foreign) > 4 else ''})")
    raise OutputError(f"{what} = {shown} is not allowed: {reason}; contactlab writes only into a new or empty "
                      f"folder or replaces a {kind} folder it wrote itself (marked by {MARKER}, listing its files).")


def _tag(name):
    return hashlib.sha256(os.fsencode(name)).hexdigest()[:16]


def process_running(pid):
    """Whether the process ``pid`` (this one included) still runs; False for anything not a pid."""
    try:
        pid = int(pid)
    except (TypeError, ValueError):
        return False
    if pid <= 0:
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


def _owner_alive(path):
    """Whether the process that made the hidden folder ``path`` (its name holds the pid) still runs."""
    parts = path.name.split("-")
    return path.name.startswith((_TMP, _OLD)) and len(parts) > 3 and process_running(parts[3])


def leftover_prefixes(target):
    """``(new, old)``: the name prefixes of the hidden folders :func:`validation.io.atomic_directory`
    makes beside ``target`` (the new folder, the previous one moved aside); the process id follows."""
    tag = _tag(Path(target).name)
    return f"{_TMP}{tag}-", f"{_OLD}{tag}-"


def _leftovers(parent, prefix):
    """The hidden folders ``parent/prefix*`` of processes that no longer run and that carry the
    marker (:data:`MARKER`), or hold nothing but it or its temporary file (a process killed while
    it wrote the marker of a new folder)."""
    found = []
    for path in sorted(parent.glob(f"{glob.escape(prefix)}*")):
        if not path.is_dir() or path.is_symlink() or _owner_alive(path):
            continue
        with contextlib.suppress(OSError):
            # .NAME.* is the temporary file of NAME (bem.files.atomic_path)
            if marker_kind(path) is not None or all(name == MARKER or name.startswith(f".{MARKER}.")
                                                    for name in os.listdir(path)):
                found.append(path)
    return found


def remove_marked(folder):
    """Remove the hidden folder ``folder`` of :func:`validation.io.atomic_directory`, its marker last: a
    process killed while it removes the folder leaves a folder still marked (:func:`recover_output_dir`)."""
    folder = Path(folder)
    with contextlib.suppress(FileNotFoundError):
        for entry in sorted(os.scandir(folder), key=lambda e: e.name == MARKER):
            if entry.is_dir(follow_symlinks=False):
                shutil.rmtree(entry.path, ignore_errors=True)
            else:
                with contextlib.suppress(OSError):
                    os.unlink(entry.path)
    with contextlib.suppress(OSError):
        folder.rmdir()


def recover_output_dir(target):
    """Clean up after a process killed while it wrote ``target`` (:func:`atomic_directory`).

    A previous folder moved aside is moved back when ``target`` is missing (the process was
    killed between the two renames), else removed; incomplete new folders are removed. Only the
    hidden folders of ``target`` that carry the marker (:data:`MARKER`, written when they are
    made) are removed: a user's folder of a similar name is left alone, as are the hidden
    folders of a process that still runs.

    Returns
    -------
    bool
        True when a previous folder was moved back to ``target``.
    """
    target = Path(target).absolute()
    parent, (new, moved) = target.parent, leftover_prefixes(target)
    if not parent.is_dir():
        return False
    restored = False
    for old in _leftovers(parent, moved):
        previous = old / "previous"
        if previous.is_dir() and not os.path.lexists(target):
            os.replace(previous, target)
            restored = True
            log.warning("restored %s: a process writing it was killed before it finished", target)
        remove_marked(old)
    for tmp in _leftovers(parent, new):
        remove_marked(tmp)
    return restored
