"""``contactlab scenes``: list the built-in scenes."""

from __future__ import annotations

PARSER = {"help": "list the built-in scenes", "description": "List the built-in scenes.",
          "epilog": "example:\n  contactlab scenes"}


def add_args(p):
    """No options."""


def run(args):
    from ..scene import builtin_scenes

    scenes = builtin_scenes()
    width = max(map(len, scenes))
    for name, desc in scenes.items():
        print(f"{name:<{width}}  {desc}")
    print("\nrun one with: contactlab run NAME   (files: validation/scenes/NAME.toml)")
    return 0
