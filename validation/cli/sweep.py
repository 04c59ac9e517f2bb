"""``contactlab sweep SCENE``: one scene over a list of values of a parameter (resumable, parallel)."""

from __future__ import annotations

from pathlib import Path

from bem.checks import InputError

from ..labels import fmt
from ..run.cluster import DEFAULT_TIMEOUT
from ..scene.checks import MAX_SWEEP_POINTS
from .common import ProgressBar, add_set, add_trust, option_names, trust

PARSER = {"help": "sweep one scene parameter (resumable, parallel)",
          "description": "Run a scene for each value of one parameter. Finished points are saved "
                         "one file each, keyed by the point's scene and the contents of its files; "
                         "rerunning into the same --out skips them (resume), and other values extend "
                         "the folder (the summary lists every point). A folder of another sweep "
                         "(another parameter, scene or file contents) is refused: no point is "
                         f"overwritten. At most {MAX_SWEEP_POINTS} values. --out DIR is the sweep "
                         "directory itself; it must be new, empty or a sweep directory contactlab wrote "
                         "(marked by DIR/.contactlab).",
          "epilog": "examples:\n  contactlab sweep paper_elastic_rigid                 (its [sweep])\n"
                    "  contactlab sweep paper_bilinear --param alpha_c --values 0,0.4,0.8,1.2\n"
                    "  contactlab sweep hertz --param load.force --values 50:200:4 --workers 2\n"
                    "  contactlab sweep paper_linear --param layer.law --values linear,none\n"
                    "  contactlab sweep hertz --param load.force --values 50,100 --scheduler tcp://host:8786"}


def add_args(p):
    p.add_argument("scene", metavar="SCENE")
    p.add_argument("--param", metavar="P", help="alpha_a, alpha_b, alpha_c or a dotted key (layer.lam, load.force)")
    p.add_argument("--values", metavar="V", help="comma list of numbers or words (0,0.25,0.5 or none,tabulated) "
                                                 f"or start:stop:num; at most {MAX_SWEEP_POINTS} values")
    p.add_argument("--out", metavar="DIR", help="the sweep directory written (default: "
                                                "results/<scene name>-sweep-<param>)")
    p.add_argument("--workers", type=int, metavar="N", help="local worker processes (default: all cores)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler address host:port or tcp://host:port "
                                                          "(needs dask.distributed)")
    p.add_argument("--scheduler-timeout", type=float, default=DEFAULT_TIMEOUT, metavar="S",
                   help=f"seconds allowed to reach the scheduler (default {DEFAULT_TIMEOUT:g})")
    p.add_argument("--no-fem", action="store_true",
                   help="skip the scene's [fem]: no FEM reference, and no need of the fem extra (gmsh, scikit-fem)")
    add_set(p)
    add_trust(p)


def run(args):
    from ..io import check_output_dir, output_errors
    from ..run.sweep import SWEEP_NAMES, parse_values, run_sweep, sweep_points
    from ..scene import load_scene

    values = parse_values(args.values) if args.values is not None else None
    if (args.param is None) != (values is None):
        raise InputError("--param and --values are not allowed alone: give both (or neither, to use the "
                         "scene's [sweep]).")
    scene = load_scene(args.scene, overrides=args.overrides, no_fem=args.no_fem, **trust(args))
    with option_names({"sweep.parameter": "--param"} if args.param is not None else {}):
        param, _key, points = sweep_points(scene, args.param, values)
    if args.out:
        out, what, value = Path(args.out), "--out", None
    else:
        out, what, value = Path("results") / f"{scene.name}-sweep-{param}", "scene.name", scene.name
    check_output_dir(out, "sweep", SWEEP_NAMES, what=what, value=value)
    bar = ProgressBar(f"sweep {param}", "point", args.no_progress or None)
    try:
        with output_errors(out, "--out" if args.out else "out_dir"), option_names({"workers": "--workers"}):
            summary = run_sweep(scene, out, parameter=args.param, values=values, workers=args.workers,
                                scheduler=args.scheduler, scheduler_timeout=args.scheduler_timeout,
                                progress=bar)
    finally:
        bar.close()
    print(f"sweep of {summary['key']} over {len(summary['points'])} values of scene {summary['scene']} "
          f"[units {summary['units']}]")
    print(f"{'value':>12} {'status':>14} {'p_max':>14} {'contact_r':>12} {'approach':>12}")
    for r in summary["points"]:
        print(f"{r['value']!s:>12} {r['status']:>14} {fmt(r.get('p_max'), 6):>14} "
              f"{fmt(r.get('contact_radius'), 6):>12} {fmt(r.get('approach'), 6):>12}")
    kept = f", {len(summary['kept'])} more from earlier runs" if summary["kept"] else ""
    print(f"computed {len(summary['computed'])}, reused {len(summary['reused'])}, failed {len(summary['failed'])}"
          f"{kept}; files {out}/ (summary.json, summary.csv, points/)")
    bad = summary["failed"] or any(r["status"] != "converged" for r in summary["points"])
    return 1 if bad else 0
