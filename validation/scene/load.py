"""Scenes: TOML files that describe one contact problem and what to run on it (docs/scenes.md).

A scene file has the sections (units: those of ``[scene] units``, SI by default)::

    [scene]    name, title, description, units           (name required)
    [bodies]   E1, nu1, E2, nu2 [Pa, -] or E_star [Pa] alone; coating1, coating2 = {thickness [m], E [Pa], nu}; hardness
    [gap]      type + parameters of a bem.gaps shape      (paraboloid: R [m], ...), or
               type = "measured" with a file (validation.scene.measured)
    [layer]    law + parameters of a bem.layers law, or the paper's lam_over_cnn with cnn_step,
               lam_ref, alpha_a, alpha_b, alpha_c (validation.scene.paper), or law = "tabulated"
               with a law file (validation.scene.layer_file); absent or law = "none": no layer
    [load]     force [N] or approach [m] (a periodic cell: or mean_pressure [Pa])
    [bem]      step [m] or nodes_across; extent [m] or extent_factor; method, rtol, maxiter,
               precondition, nested, relaxation; a rough gap (validation.scene.rough):
               periodic = true, cell_nodes
    [fem]      only when an FEM reference is wanted (axisymmetric gaps): n_contact_elements, domain_factor, ...
    [analytic] only when wanted: kind = "hertz" | "hertz_elliptic" | "rigid_layer"
    [sweep]    only when wanted: parameter, values
    [report]   only when wanted: sections, format
    [stress]   only when wanted: depths ("auto" or a list [m]), n_depths, max_depth, bodies

A scene with ``[study]`` (name, options) and ``[scene]`` alone runs a built-in study instead
(:mod:`validation.scene.study`); it loads as a :class:`~validation.scene.study.StudyScene`.

:func:`load_scene` validates the WHOLE scene (every point of its sweep included) before any
work: unknown keys, wrong types, out-of-range values, missing keys and impossible combinations
raise :class:`SceneError` whose message names the dotted key (``layer.lam``), the value and
the rule. Built-in scenes ship in ``validation/scenes/*.toml`` and are addressed by name.
"""

from __future__ import annotations

import copy
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..extras import require as require_extra
from ..units import Units
from . import checks as ck
from . import schema as sec
from .checks import SceneError, closest
from .coatings import coated_sections
from .measured import measured_region
from .paper import ALIASES
from .paper import EXCLUSIVE as LAYER_EXCLUSIVE
from .rough import bem_section
from .sizing import EXCLUSIVE as BEM_EXCLUSIVE
from .source import builtin_path, builtin_scenes, read_source, read_toml
from .study import StudyScene, is_study_scene, parse_study_scene
from .layer_file import EXCLUSIVE as FILE_EXCLUSIVE
from .layer_file import resolve_layer_file
from .trust import check_code_name, code_names, refuse_code, scene_file

__all__ = ["Scene", "SceneError", "load_scene", "check_scene", "parse_scene", "builtin_scenes", "builtin_path",
           "read_toml", "apply_overrides", "parse_override", "SECTIONS"]

SECTIONS = ("scene", "bodies", "gap", "layer", "load", "bem", "fem", "analytic", "sweep", "report", "stress")
_REQUIRED = ("scene", "bodies", "gap", "load")
#: section -> groups of keys that replace each other (a ``--set`` of one drops the others)
_EXCLUSIVE = {"bem": BEM_EXCLUSIVE, "load": (("force", "approach", "mean_pressure"),),
              "layer": LAYER_EXCLUSIVE + FILE_EXCLUSIVE,
              "bodies": tuple(("E_star", key) for key in sec.BODY_KEYS)}


