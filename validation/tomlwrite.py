"""A minimal TOML writer for scene dictionaries (``tomllib`` reads, it does not write).

Handles what scene files hold: tables (nested), strings, booleans, integers, floats
(``inf``/``nan`` included), and arrays of those (arrays of arrays for tables of numbers).
Floats are written with ``repr`` so ``tomllib.loads(dumps(d)) == d`` exactly.
"""

from __future__ import annotations

import json
import math
import re

__all__ = ["dumps"]

_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def _key(k):
    return k if _BARE_KEY.match(k) else json.dumps(k)


def _value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)  # a valid TOML basic string
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(f"cannot write {type(v).__name__} value {v!r} to TOML")


def _table(lines, prefix, table):
    scalars = {k: v for k, v in table.items() if not isinstance(v, dict)}
    tables = {k: v for k, v in table.items() if isinstance(v, dict)}
    if prefix and (scalars or not tables):
        lines.append(f"[{prefix}]")
    for k, v in scalars.items():
        lines.append(f"{_key(k)} = {_value(v)}")
    if prefix and (scalars or not tables):
        lines.append("")
    for k, v in tables.items():
        _table(lines, f"{prefix}.{_key(k)}" if prefix else _key(k), v)


def dumps(data):
    """TOML text of the dict ``data`` (top-level keys that are dicts become ``[tables]``)."""
    lines = []
    _table(lines, "", data)
    return "\n".join(lines).rstrip("\n") + "\n"
