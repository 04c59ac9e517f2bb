"""The table file of a rough surface's layer law, read back (:meth:`bem.rough.TopographyLaw.save` writes it).

The file and its tables: :mod:`bem.rough.layer_law`.
"""

from __future__ import annotations

import tomllib
from dataclasses import fields
from pathlib import Path

import numpy as np

from ..checks import InputError, fail
from ..layers import Tabulated
from .layer_law import TopographyLaw
from .surface import SurfaceStats

__all__ = ["read_layer_law"]


def _arrays(table):
    return {k: np.array(v, dtype=float) if isinstance(v, list) else v for k, v in table.items()}


def read_layer_law(path):
    """Read a table file written by :meth:`TopographyLaw.save`.

    Returns
    -------
    TopographyLaw

    Raises
    ------
    bem.InputError
        The file cannot be read, is not TOML, or lacks the ``[layer]`` or ``[topography]`` table.
    """
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, RecursionError) as exc:
        raise InputError(f"path = {str(path)!r} is not allowed: it must be a readable TOML table file "
                         f"({'nested too deep' if isinstance(exc, RecursionError) else type(exc).__name__}).") from None
    layer, topo = data.get("layer"), data.get("topography")
    if not isinstance(layer, dict) or layer.get("law") != "tabulated" or not isinstance(topo, dict):
        fail("path", str(path), "a layer law file with [layer] law = 'tabulated' and a [topography] table")
    try:
        stats = dict(topo["surface"])
        stats.update(size=tuple(stats["size"]), grid=tuple(stats["grid"]))
        stats = SurfaceStats(**{f.name: stats[f.name] for f in fields(SurfaceStats) if f.name in stats})
        arrays = {k: np.array(topo[k], dtype=float) for k in ("mean_pressure", "closure", "mean_gap",
                                                               "contact_fraction", "stiffness")}
        cell = {k: topo[k] for k in ("n_cols", "n_rows", "step", "stretch_y", "method", "rtol")}
        hardness = None if topo.get("hardness") is None else float(topo["hardness"])
        return TopographyLaw(Tabulated(layer["p"], layer["w"]), arrays["mean_pressure"], arrays["closure"],
                             arrays["mean_gap"], float(topo["first_touch_gap"]), arrays["contact_fraction"],
                             arrays["stiffness"], np.array(topo["iterations"], dtype=int), float(topo["E_star"]),
                             cell, stats, str(topo["version"]), dict(topo.get("preparation", {})),
                             dict(topo.get("ladder_start", {})), _arrays(topo.get("persson", {})),
                             hardness, None if hardness is None else np.array(topo["plastic_fraction"], dtype=float))
    except (KeyError, TypeError) as exc:
        raise InputError(f"path = {str(path)!r} is not allowed: its [topography] table lacks {exc}.") from None
