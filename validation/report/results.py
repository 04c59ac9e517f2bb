"""Reading a results directory written by ``contactlab run`` (tolerantly).

What is read, all optional except ``result.json``:

``result.json``
    Scalars of the run. Either flat (``p_max``, ``force``, ``approach``, ``contact_area``,
    ``contact_radius``, ``iterations``, ``converged``, ``kkt_residual``, ``method``,
    ``message``, ``wall_time_s``) or split by solver (``{"bem": {...}, "fem": {...}}``);
    ``wall_time_s`` a number or ``{"bem": s, "fem": s}``. Optional ``units`` (a string or
    ``{"length", "pressure", "force"}``), ``scene`` (``name``, ``gap``, ``layer``, ``bodies``
    or ``materials``, ``load``, ``units``) and comparison metrics under ``comparison``,
    ``comparisons`` or ``metrics`` (a flat or nested dict of scalars). The FEM took part
    when there is a ``fem`` dict or a ``wall_time_s["fem"]`` that is a number. Unknown keys
    are kept and shown as "other values"; malformed values are skipped with a log message.
study files
    Any other ``*.json`` in the directory or in ``studies/``: a list of row dicts, or a dict
    with ``rows`` (and optional ``title``/``name``, ``error_label``). Rows with ``error`` and
    ``wall_time_s`` make a work-precision plot, rows with ``status`` a coloured table.
nodal fields
    ``*.npz`` with arrays ``x, y, p`` (BEM pressure on the plane), or ParaView files
    (``.vtu``, ``.vtk``, ``.vtp``) read with meshio: point data ``pressure``, ``p`` or
    ``contact_pressure`` on points in a plane is a BEM field; ``von_mises`` on
    (6-node) triangles is an FEM (r, z) section.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bem._validate import InputError

__all__ = ["RunResults", "load_results", "SCALAR_KEYS"]

log = logging.getLogger(__name__)

#: scalar keys of a solver part of result.json, in display order
SCALAR_KEYS = ("p_max", "force", "approach", "contact_area", "contact_radius", "iterations", "converged",
               "kkt_residual", "method", "message", "wall_time_s", "n_nodes", "n_contact", "step", "n_dofs")
_META_KEYS = ("bem", "fem", "units", "scene", "comparison", "comparisons", "metrics", "wall_time_s")
_PRESSURE_NAMES = ("pressure", "p", "contact_pressure")


@dataclass
class RunResults:
    """The content of a results directory.

    Attributes
    ----------
    directory : Path
    bem : dict
        Scalars of the BEM part (may be empty).
    fem : dict or None
        Scalars of the FEM part; ``None`` when the FEM did not run.
    comparison : dict
        Flattened comparison metrics (``"a.b"`` keys for nested dicts).
    scene : dict
        Scene description, if recorded.
    units : dict or str or None
    other : dict
        Top-level scalars not understood otherwise.
    studies : list of (str, dict)
        ``(title, {"rows": [...], ...})`` per study file.
    bem_field : tuple or None
        ``(x, y, p)`` nodal arrays.
    fem_field : tuple or None
        ``(r, z, triangles, von_mises)``.
    """

    directory: Path
    bem: dict = field(default_factory=dict)
    fem: dict | None = None
    comparison: dict = field(default_factory=dict)
    scene: dict = field(default_factory=dict)
    units: object = None
    other: dict = field(default_factory=dict)
    studies: list = field(default_factory=list)
    bem_field: tuple | None = None
    fem_field: tuple | None = None


def _scalar(v):
    return isinstance(v, (int, float, str, bool)) or v is None


def _flatten(d, prefix=""):
    out = {}
    for k, v in d.items():
        key = f"{prefix}{k}"
        if isinstance(v, Mapping):
            out.update(_flatten(v, key + "."))
        elif _scalar(v):
            out[key] = v
    return out


def _split(data):
    """BEM scalars, FEM scalars (or None) and the leftovers of result.json."""
    times = data.get("wall_time_s")
    bem = dict(data["bem"]) if isinstance(data.get("bem"), Mapping) else {
        k: data[k] for k in SCALAR_KEYS if k in data and k != "wall_time_s"}
    fem = dict(data["fem"]) if isinstance(data.get("fem"), Mapping) else None
    if isinstance(times, Mapping):
        if times.get("bem") is not None:
            bem.setdefault("wall_time_s", times["bem"])
        if isinstance(times.get("fem"), (int, float)) and not isinstance(times.get("fem"), bool):
            fem = {} if fem is None else fem
            fem.setdefault("wall_time_s", times["fem"])
    elif isinstance(times, (int, float)):
        bem.setdefault("wall_time_s", times)
    used = set(_META_KEYS) | (set(SCALAR_KEYS) if not isinstance(data.get("bem"), Mapping) else set())
    other = {k: v for k, v in data.items() if k not in used and _scalar(v)}
    return bem, fem, other


def _read_json(path):
    try:
        return json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise InputError(f"{path} is not allowed: it must be a readable JSON file ({exc}).") from None


def _study(path):
    try:
        data = _read_json(path)
    except InputError as exc:
        log.warning("skipping %s: %s", path, exc)
        return None
    if isinstance(data, Mapping) and isinstance(data.get("rows"), list):
        rows, meta = data["rows"], {k: v for k, v in data.items() if k != "rows"}
    elif isinstance(data, list):
        rows, meta = data, {}
    else:
        return None
    rows = [r for r in rows if isinstance(r, Mapping)]
    if not rows:
        return None
    title = str(meta.get("title") or meta.get("name") or Path(path).stem.replace("_", " "))
    return title, {"rows": rows, **meta}


def _bem_field_npz(path):
    with np.load(path) as z:
        if all(k in z for k in ("x", "y", "p")):
            return tuple(np.asarray(z[k], dtype=float).ravel() for k in ("x", "y", "p"))
    return None


def _mesh_fields(path):
    """``("bem", (x, y, p))`` or ``("fem", (r, z, tri, vm))`` from a ParaView file, or None."""
    import meshio

    try:
        mesh = meshio.read(path)
    except Exception as exc:  # noqa: BLE001 - any reader error means "not a field we understand"
        log.warning("skipping %s: meshio cannot read it (%s)", path, exc)
        return None
    tris = [c.data[:, :3] for c in mesh.cells if c.type in ("triangle", "triangle6")]
    if "von_mises" in mesh.point_data and tris:
        return "fem", (mesh.points[:, 0], mesh.points[:, 1], np.vstack(tris),
                       np.asarray(mesh.point_data["von_mises"], dtype=float))
    for name in _PRESSURE_NAMES:
        if name in mesh.point_data:
            p = np.asarray(mesh.point_data[name], dtype=float).ravel()
            if p.size == mesh.points.shape[0]:
                return "bem", (mesh.points[:, 0], mesh.points[:, 1], p)
    return None


def load_results(directory):
    """Read a results directory (see the module docstring for what is understood).

    Raises
    ------
    bem._validate.InputError
        ``directory`` is not a directory or has no readable ``result.json``.
    """
    directory = Path(directory)
    if not directory.is_dir():
        raise InputError(f"directory = {str(directory)!r} is not allowed: it must be a results directory.")
    main = directory / "result.json"
    if not main.is_file():
        raise InputError(f"directory = {str(directory)!r} is not allowed: it has no result.json "
                         "(run the scene first: contactlab run SCENE --out DIR).")
    data = _read_json(main)
    if not isinstance(data, Mapping):
        raise InputError(f"{main} is not allowed: it must hold a JSON object.")
    bem, fem, other = _split(data)
    comparison = next((data[k] for k in ("comparison", "comparisons", "metrics") if isinstance(data.get(k), Mapping)),
                      {})
    scene = dict(data["scene"]) if isinstance(data.get("scene"), Mapping) else {}
    res = RunResults(directory=directory, bem=bem, fem=fem, comparison=_flatten(comparison), scene=scene,
                     units=data.get("units", scene.get("units")), other=other)
    candidates = sorted(directory.glob("*.json")) + sorted((directory / "studies").glob("*.json"))
    for path in candidates:
        if path.name != "result.json":
            study = _study(path)
            if study is not None:
                res.studies.append(study)
    for path in sorted(directory.glob("*.npz")):
        res.bem_field = res.bem_field or _bem_field_npz(path)
    for path in sorted(p for ext in ("vtu", "vtk", "vtp") for p in directory.glob(f"*.{ext}")):
        got = _mesh_fields(path)
        if got is not None and got[0] == "bem" and res.bem_field is None:
            res.bem_field = got[1]
        elif got is not None and got[0] == "fem" and res.fem_field is None:
            res.fem_field = got[1]
    return res