@dataclass(frozen=True)
class Scene:
    """A validated scene. ``raw`` is the TOML content (overrides applied), re-loadable as is.

    ``units`` is the parsed ``[scene] units`` label; ``gap`` the :mod:`bem.gaps` shape;
    ``layer_spec`` the validated ``[layer]`` and ``layer`` the law built from it once (``None``
    without a layer, or for a law of the paper's parameters, which the runner resolves);
    ``bem`` the solver options with the resolved lattice (:func:`validation.scene.sizing.bem_options`).
    ``hardness``: ``bodies.hardness`` [pressure] that caps the pressure of the run's solve, ``None``: elastic.
    ``base_dir``, ``allow_code`` and ``allow_outside_files``: the folder its file names start
    from and what it may reach (:attr:`trust`); ``unimported``: ``(key, "module:function")``
    of code named but not imported (:func:`check_scene`; such a scene does not run);
    ``skipped``: sections dropped at load (``("fem",)`` with ``no_fem``).
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
    coatings: dict | None = None
    base_dir: str | None = None
    allow_code: bool = False
    allow_outside_files: bool = False
    unimported: tuple = field(default=())
    skipped: tuple = field(default=())
    hardness: float | None = None

    @property
    def trust(self):
        """The keywords of :func:`parse_scene` that re-validate ``raw`` as this scene was: its
        folder and what it was allowed (:mod:`validation.scene.trust`)."""
        return {"base_dir": self.base_dir, "allow_code": self.allow_code,
                "allow_outside_files": self.allow_outside_files}

    @property
    def axisymmetric(self):
        """Whether the gap is axisymmetric (contact radius and FEM reference apply)."""
        return bool(self.gap.is_axisymmetric)


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


def _allowed_keys(section, d):
    """The keys ``[section]`` may hold, or ``None`` when they depend on a value its validator checks."""
    keys = sec.scene_keys()[section]
    if section not in ("gap", "layer"):
        return keys[""]
    variant = d.get("type" if section == "gap" else "law")
    if not isinstance(variant, str) or (variant not in keys and variant != "none"):
        return None
    return (*keys[""], *keys.get(variant, ()))


def _known_keys_only(raw, check):
    """``raw`` without the unknown keys of its sections, each recorded as an error of ``check``.

    Every misspelled key is reported in the same pass as the other errors, also in a section whose
    validator waits for another section; the validators then see only known keys.
    """
    out = {}
    for section, d in raw.items():
        allowed = _allowed_keys(section, d) if section in SECTIONS and isinstance(d, dict) else None
        if allowed is None or all(k in allowed for k in d):
            out[section] = d
            continue
        check(ck.unknown_keys, section, d, allowed)
        out[section] = {k: v for k, v in d.items() if k in allowed}
    return out


def _code(raw, mode, check):
    """Sections that name Python code (:mod:`validation.scene.trust`), and what to do with them.

    ``mode``: ``"import"`` (allowed), ``"form"`` (checked, not imported: ``contactlab check``)
    or ``"refuse"``. Returns ``(sections not to build, (key, name) pairs not imported)``.
    """
    names = code_names(raw)
    if mode == "import":
        return set(), ()
    for key, value in names:
        if check(check_code_name, key, value) is not check.FAILED and mode == "refuse":
            check.fail(refuse_code(key, value))
    return {key.split(".")[0] for key, _ in names}, tuple(names)


def _validate(raw, source, overrides, *, base_dir=None, code="refuse", outside_files=False):
    if not isinstance(raw, dict):
        raise SceneError(f"scene = {raw!r} is not allowed: it must be a table of sections.")
    check = _Collect()
    for key, value in raw.items():
        if key not in SECTIONS:
            check.fail(f"{key} = {'{...}' if isinstance(value, dict) else repr(value)} is not allowed: "
                       f"there is no section [{key}] (sections: {', '.join(SECTIONS)}).{closest(key, SECTIONS)}")
    raw = _known_keys_only(raw, check)
    for key in _REQUIRED:
        if key not in raw:
            check.fail(f"[{key}] is missing: every scene needs the sections " + ", ".join(_REQUIRED) + ".")
    coded, unimported = _code(raw, code, check)
    section = {k: (raw[k] if k in raw else check.FAILED) for k in _REQUIRED}
    if check(_resolve_files, raw, base_dir, outside_files) is check.FAILED:
        section["gap"] = check.FAILED
    layer_file = check(resolve_layer_file, raw, base_dir, outside_files)
    meta = check(sec.scene_meta, section["scene"])
    body = check(sec.bodies, section["bodies"])
    load = check(sec.load, section["load"])
    if code == "refuse":  # refused above: build nothing that imports
        section["gap"] = check.FAILED if "gap" in coded else section["gap"]
    layer_raw = check.FAILED if code == "refuse" and "layer" in coded else raw.get("layer")
    layer_raw = check.FAILED if layer_file is check.FAILED else layer_raw
    build = {part: code == "import" or part not in coded for part in ("gap", "layer")}
    shape = check(lambda d, b, m: sec.gap(d, b["E_star"], units=m["units"], build=build["gap"], base_dir=base_dir),
                  section["gap"], body, meta)
    layer = check(lambda d: sec.layer(d, build=build["layer"], E_star=None if body is check.FAILED else body["E_star"]),
                  layer_raw)
    bem = check(lambda g, la, b, ld: bem_section(raw.get("bem"), g[1], *la, b["E_star"], ld, raw.get("stress")),
                shape, layer, body, load)
    shape = check(lambda g, b: (g[0], measured_region(g[1], b["extent"])), shape, bem)
    fem = check(lambda g, b: sec.fem_options(raw.get("fem"), g[1], b["materials"]), shape, body)
    analytic = check(lambda g, la: sec.analytic(raw.get("analytic"), g[1], la[0]), shape, layer)
    sweep = check(sec.sweep_spec, raw.get("sweep"), SECTIONS)
    report = check(sec.report, raw.get("report"))
    stress = check(lambda b, bo: sec.stress_options(raw.get("stress"), b["materials"], bo["step"]), body, bem)
    stress = check(lambda st, bo: sec.stress_depth_bound(st, bo["extent"]), stress, bem)
    stress = check(lambda b, st: coated_sections(b["coatings"], raw, st, b["materials"]), body, stress)
    hardness = check(sec.hardness_bound, body, load, bem, fem, analytic)
    if check.errors:
        raise SceneError.of(check.errors)
    return Scene(
        name=meta["name"], title=meta["title"], description=meta["description"], units=meta["units"],
        source=source, raw=raw, E_star=body["E_star"], materials=body["materials"], gap=shape[1],
        gap_spec=shape[0], layer_spec=layer[0], layer=layer[1], load=load, bem=bem, fem=fem, analytic=analytic,
        sweep=sweep, report=report, overrides=tuple(overrides), stress=stress, coatings=body["coatings"],
        base_dir=None if base_dir is None else str(base_dir), allow_code=code == "import",
        allow_outside_files=outside_files, unimported=unimported, hardness=hardness,
    )


def _check_sweep_points(scene, **kw):
    """Every point of the scene's own sweep must be a valid scene too."""
    base = {k: v for k, v in scene.raw.items() if k != "sweep"}
    for i, value in enumerate(scene.sweep["values"]):
        try:
            _validate(apply_overrides(base, {scene.sweep["key"]: value}), scene.source, (), **kw)
        except SceneError as exc:
            raise SceneError(f"sweep.values[{i}] = {value!r} gives an invalid scene: {exc}") from None


