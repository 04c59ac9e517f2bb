"""Scenes: TOML files that describe one contact problem and what to run on it (docs/scenes.md).

A scene file has the sections (units: those of ``[scene] units``, SI by default)::

    [scene]    name, title, description, units           (name required)
    [bodies]   E1, nu1, E2, nu2 [Pa, -]  -- or E_star [Pa] alone
    [gap]      type + parameters of a bem.gaps shape      (paraboloid: R [m], ...), or
               type = "measured" with a file (validation.scene.measured)
    [layer]    law + parameters of a bem.layers law, or the paper's lam_over_cnn with cnn_step,
               lam_ref, alpha_a, alpha_b, alpha_c (validation.scene.paper); absent or
               law = "none": no layer
    [load]     force [N] or approach [m]
    [bem]      step [m] or nodes_across; extent [m] or extent_factor; method, rtol, maxiter,
               precondition, nested, relaxation
    [fem]      only when an FEM reference is wanted (axisymmetric gaps): n_contact, extent, ...
    [analytic] only when wanted: kind = "hertz" | "hertz_elliptic" | "rigid_layer"
    [sweep]    only when wanted: parameter, values
    [report]   only when wanted: sections, format
    [stress]   only when wanted: depths ("auto" or a list [m]), n_depths, max_depth, bodies

:func:`load_scene` validates the WHOLE scene (every point of its sweep included) before any
work: unknown keys, wrong types, out-of-range values, missing keys and impossible combinations
raise :class:`SceneError` whose message names the dotted key (``layer.lam``), the value and
the rule. Built-in scenes ship in ``validation/scenes/*.toml`` and are addressed by name.
"""

from __future__ import annotations

import copy
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from ..extras import require as require_extra
from ..provenance import display_path
from ..units import Units
from . import schema as sec
from .checks import SceneError
from .measured import measured_region
from .paper import ALIASES
from .paper import EXCLUSIVE as LAYER_EXCLUSIVE
from .sizing import EXCLUSIVE as BEM_EXCLUSIVE
from .sizing import bem_options

__all__ = ["Scene", "SceneError", "load_scene", "parse_scene", "builtin_scenes", "builtin_path",
           "apply_overrides", "parse_override", "SECTIONS"]

SECTIONS = ("scene", "bodies", "gap", "layer", "load", "bem", "fem", "analytic", "sweep", "report", "stress")
_REQUIRED = ("scene", "bodies", "gap", "load")
#: section -> groups of keys that replace each other (a ``--set`` of one drops the others)
_EXCLUSIVE = {"bem": BEM_EXCLUSIVE, "load": (("force", "approach"),), "layer": LAYER_EXCLUSIVE,
              "bodies": tuple(("E_star", key) for key in sec.BODY_KEYS)}


@dataclass(frozen=True)
class Scene:
    """A validated scene. ``raw`` is the TOML content (overrides applied), re-loadable as is.

    ``units`` is the parsed ``[scene] units`` label; ``gap`` the :mod:`bem.gaps` shape;
    ``layer_spec`` the validated ``[layer]`` and ``layer`` the law built from it once (``None``
    without a layer, or for a law of the paper's parameters, which the runner resolves);
    ``bem`` the solver options with the resolved lattice (:func:`validation.scene.sizing.bem_options`).
    """

    name: str
    title: str
    description: str
    units: Units
    source: str
    raw: dict
    E_star: float
    materials: dict | None
    gap: object
    gap_spec: dict
    layer_spec: dict | None
    layer: object
    load: dict
    bem: dict
    fem: dict | None = None
    analytic: dict | None = None
    sweep: dict | None = None
    report: dict | None = None
    overrides: tuple = field(default=())
    stress: dict | None = None

    @property
    def axisymmetric(self):
        """Whether the gap is axisymmetric (contact radius and FEM reference apply)."""
        return bool(self.gap.is_axisymmetric)


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


def parse_override(text):
    """``"section.key=value"`` -> ``("section.key", value)``; value parsed as TOML, else a string."""
    if not isinstance(text, str) or "=" not in text:
        raise SceneError(f"--set {text!r} is not allowed: it must be section.key=value, e.g. bem.nodes_across=20.")
    key, value = (s.strip() for s in text.split("=", 1))
    try:
        parsed = tomllib.loads(f"v = {value}")["v"]
    except tomllib.TOMLDecodeError:
        parsed = value
    return key, parsed


