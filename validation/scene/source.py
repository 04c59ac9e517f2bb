"""Reading a scene: the built-in scenes by name, and a scene file's TOML (UTF-8, bounded nesting)."""

from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path

from ..provenance import display_path
from bem.checks import check_file_name

from .checks import SceneError, scene_errors

__all__ = ["builtin_dir", "builtin_scenes", "builtin_path", "read_toml", "read_source", "MAX_DEPTH"]


def builtin_dir():
    """The folder of the built-in scene files."""
    return Path(str(resources.files("validation") / "scenes"))


def builtin_scenes():
    """``{name: one-line description}`` of the built-in scenes, sorted by name."""
    out = {}
    for path in sorted(builtin_dir().glob("*.toml")):
        with path.open("rb") as fh:
            meta = tomllib.load(fh).get("scene", {})
        out[path.stem] = meta.get("description") or meta.get("title", "")
    return out


def builtin_path(name):
    """Path of the built-in scene ``name``; SceneError listing the names if there is none."""
    path = builtin_dir() / f"{name}.toml"
    if not path.is_file():
        raise SceneError(f"scene = {name!r} is not allowed: it must be a built-in scene name ("
                         + ", ".join(builtin_scenes()) + ") or a path to a .toml file.")
    return path


#: deepest nesting of arrays and tables a scene file may hold
MAX_DEPTH = 32


def _depth(value):
    """Nesting depth of lists and dicts in ``value`` (iterative: any depth)."""
    deepest, stack = 0, [(value, 0)]
    while stack:
        node, depth = stack.pop()
        deepest = max(deepest, depth)
        if deepest > MAX_DEPTH:
            break
        children = node.values() if isinstance(node, dict) else node if isinstance(node, list) else ()
        stack.extend((child, depth + 1) for child in children)
    return deepest


def read_toml(path, name=None):
    """The content of a scene file (or a file it names): UTF-8 TOML, arrays and tables nested at most
    :data:`MAX_DEPTH` deep; ``name`` is the file in messages (default ``"scene file 'path'"``).

    Raises
    ------
    SceneError
        An unreadable file, another encoding than UTF-8, invalid TOML or too deep a nesting.
    """
    name = f"scene file {str(path)!r}" if name is None else name
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise SceneError(f"{name} is not allowed: it cannot be read ({exc.strerror}).") from None
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise SceneError(f"{name} is not allowed: it is UTF-16 text and a TOML file is UTF-8; save it as UTF-8.")
    try:
        text = data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as exc:
        raise SceneError(f"{name} is not allowed: it must be UTF-8 text (TOML), and byte {exc.start} "
                         f"(0x{data[exc.start]:02x}) is not UTF-8; save it as UTF-8.") from None
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{name} is not valid TOML: {exc}.") from None
    except RecursionError:
        raw = None
    if raw is None or _depth(raw) > MAX_DEPTH:
        raise SceneError(f"{name} is not allowed: it nests arrays or tables more than {MAX_DEPTH} levels deep.")
    return raw


def read_source(source):
    """``(raw, label, folder)`` of a built-in name or a TOML file."""
    with scene_errors():
        check_file_name("scene", source)
    path = Path(source)
    if path.suffix == ".toml" or path.exists():
        if not path.is_file():
            raise SceneError(f"scene = {str(source)!r} is not allowed: there is no such file.")
        label = display_path(path)
    else:
        path = builtin_path(str(source))
        label = f"builtin:{source}"
    return read_toml(path), label, path.parent
