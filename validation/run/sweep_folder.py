"""The folder of a sweep: how points are keyed, and which points a folder already holds.

A point's ``fingerprint`` is the SHA-256 of its scene (:func:`keyed`: what decides the result)
and of the contents of every file the scene names (every key ``file``, e.g. ``gap.file`` of a
measured surface: the SHA-256 of the file's bytes, :func:`file_digests`). A sweep's identity
is the same for its base scene: the scene with the swept key replaced by :data:`SWEPT`, with
the key. A folder holds the points of one sweep identity (:func:`earlier_points`).

A sweep folder is written in place, each file whole or not at all (:func:`write_file`): the
temporary file of a write names the process writing it
(``.point-<fingerprint>.json.<random>.<pid>.contactlab-tmp``), so that the next sweep into the
folder removes what a killed sweep left (:func:`remove_unfinished`) and computes that point again.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
from pathlib import Path

from bem.files import atomic_path

from ..folders import process_running
from ..io import OutputError, json_text

__all__ = ["SWEPT", "file_digests", "keyed", "fingerprint", "earlier_points", "other_point", "write_file",
           "write_point", "remove_unfinished"]

log = logging.getLogger(__name__)

#: the swept key's place holder in the base scene of a sweep
SWEPT = "<swept>"
#: keys that do not change a point's result: left out of its fingerprint
_NOT_KEYED = {"report": None, "scene": ("title", "description")}
#: the end of the name of a file being written into a sweep folder (:func:`write_file`)
_UNFINISHED = ".contactlab-tmp"
_REMEDY = ("a sweep folder holds one parameter over one base scene and no point is overwritten: give another "
           "--out, or remove the folder to start again.")


def _sha256_file(path):
    """SHA-256 of a file's bytes (hex), or None when there is no such file."""
    path = Path(path)
    if not path.is_file():
        return None
    digest = hashlib.sha256()
    with path.open("rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def file_digests(raw, cache, prefix=""):
    """``{dotted key: SHA-256}`` of every file the scene names (keys ``file``); ``cache``: path -> digest."""
    out = {}
    for key, value in raw.items():
        if isinstance(value, dict):
            out.update(file_digests(value, cache, f"{prefix}{key}."))
        elif key == "file" and isinstance(value, str):
            if value not in cache:
                cache[value] = _sha256_file(value)
            out[f"{prefix}{key}"] = cache[value]
    return out


def keyed(raw):
    """The part of a scene that decides its result (no ``[report]``, title or description)."""
    out = {}
    for section, value in raw.items():
        skip = _NOT_KEYED.get(section, ())
        if skip is None:
            continue
        out[section] = {k: v for k, v in value.items() if k not in skip} if isinstance(value, dict) else value
    return out


def fingerprint(*parts):
    """SHA-256 (hex) of JSON-able ``parts``, keys sorted."""
    return hashlib.sha256(json.dumps(parts, sort_keys=True, default=str).encode()).hexdigest()


def _flat(d, prefix=""):
    """``{dotted key: value}`` of nested tables."""
    out = {}
    for key, value in (d or {}).items():
        if isinstance(value, dict):
            out.update(_flat(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


def _difference(old, new):
    """What makes ``old`` (``key``, ``scene``, ``files`` of a point file) differ from ``new``, in words."""
    if not isinstance(old, dict) or not isinstance(old.get("scene"), dict):
        return "it is not a point of a contactlab sweep"
    if old.get("key") != new["key"]:
        return f"it is a point of a sweep of {old.get('key')}, not of {new['key']}"
    was, now = _flat(old["scene"]), _flat(new["scene"])
    keys = sorted(k for k in was.keys() | now.keys() if was.get(k, SWEPT) != now.get(k, SWEPT))
    files = sorted(k for k in (old.get("files") or {}).keys() | new["files"].keys()
                   if (old.get("files") or {}).get(k) != new["files"].get(k))
    said = [f"{k} = {was.get(k)!r} there, {now.get(k)!r} here" for k in keys[:4]] + [
        f"the contents of the file {k}" for k in files if k not in keys]
    return "its scene differs: " + ("; ".join(said) or "in its keys") + ("; ..." if len(keys) > 4 else "")


def earlier_points(out, sweep):
    """``{fingerprint: point data}`` of the points in ``out/points`` (each of the sweep ``sweep``).

    Raises
    ------
    OutputError
        A file in ``out/points`` is not a point of this sweep (another parameter, another base
        scene, a changed file, or not a point at all): its points are never overwritten or mixed.
    """
    found = {}
    folder = out / "points"
    for path in sorted(folder.glob("[!.]*.json")) if folder.is_dir() else ():  # not a hidden unfinished write
        try:
            with open(path, encoding="utf-8") as fh:
                data = json.load(fh)
        except (OSError, ValueError, RecursionError):  # RecursionError: nested too deep
            data = None
        old = data.get("sweep") if isinstance(data, dict) else None
        ok = isinstance(old, dict) and old.get("fingerprint") == sweep["fingerprint"]
        if not ok or not isinstance(data.get("result"), dict) or not isinstance(data.get("fingerprint"), str):
            why = _difference(old, sweep) if not ok else "not a finished point"
            raise OutputError(f"--out = {str(out)!r} is not allowed: it holds points of another sweep "
                              f"(points/{path.name}: {why}); {_REMEDY}")
        found[data["fingerprint"]] = dict(data, file=path.name)
    return found


def other_point(out, data, point):
    """Refuse an earlier point ``data`` of the same value as ``point`` but another fingerprint.

    Within one sweep this happens when the swept key names a file (``gap.file``) whose
    contents changed: the earlier answer is stale and is not overwritten.

    Raises
    ------
    OutputError
        Always; the message says what differs.
    """
    old = {"key": point.sweep["key"], "scene": keyed(data.get("scene") or {}), "files": data.get("files")}
    new = {"key": point.sweep["key"], "scene": keyed(point.scene.raw), "files": point.files}
    raise OutputError(f"--out = {str(out)!r} is not allowed: it holds the point {point.sweep['key']} = "
                      f"{point.value!r} of another scene (points/{data['file']}: {_difference(old, new)}); {_REMEDY}")




def write_file(path, text):
    """Write ``text`` (UTF-8) to ``path`` in a sweep folder, whole or not at all
    (:func:`bem.files.atomic_path`); the temporary file's name ends with the process id and
    ``.contactlab-tmp``, what :func:`remove_unfinished` looks for. Returns the path."""
    path = Path(path)
    with atomic_path(path, suffix=f".{os.getpid()}{_UNFINISHED}") as tmp, open(tmp, "wb") as fh:
        fh.write(text.encode("utf-8"))
        fh.flush()
        os.fsync(fh.fileno())
    return path


def write_point(path, data):
    """Write the point file ``path`` (JSON of ``data``) whole or not at all (:func:`write_file`)."""
    return write_file(path, json_text(data))


def remove_unfinished(out):
    """Remove the temporary files a killed sweep left in the sweep folder ``out`` (and its ``points``).

    Only files named as :func:`write_file` names them, by a process that no longer runs: a point
    whose write did not finish is computed again. Returns the names removed.
    """
    removed = []
    for folder in (Path(out), Path(out) / "points"):
        for path in sorted(folder.glob(f".*{_UNFINISHED}")) if folder.is_dir() else ():
            pid = path.name[: -len(_UNFINISHED)].rsplit(".", 1)[-1]
            if path.is_file() and not path.is_symlink() and not process_running(pid):
                with contextlib.suppress(FileNotFoundError):
                    path.unlink()
                removed.append(path.name)
    if removed:
        log.warning("removed %d unfinished file(s) of a killed sweep from %s", len(removed), out)
    return removed