def _exclusive_partners(section, key):
    """Keys of ``section`` that a new value of ``key`` replaces."""
    return {other for group in _EXCLUSIVE.get(section, ()) if key in group for other in group if other != key}


def apply_overrides(raw, overrides):
    """A deep copy of ``raw`` with dotted-key overrides applied.

    Parameters
    ----------
    raw : dict
        Scene content.
    overrides : dict or iterable of str or (key, value) pairs
        ``{"bem.nodes_across": 20}`` or ``["bem.nodes_across=20", ...]``; the short names
        ``alpha_a``, ``alpha_b``, ``alpha_c`` mean ``layer.alpha_*``. Setting one key of an
        alternative pair drops the other (``bem.step`` replaces ``bem.nodes_across``,
        ``load.force`` replaces ``load.approach``, ``layer.alpha_a`` replaces ``layer.p_cr``...);
        ``layer.law = "none"`` removes the layer.
    """
    out = copy.deepcopy(raw)
    if isinstance(overrides, dict):
        items = list(overrides.items())
    else:
        items = [o if isinstance(o, tuple) else parse_override(o) for o in overrides or ()]
    for key, value in items:
        key = ALIASES.get(key, key)
        parts = key.split(".")
        if len(parts) < 2 or not all(parts):
            raise SceneError(f"--set {key!r} is not allowed: the key must be section.key (e.g. load.force).")
        node = out
        for part in parts[:-1]:
            child = node.setdefault(part, {})
            if not isinstance(child, dict):
                raise SceneError(f"--set {key!r} is not allowed: {part} is not a table in this scene.")
            node = child
        if len(parts) == 2:
            for other in _exclusive_partners(*parts):
                node.pop(other, None)
            if parts == ["layer", "law"] and value == "none":
                node.clear()
        node[parts[-1]] = value
    return out


class _Collect:
    """Runs section validators and keeps every :class:`SceneError` instead of stopping at the first.

    ``check(fn, *needs)`` returns ``fn(*needs)``, or :attr:`FAILED` after recording its
    error; a validator whose inputs (``needs``) failed is skipped (its errors would only
    repeat the first).
    """

    FAILED = object()

    def __init__(self):
        self.errors = []

    def __call__(self, fn, *needs):
        if any(n is self.FAILED for n in needs):
            return self.FAILED
        try:
            return fn(*needs)
        except SceneError as exc:
            self.errors.extend(getattr(exc, "errors", None) or (str(exc),))
            return self.FAILED

    def fail(self, message):
        self.errors.append(message)


def _validate(raw, source, overrides):
    if not isinstance(raw, dict):
        raise SceneError(f"scene = {raw!r} is not allowed: it must be a table of sections.")
    check = _Collect()
    for key, value in raw.items():
        if key not in SECTIONS:
            check.fail(f"{key} = {'{...}' if isinstance(value, dict) else repr(value)} is not allowed: "
                       f"there is no section [{key}] (sections: {', '.join(SECTIONS)}).")
    for key in _REQUIRED:
        if key not in raw:
            check.fail(f"[{key}] is missing: every scene needs the sections " + ", ".join(_REQUIRED) + ".")
    section = {k: (raw[k] if k in raw else check.FAILED) for k in _REQUIRED}
    meta = check(sec.scene_meta, section["scene"])
    body = check(sec.bodies, section["bodies"])
    load = check(sec.load, section["load"])
    shape = check(lambda d, b, m: sec.gap(d, b["E_star"], units=m["units"]), section["gap"], body, meta)
    layer = check(sec.layer, raw.get("layer"))
    bem = check(lambda g, la, b, ld: bem_options(raw.get("bem"), g[1], *la, b["E_star"], ld), shape, layer, body, load)
    shape = check(lambda g, b: (g[0], measured_region(g[1], b["extent"])), shape, bem)
    fem = check(lambda g, b: sec.fem_options(raw.get("fem"), g[1], b["materials"]), shape, body)
    analytic = check(lambda g, la: sec.analytic(raw.get("analytic"), g[1], la[0]), shape, layer)
    sweep = check(sec.sweep_spec, raw.get("sweep"), SECTIONS)
    report = check(sec.report, raw.get("report"))
    stress = check(lambda b, bo: sec.stress_options(raw.get("stress"), b["materials"], bo["step"]), body, bem)
    if check.errors:
        raise SceneError.of(check.errors)
    return Scene(
        name=meta["name"], title=meta["title"], description=meta["description"], units=meta["units"],
        source=source, raw=raw, E_star=body["E_star"], materials=body["materials"], gap=shape[1],
        gap_spec=shape[0], layer_spec=layer[0], layer=layer[1], load=load, bem=bem, fem=fem, analytic=analytic,
        sweep=sweep, report=report, overrides=tuple(overrides), stress=stress,
    )


