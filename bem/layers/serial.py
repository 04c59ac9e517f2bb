"""Rebuild a layer law from its ``to_dict()`` form (scene files, result files)."""

from __future__ import annotations

from collections.abc import Mapping

from ..checks import InputError, check_choice
from .analytic import Bilinear, ElasticRigid, Linear, Power, Root
from .base import Layer
from .custom import Custom
from .series import Series
from .tabulated import Tabulated

__all__ = ["LAWS", "from_dict"]

#: Law name (the ``"law"`` key) -> class.
LAWS = {cls.law: cls for cls in (Linear, Power, Root, ElasticRigid, Bilinear, Tabulated, Custom, Series)}


def from_dict(d):
    """Build the law described by ``d = {"law": name, **parameters}`` (inverse of ``to_dict``).

    Parameters
    ----------
    d : Mapping or Layer
        ``"law"`` is one of :data:`LAWS`; the other keys are the constructor's keywords,
        e.g. ``{"law": "power", "lam": 1e-3, "s": 0.5}``. A series holds its two layers as
        nested dicts ``"a"`` and ``"b"``; a custom law holds ``"module:function"`` strings (or
        callables). A ``Layer`` is returned unchanged.

    Raises
    ------
    InputError
        Unknown law, unknown or missing key, or a bad parameter; the message names the key
        (nested keys of a series as ``a.lam``).
    """
    if isinstance(d, Layer):
        return d
    if not isinstance(d, Mapping):
        raise InputError(f"layer = {d!r} is not allowed: it must be a mapping with a 'law' key.")
    cls = LAWS[check_choice("law", d.get("law"), tuple(LAWS))]
    keys = ("law", *cls._required, *cls._optional)
    for key in d:
        check_choice("layer key", key, keys)
    kwargs = {key: d.get(key) for key in cls._required}
    kwargs.update({key: d[key] for key in cls._optional if key in d})
    if cls is Series:
        kwargs = {key: _nested(key, value) for key, value in kwargs.items()}
    return cls(**kwargs)


def _nested(prefix, value):
    try:
        return from_dict(value)
    except InputError as exc:
        raise InputError(f"{prefix}.{exc}") from None
