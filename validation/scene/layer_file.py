"""A tabulated layer law read from a file: ``[layer] law = "tabulated"`` with ``file``.

Keys of the ``[layer]`` table::

    law  = "tabulated"
    file = "law.toml"      # relative to the scene file's folder (validation.scene.trust)

The file is a TOML table file whose ``[layer]`` table is a tabulated law (``law =
"tabulated"``, ``p``, ``w``): the table file of a rough surface's layer law
(:meth:`bem.rough.TopographyLaw.save`, ``contactlab layer-law``) or one written by hand. Its
numbers are taken in the scene's units. A file with a ``[topography]`` table states the
effective modulus ``E_star`` its law was made with; a scene whose ``E_star`` differs from it by
more than :data:`E_STAR_RTOL` (relative) is refused: the closure of a roughness depends on the
modulus, and a different one also betrays a file in other units. ``file`` replaces ``p`` and
``w``; the law is the file's table, exactly as an inline ``[layer]`` with the same numbers.
A sweep hashes the file's contents (every key ``file``, :mod:`validation.run.sweep_folder`).
"""

from __future__ import annotations

import math
from pathlib import Path

from . import checks as ck
from .source import read_toml

__all__ = ["is_layer_file", "resolve_layer_file", "read_layer_file", "E_STAR_RTOL", "EXCLUSIVE"]

#: ``[layer]`` keys that replace each other (a ``--set layer.file=...`` drops ``p`` and ``w``)
EXCLUSIVE = (("file", "p"), ("file", "w"))

#: largest relative difference between the scene's ``E_star`` and the one the law file was made with
E_STAR_RTOL = 0.01


def is_layer_file(d):
    """Whether a raw ``[layer]`` table names a law file (``law = "tabulated"`` and ``file``)."""
    return isinstance(d, dict) and d.get("law") == "tabulated" and "file" in d


def resolve_layer_file(raw, base_dir, allow_outside):
    """Make ``layer.file`` absolute, relative to ``base_dir`` (:func:`validation.scene.trust.scene_file`)."""
    from .trust import scene_file

    layer = raw.get("layer")
    if is_layer_file(layer) and isinstance(layer["file"], str):
        layer["file"] = scene_file("layer.file", layer["file"], base_dir, allow_outside=allow_outside)


def _fail(value, rule):
    raise ck.SceneError(f"layer.file = {value!r} is not allowed: {rule}.")


def read_layer_file(d, E_star=None):
    """The spec ``{"law": "tabulated", "file", "p", "w"}`` of a ``[layer]`` table naming a law file.

    Parameters
    ----------
    d : dict
        The ``[layer]`` table (``file`` made absolute by :func:`resolve_layer_file`).
    E_star : float, optional
        The scene's effective modulus [pressure], compared with the file's ``[topography] E_star``.

    Raises
    ------
    validation.scene.SceneError
        ``file`` together with ``p`` or ``w``, another key, a missing or unreadable file, a file
        without a tabulated ``[layer]`` table, or an ``E_star`` that differs from the file's.
    """
    for key in ("p", "w"):
        if key in d:
            raise ck.SceneError(f"layer.{key} = {d[key]!r} is not allowed together with layer.file: the file holds "
                                "the table; give layer.file alone, or p and w.")
    ck.unknown_keys("layer", d, ("law", "file"))
    file = ck.string("layer.file", d["file"])
    path = Path(file)
    if not path.is_file():
        _fail(file, "there is no such file (a relative name starts from the scene file's folder)")
    data = read_toml(path, f"layer.file = {file!r}")
    layer = data.get("layer")
    if not isinstance(layer, dict) or layer.get("law") != "tabulated" or not {"p", "w"} <= layer.keys():
        _fail(file, "it must hold a [layer] table with law = 'tabulated', p and w (a layer law file: "
                    "contactlab layer-law, bem.rough.TopographyLaw.save)")
    topography = data.get("topography")
    made_with = topography.get("E_star") if isinstance(topography, dict) else None
    if E_star is not None and isinstance(made_with, (int, float)) and made_with > 0:
        if not math.isclose(E_star, made_with, rel_tol=E_STAR_RTOL):
            _fail(file, f"its law was made with E_star = {made_with!r}, the scene's E_star is {E_star!r}; they must "
                        f"agree within {E_STAR_RTOL:.0%} (the closure of a roughness depends on the modulus, and the "
                        "file's numbers are taken in the scene's units)")
    return {"law": "tabulated", "file": file, "p": layer["p"], "w": layer["w"]}