def _check_sweep_points(scene):
    """Every point of the scene's own sweep must be a valid scene too."""
    base = {k: v for k, v in scene.raw.items() if k != "sweep"}
    for i, value in enumerate(scene.sweep["values"]):
        try:
            _validate(apply_overrides(base, {scene.sweep["key"]: value}), scene.source, ())
        except SceneError as exc:
            raise SceneError(f"sweep.values[{i}] = {value!r} gives an invalid scene: {exc}") from None


def _resolve_files(raw, base_dir):
    """Make the file a scene names (``gap.file`` of a measured gap) absolute, relative to ``base_dir``."""
    gap = raw.get("gap")
    if isinstance(gap, dict) and gap.get("type") == "measured" and isinstance(gap.get("file"), str):
        gap["file"] = str((Path(base_dir) / Path(gap["file"]).expanduser()).absolute())


def parse_scene(raw, *, source="<dict>", overrides=None, base_dir=None):
    """Validate a scene given as a dict (the parsed TOML); returns a :class:`Scene`.

    ``base_dir`` is the folder that relative file names in the scene (``gap.file``) start
    from: the scene file's folder (:func:`load_scene`), the current directory by default.
    ``Scene.raw`` holds them made absolute, so it re-loads from anywhere.

    Raises
    ------
    SceneError
        Anything wrong in the scene.
    validation.extras.MissingExtraError
        The scene has ``[fem]`` but gmsh or scikit-fem cannot be imported ("install
        contactlab[fem]"); nothing has run.
    """
    overrides = list(overrides.items()) if isinstance(overrides, dict) else list(overrides or ())
    raw = apply_overrides(raw, overrides)
    _resolve_files(raw, Path.cwd() if base_dir is None else base_dir)
    scene = _validate(raw, source, [o if isinstance(o, str) else f"{o[0]}={o[1]!r}" for o in overrides])
    if scene.sweep is not None:
        _check_sweep_points(scene)
    if scene.fem is not None:
        require_extra("fem", f"[fem] of scene {scene.name!r} (the FEM reference)")
    return scene


def load_scene(source, *, overrides=None):
    """Load and validate a scene: a built-in name, a path to a TOML file, a dict or a Scene.

    Parameters
    ----------
    source : str, path-like, dict or Scene
        Built-in name (``contactlab scenes`` lists them) or TOML file path.
    overrides : dict or list of str, optional
        Dotted-key overrides (:func:`apply_overrides`), validated with the rest.

    Raises
    ------
    SceneError
        Anything wrong in the scene (the message names the key), or an unknown scene.
    """
    if isinstance(source, Scene):
        return parse_scene(source.raw, source=source.source, overrides=overrides)
    if isinstance(source, dict):
        return parse_scene(source, overrides=overrides)
    path = Path(source)
    if path.suffix == ".toml" or path.exists():
        if not path.is_file():
            raise SceneError(f"scene = {str(source)!r} is not allowed: there is no such file.")
        label = display_path(path)
    else:
        path = builtin_path(str(source))
        label = f"builtin:{source}"
    try:
        with path.open("rb") as fh:
            raw = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"scene file {str(path)!r} is not valid TOML: {exc}.") from None
    return parse_scene(raw, source=label, overrides=overrides, base_dir=path.parent)