def _resolve_files(raw, base_dir, allow_outside):
    """Make the file a scene names (``gap.file`` of a measured or surface gap) absolute, relative to ``base_dir``
    (:func:`validation.scene.trust.scene_file`)."""
    gap = raw.get("gap")
    if isinstance(gap, dict) and gap.get("type") in ("measured", "surface") and isinstance(gap.get("file"), str):
        gap["file"] = scene_file("gap.file", gap["file"], base_dir, allow_outside=allow_outside)


def _parse(raw, source, overrides, base_dir, code, allow_outside_files, no_fem=False):
    overrides = list(overrides.items()) if isinstance(overrides, dict) else list(overrides or ())
    raw = apply_overrides(raw, overrides)
    if is_study_scene(raw):
        return parse_study_scene(raw, source, [o if isinstance(o, str) else f"{o[0]}={o[1]!r}" for o in overrides])
    skipped = ("fem",) if no_fem and "fem" in raw else ()
    raw = {k: v for k, v in raw.items() if k not in skipped}
    kw = {"base_dir": Path.cwd() if base_dir is None else Path(base_dir), "code": code,
          "outside_files": allow_outside_files}
    scene = _validate(raw, source, [o if isinstance(o, str) else f"{o[0]}={o[1]!r}" for o in overrides], **kw)
    if scene.sweep is not None:
        _check_sweep_points(scene, **kw)
    return replace(scene, skipped=skipped) if skipped else scene


