"""The folder of a sweep: how points are keyed, and which points a folder already holds.

A point's ``fingerprint`` is the SHA-256 of its scene (:func:`keyed`: what decides the result)
and of the contents of every file the scene names (every key ``file``, e.g. ``gap.file`` of a
measured surface: the SHA-256 of the file's bytes, :func:`file_digests`). A sweep's identity
is the same for its base scene: the scene with the swept key replaced by :data:`SWEPT`, with
the key. A folder holds the points of one sweep identity (:func:`earlier_points`).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from ..io import OutputError

__all__ = ["SWEPT", "file_digests", "keyed", "fingerprint", "earlier_points", "other_point"]

#: the swept key's place holder in the base scene of a sweep
SWEPT = "<swept>"
#: keys that do not change a point's result: left out of its fingerprint
_NOT_KEYED = {"report": None, "scene": ("title", "description")}
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


