"""``contactlab check SCENE``: validate a scene (and every point of its sweep); run nothing."""

from __future__ import annotations

from .common import add_set, add_trust

PARSER = {"help": "validate a scene without running it",
          "description": "Validate a scene (and every point of its sweep); run nothing. Every error is "
                         "listed at once. Python code the scene names is checked for its form, never "
                         "imported.",
          "epilog": "examples:\n  contactlab check my.toml\n  contactlab check hertz --set load.force=-1"}


def add_args(p):
    p.add_argument("scene", metavar="SCENE")
    add_set(p)
    add_trust(p, code=False)


def run(args):
    from ..extras import require as require_extra
    from ..scene import StudyScene, check_scene

    scene = check_scene(args.scene, overrides=args.overrides, allow_outside_files=args.allow_outside_files)
    if isinstance(scene, StudyScene):
        options = ", ".join(f"{k} = {'true' if v is True else 'false' if v is False else repr(v)}" for k, v in scene.options.items())
        print(f"{scene.name}: OK (study {scene.study}{', ' + options if options else ''})")
        return 0
    if scene.fem is not None:
        require_extra("fem", f"[fem] of scene {scene.name!r} (the FEM reference; contactlab run --no-fem skips it)")
    parts = ["bem"] + [k for k in ("fem", "analytic", "sweep", "stress", "report") if getattr(scene, k) is not None]
    b = scene.bem
    if b.get("periodic"):
        where = f"periodic cell {b['size'][0]:.4g} x {b['size'][1]:.4g} of {b['cell'][0]} x {b['cell'][1]}"
    else:
        where = f"region {b['extent'][0]:.4g} x {b['extent'][1]:.4g}"
    print(f"{scene.name}: OK ({', '.join(parts)}); lattice step {b['step']:.4g}, {where}, {b['n_nodes']} nodes   "
          f"[units {scene.units.label}]")
    for key, name in scene.unimported:
        print(f"note: {key} = {name!r} names Python code, not imported here; run the scene with --allow-code "
              "if you trust it.")
    return 0