def parse_scene(raw, *, source="<dict>", overrides=None, base_dir=None, allow_code=False,
                allow_outside_files=False, no_fem=False):
    """Validate a scene given as a dict (the parsed TOML); returns a :class:`Scene`, or a
    :class:`~validation.scene.study.StudyScene` for a scene with ``[study]``.

    ``base_dir`` is the folder that relative file names in the scene (``gap.file``) start
    from: the scene file's folder (:func:`load_scene`), the current directory by default.
    ``Scene.raw`` holds them made absolute. ``allow_code`` imports the Python code the scene
    names (``gap.function``, ``layer.w``...) and ``allow_outside_files`` reads files outside
    ``base_dir``; both are refused by default (:mod:`validation.scene.trust`). ``no_fem``
    drops the scene's ``[fem]`` (no FEM reference, no need of the ``fem`` extra), noted in
    :attr:`Scene.skipped`.

    Raises
    ------
    SceneError
        Anything wrong in the scene.
    validation.extras.MissingExtraError
        The scene has ``[fem]`` but gmsh or scikit-fem cannot be imported ("install
        contactlab[fem]"); nothing has run.
    """
    scene = _parse(raw, source, overrides, base_dir, "import" if allow_code else "refuse", allow_outside_files, no_fem)
    if not isinstance(scene, StudyScene) and scene.fem is not None:
        require_extra("fem", f"[fem] of scene {scene.name!r} (the FEM reference)")
    return scene


def load_scene(source, *, overrides=None, allow_code=False, allow_outside_files=False, no_fem=False):
    """Load and validate a scene: a built-in name, a path to a TOML file, a dict or a Scene.

    Parameters
    ----------
    source : str, path-like, dict or Scene
        Built-in name (``contactlab scenes`` lists them) or TOML file path. A Scene is
        re-validated with its own folder and permissions (:attr:`Scene.trust`).
    overrides : dict or list of str, optional
        Dotted-key overrides (:func:`apply_overrides`), validated with the rest.
    allow_code, allow_outside_files : bool
        Import the Python code the scene names; read files outside the scene's folder
        (:mod:`validation.scene.trust`). Refused by default.
    no_fem : bool
        Drop the scene's ``[fem]``: run it without the FEM reference (:attr:`Scene.skipped`).

    Raises
    ------
    SceneError
        Anything wrong in the scene (the message names the key), or an unknown scene.
    """
    if isinstance(source, (Scene, StudyScene)):
        trust = source.trust if isinstance(source, Scene) else {}
        return parse_scene(source.raw, source=source.source, overrides=overrides, no_fem=no_fem, **trust)
    kw = {"allow_code": allow_code, "allow_outside_files": allow_outside_files, "no_fem": no_fem}
    if isinstance(source, dict):
        return parse_scene(source, overrides=overrides, **kw)
    raw, label, folder = read_source(source)
    return parse_scene(raw, source=label, overrides=overrides, base_dir=folder, **kw)


def check_scene(source, *, overrides=None, allow_outside_files=False):
    """Validate a scene as :func:`load_scene` does, importing no code and needing no extra.

    The Python code a scene names is checked for its form only; such a scene is returned with
    the names in :attr:`Scene.unimported`, and does not run. Used by ``contactlab check``.
    """
    if isinstance(source, dict):
        raw, label, folder = source, "<dict>", None
    else:
        raw, label, folder = read_source(source)
    return _parse(raw, label, overrides, folder, "form", allow_outside_files)
