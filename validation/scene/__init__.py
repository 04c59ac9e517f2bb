"""Scenes: TOML files that describe one contact problem and what to run on it (docs/scenes.md).

- :mod:`validation.scene.load`: the :class:`Scene`, loading, overrides;
- :mod:`validation.scene.source`: the built-in scenes, reading a scene file;
- :mod:`validation.scene.schema`: the validator of each section;
- :mod:`validation.scene.paper`: the paper's layer parameters (``lam_over_cnn``, ``alpha_*``);
- :mod:`validation.scene.sizing`: the lattice and candidate region from the expected contact;
- :mod:`validation.scene.measured`: measured surfaces as the gap;
- :mod:`validation.scene.checks`: the checks, whose errors name the dotted key;
- :mod:`validation.scene.study`: scenes that run a built-in study (``[study]``);
- :mod:`validation.scene.trust`: the code and files a scene may reach (opt-in).
"""

from .checks import SceneError
from .load import (SECTIONS, Scene, apply_overrides, builtin_path, builtin_scenes, check_scene, load_scene,
                   parse_override, parse_scene)
from .study import StudyScene

__all__ = ["Scene", "SceneError", "load_scene", "check_scene", "parse_scene", "builtin_scenes", "builtin_path",
           "apply_overrides", "parse_override", "SECTIONS", "StudyScene"]
