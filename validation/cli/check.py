"""``contactlab check SCENE``: validate a scene (and every point of its sweep); run nothing."""

from __future__ import annotations

from .common import add_set

PARSER = {"help": "validate a scene without running it",
          "description": "Validate a scene (and every point of its sweep); run nothing.",
          "epilog": "examples:\n  contactlab check my.toml\n  contactlab check hertz --set load.force=-1"}


def add_args(p):
    p.add_argument("scene", metavar="SCENE")
    add_set(p)


def run(args):
    from ..scene import load_scene

    scene = load_scene(args.scene, overrides=args.overrides)
    parts = ["bem"] + [k for k in ("fem", "analytic", "sweep", "stress", "report") if getattr(scene, k) is not None]
    b = scene.bem
    print(f"{scene.name}: OK ({', '.join(parts)}); lattice step {b['step']:.4g}, region "
          f"{b['extent'][0]:.4g} x {b['extent'][1]:.4g}, {b['n_nodes']} nodes   [units {scene.units.label}]")
    return 0
