"""Scenes that run a built-in study: a ``[study]`` section instead of a contact problem.

A study scene holds ``[scene]`` (name, title, description) and ``[study]``: ``name``, one of
:data:`STUDY_OPTIONS`, and that study's options. ``contactlab run`` runs the study and writes
its files into the result folder. The study builds its own problems, so the sections of a
contact problem (``[bodies]``, ``[bem]``, ``[fem]``...) are refused, naming the key.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from . import checks as ck
from . import schema as sec
from .checks import SceneError, closest

__all__ = ["StudyScene", "STUDY_OPTIONS", "is_study_scene", "parse_study_scene", "refuse_study"]

#: study name -> {option: check(dotted key, value)}
STUDY_OPTIONS = {"two-scale": {"quick": ck.boolean}}


@dataclass(frozen=True)
class StudyScene:
    """A validated study scene: ``study`` (a name of :data:`STUDY_OPTIONS`) run with ``options``."""

    name: str
    title: str
    description: str
    source: str
    raw: dict
    study: str
    options: dict = field(default_factory=dict)
    overrides: tuple = field(default=())


def is_study_scene(raw):
    """Whether the parsed TOML ``raw`` has a ``[study]`` section."""
    return isinstance(raw, Mapping) and "study" in raw


def parse_study_scene(raw, source="<dict>", overrides=()):
    """Validate a study scene (``raw`` with its overrides applied); returns a :class:`StudyScene`.

    Raises
    ------
    SceneError
        A section other than ``[scene]`` and ``[study]`` (the key is named), an unknown study
        or option (with the closest known one), or a bad value.
    """
    for section, d in raw.items():
        if section in ("scene", "study"):
            continue
        keys = list(d) if isinstance(d, Mapping) else []
        key = f"{section}.{keys[0]}" if keys else section
        shown = d[keys[0]] if keys else d
        raise SceneError(f"{key} = {shown!r} is not allowed: a scene with [study] runs a built-in study, which "
                         f"builds its own problems and ignores [{section}]; remove it.")
    meta = sec.scene_meta(ck.table("scene", raw.get("scene", {})))
    study = ck.table("study", raw["study"])
    name = ck.string("study.name", ck.require("study", study, "name", 'give a built-in study, e.g. name = "two-scale"'))
    if name not in STUDY_OPTIONS:
        raise SceneError(f"study.name = {name!r} is not allowed: it must be one of {', '.join(STUDY_OPTIONS)}."
                         f"{closest(name, STUDY_OPTIONS)}")
    rules = STUDY_OPTIONS[name]
    ck.unknown_keys("study", study, ["name", *rules])
    return StudyScene(name=meta["name"], title=meta["title"], description=meta["description"], source=source,
                      raw=raw, study=name, options=ck.options("study", study, rules), overrides=tuple(overrides))


def refuse_study(scene, what):
    """Raise :class:`SceneError` when ``scene`` is a :class:`StudyScene`: ``what`` (``"a sweep"``)
    needs one contact problem, and the scene runs a study (``contactlab run`` does)."""
    if isinstance(scene, StudyScene):
        raise SceneError(f"scene = {scene.name!r} is not allowed: {what} needs a contact problem, and this scene "
                         f"runs the built-in study {scene.study!r} ([study]); run it with `contactlab run "
                         f"{scene.name}` and report its result folder.")
