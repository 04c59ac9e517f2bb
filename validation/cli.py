"""The ``contactlab`` command line: run, check and sweep scenes; dispatch studies and reports.

Exit codes: 0 success; 1 a solver did not converge (results are still written, flagged
``converged = false``); 2 bad input (scene, option or output location); 130 interrupted.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import logging
import os
import sys
from pathlib import Path

from bem.checks import InputError

from .scene.paper import CalibrationError

from .io import OutputError

__all__ = ["main", "build_parser"]

log = logging.getLogger(__name__)

DESCRIPTION = """\
contactlab: frictionless normal contact of two elastic bodies with a nonlinear interface
layer (rough surface, coating) between them. Half-space boundary elements (BEM) on a
triangular lattice, an axisymmetric finite-element (FEM) reference, closed-form checks.

A SCENE is a TOML file, or the name of a built-in scene (see `contactlab scenes`). It says
what the bodies, gap, layer and load are and what to run: the BEM always; the FEM reference,
a closed-form comparison, a sweep, the subsurface stresses or a report only when it has a
[fem], [analytic], [sweep], [stress] or [report] section.

Units: every number is in the scene's own consistent units, stated in its [scene] units
label. The built-in scenes use SI: lengths in m, moduli and pressures in Pa, forces in N
(e.g. E1 = 210e9 for steel, R = 0.01 for a 10 mm radius, force = 100.0 for 100 N).
The paper's layer parameters are dimensionless: lam_over_cnn (compliance / C_nn),
alpha_a = p_cr / p_max^lambda, alpha_b = p_max^root / p_max^lambda, alpha_c = arctan(lam2/lam1) [rad].
"""

EPILOG = """\
examples:
  contactlab scenes                                  list the built-in scenes
  contactlab check my_scene.toml                     validate a scene, run nothing
  contactlab run hertz                               BEM + FEM + Hertz; writes results/hertz/
  contactlab run paper_root --out out/root           choose the result directory
  contactlab run hertz --set bem.nodes_across=80 --set load.force=200
                                                     override scene keys (dotted, TOML values)
  contactlab run paper_elastic_rigid --set alpha_a=0.25
  contactlab sweep paper_elastic_rigid --param alpha_a --values 0,0.25,0.5,0.75,1
  contactlab sweep paper_root --param alpha_b --values 0.8:1.1:4 --workers 2
  contactlab sweep hertz --param load.force --values 50,100,200 --scheduler tcp://10.0.0.5:8786
  contactlab study error-time hertz                  error vs time of the BEM methods
  contactlab study stability                         convergence of the methods across layers
  contactlab study robustness                        every layer method over 12 decades of compliance
  contactlab report results/hertz --out report/      figures + HTML/Markdown report
  contactlab report results/hertz-sweep-load.force   report of a sweep directory
  contactlab report paper --quick                    the paper's test problem, a quick preview

result directory (run): result.json (p_max, force, approach, contact_area, contact_radius,
iterations, converged, kkt_residual, wall_time_s, comparison metrics...), scene.toml (the
effective scene, re-runnable), bem_field.vtu, fem_field.vtu and stress_field.vtu (open in ParaView).
Written whole or not at all. Exit codes: 0 ok, 1 not converged, 2 bad input (every error of a
scene is listed), or an unknown option.
"""


#: measured wall time of `contactlab report paper --quick` and of the full paper report on 2 cores shared
#: with other jobs (load 2.3-5; CPU time 15-18 s and 36-42 s)
QUICK_TIME, FULL_TIME = "18-26 s", "50-80 s"
#: figure formats of `contactlab report --format` (validation.report.style.FORMATS, kept here so the
#: parser needs no import of the report package)
FORMATS = ("png", "svg", "pdf")


def _add_set(p, scope=""):
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help=f"{scope}override a scene key, e.g. bem.nodes_across=20, layer.alpha_a=0.3, "
                        "load.force=250.0 (value parsed as TOML; repeatable)")


def build_parser():
    """The argparse parser of ``contactlab``."""
    fmt = argparse.RawDescriptionHelpFormatter
    parser = argparse.ArgumentParser(prog="contactlab", description=DESCRIPTION, epilog=EPILOG, formatter_class=fmt)
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details (INFO)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    p = sub.add_parser("run", help="run a scene and write its result directory", formatter_class=fmt,
                       description="Run a scene: the BEM, and the FEM/closed form/comparison it names.",
                       epilog="examples:\n  contactlab run hertz\n  contactlab run my.toml --out out/my "
                              "--set bem.method=\"augmented_gap\"\n  contactlab run punch --set fem.n_contact=32")
    p.add_argument("scene", metavar="SCENE", help="built-in scene name or path to a .toml file")
    p.add_argument("--out", metavar="DIR", help="result directory (default: results/<scene name>)")
    _add_set(p)

    sub.add_parser("scenes", help="list the built-in scenes", description="List the built-in scenes.",
                   epilog="example:\n  contactlab scenes", formatter_class=fmt)

    p = sub.add_parser("check", help="validate a scene without running it", formatter_class=fmt,
                       description="Validate a scene (and every point of its sweep); run nothing.",
                       epilog="examples:\n  contactlab check my.toml\n  contactlab check hertz --set load.force=-1")
    p.add_argument("scene", metavar="SCENE")
    _add_set(p)

    p = sub.add_parser("sweep", help="sweep one scene parameter (resumable, parallel)", formatter_class=fmt,
                       description="Run a scene for each value of one parameter. Finished points are saved "
                                   "one file each; rerunning skips them (resume).",
                       epilog="examples:\n  contactlab sweep paper_elastic_rigid                 (its [sweep])\n"
                              "  contactlab sweep paper_bilinear --param alpha_c --values 0,0.4,0.8,1.2\n"
                              "  contactlab sweep hertz --param load.force --values 50:200:4 --workers 2\n"
                              "  contactlab sweep hertz --param load.force --values 50,100 "
                              "--scheduler tcp://host:8786")
    p.add_argument("scene", metavar="SCENE")
    p.add_argument("--param", metavar="P", help="alpha_a, alpha_b, alpha_c or a dotted key (layer.lam, load.force)")
    p.add_argument("--values", metavar="V", help="comma list 0,0.25,0.5 or start:stop:num")
    p.add_argument("--out", metavar="DIR", help="sweep directory (default: results/<scene>-sweep-<param>)")
    p.add_argument("--workers", type=int, metavar="N", help="local worker processes (default: all cores)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler address (needs dask.distributed)")
    _add_set(p)

    p = sub.add_parser("study", help="error-time and stability studies", formatter_class=fmt,
                       description="Studies of the methods (validation.studies) on their built-in problems "
                                   "(no scene keys to override).",
                       epilog="examples:\n  contactlab study error-time hertz --out reports/studies\n"
                       "  contactlab study stability --quick\n"
                       "  contactlab report reports/studies      (work-precision plot and tables)")
    p.add_argument("study", choices=("error-time", "stability", "robustness"),
                   metavar="{error-time,stability,robustness}")
    p.add_argument("scene", nargs="?", metavar="SCENE",
                   help="problem for error-time: hertz or paper_root (default: both)")
    p.add_argument("--quick", action="store_true", help="a short ladder / case list (minutes instead of ~5)")
    p.add_argument("--out", metavar="DIR")

    p = sub.add_parser("report", help="figures and an HTML/Markdown report", formatter_class=fmt,
                       description="Build a report (report.html, report.md, figures/) from the paper's test\n"
                                   "problem, a scene (runs it first), a result directory of `contactlab run`, a\n"
                                   "sweep directory of `contactlab sweep` or a directory of study files.\n"
                                   "Prints where it wrote report.html; a progress bar on stderr shows the stages.",
                       epilog="examples:\n  contactlab report hertz                     runs it into results/hertz/\n"
                              "  contactlab report results/hertz --out rep/\n"
                              "  contactlab report results/paper_elastic_rigid-sweep-alpha_a      (a sweep)\n"
                              "  contactlab report reports/studies                (study files)\n"
                              "  contactlab report paper --quick --out /tmp/paper\n"
                              "  contactlab report hertz --units dimensionless --format pdf")
    p.add_argument("target", metavar="SCENE_OR_DIR",
                   help="'paper', a scene (built-in name or .toml), or a result, sweep or study directory")
    p.add_argument("--out", metavar="DIR", help="report directory (default: reports/paper for 'paper', "
                                                "DIR/report for a directory, results/NAME/report for a scene)")
    p.add_argument("--format", choices=FORMATS, default="png",
                   help="figure files: png (300 dpi, default), svg (vector, shown in the HTML), or pdf "
                        "(vector, beside a PNG for the HTML)")
    p.add_argument("--units", choices=("scene", "dimensionless"),
                   help="axes of a scene, result or sweep report: in the scene's units (mm and MPa for SI "
                        "scenes; the default when the scene's units label names them) or divided by the "
                        "contact's scales (Hertz's p_H and a_H for a paraboloid, else p_max and the contact "
                        "half-width)")
    p.add_argument("--quick", action="store_true",
                   help=f"'paper' only: a coarse preview (a_H/c = 8, short sweeps): {QUICK_TIME} instead of "
                        f"{FULL_TIME} on 2 cores")
    _add_set(p, "scene targets only: ")
    return parser


def _units(result):
    """``(length, pressure, force)`` unit symbols of a result ("" where unknown)."""
    symbols = result.get("unit_symbols") or {}
    return tuple(symbols.get(k, "") for k in ("length", "pressure", "force"))


def _summary(result, out_dir):
    L, Pa, N = _units(result)
    t = result["wall_time_s"]
    lines = [f"scene      {result['scene']}: {result['title']}   [units {result['units']}]"]
    p_line = f"p_max      {result['p_max']:.6g} {Pa}"
    if "fem" in result:
        f = result["fem"]["p_max"]
        p_line += f"   (FEM {f:.6g}, {100 * (result['p_max'] - f) / f:+.2f} %)"
    if "analytic" in result:
        a = result["analytic"]["p_max"]
        p_line += f"   ({result['analytic']['kind']} {a:.6g}, {100 * (result['p_max'] - a) / a:+.2f} %)"
    lines.append(p_line)
    if "contact_radius" in result:
        lines.append(f"contact    radius {result['contact_radius']:.6g} {L}, area {result['contact_area']:.6g} {L}^2")
    else:
        ext = result["contact_extent"]
        lines.append(f"contact    |x| <= {ext['x']:.6g} {L}, |y| <= {ext['y']:.6g} {L}, "
                     f"area {result['contact_area']:.6g} {L}^2")
    lines.append(f"load       force {result['force']:.6g} {N}, approach {result['approach']:.6g} {L}")
    if "alpha_b" in result:
        lines.append(f"layer      alpha_b = p_max^root / p_max^lambda = {result['alpha_b']:.4f}")
    conv = "yes" if result["converged"] else "NO"
    lines.append(f"converged  {conv} ({result['method']}, {result['iterations']} iterations, "
                 f"KKT residual {result['kkt_residual']:.2e})")
    times = ", ".join(f"{k} {v:.2f} s" for k, v in t.items() if v is not None)
    lines.append(f"time       {times}")
    for name, body in (result.get("stress") or {}).get("bodies", {}).items():
        x, y, z = body["location_of_max"]
        lines.append(f"stress     {name}: max von Mises {body['max_von_mises']:.6g} {Pa} at depth {z:.6g} {L} "
                     f"(x {x:.3g}, y {y:.3g}), max shear {body['max_tresca']:.6g} {Pa}")
    for msg in result["messages"]:
        lines.append(f"note       {msg}")
    if out_dir is not None:
        lines.append(f"files      {out_dir}/ ({', '.join(result['files'].values())})")
    return "\n".join(lines)


class _StageBar:
    """tqdm bar over the run stages; BEM iterations shown as a postfix."""

    def __init__(self, stages, disable):
        from tqdm import tqdm

        self.bar = tqdm(total=len(stages), desc="run", unit="stage", disable=disable, leave=False)

    def __call__(self, stage, status, info):
        if status == "start":
            self.bar.set_description(stage)
        elif status == "iteration":
            self.bar.set_postfix(iteration=info["iteration"], refresh=False)
            self.bar.refresh()
        elif status == "done":
            self.bar.update(1)

    def close(self):
        self.bar.close()


def _cmd_run(args):
    from .run.runner import execute_scene, planned_stages, write_outputs
    from .scene.load import load_scene

    scene = load_scene(args.scene, overrides=args.overrides)
    out_dir = Path(args.out) if args.out else Path("results") / scene.name
    bar = _StageBar(planned_stages(scene, write=True), args.no_progress or None)
    try:
        outcome = execute_scene(scene, progress=bar)
        write_outputs(outcome, out_dir, progress=bar)
    finally:
        bar.close()
    print(_summary(outcome.result, out_dir))
    return 0 if outcome.result["converged"] else 1


def _cmd_scenes(args):
    from .scene.load import builtin_scenes

    scenes = builtin_scenes()
    width = max(map(len, scenes))
    for name, desc in scenes.items():
        print(f"{name:<{width}}  {desc}")
    print("\nrun one with: contactlab run NAME   (files: validation/scenes/NAME.toml)")
    return 0


def _cmd_check(args):
    from .scene.load import load_scene

    scene = load_scene(args.scene, overrides=args.overrides)
    parts = ["bem"] + [k for k in ("fem", "analytic", "sweep", "stress", "report") if getattr(scene, k) is not None]
    b = scene.bem
    print(f"{scene.name}: OK ({', '.join(parts)}); lattice step {b['step']:.4g}, region "
          f"{b['extent'][0]:.4g} x {b['extent'][1]:.4g}, {b['n_nodes']} nodes   [units {scene.units.label}]")
    return 0


def _cmd_sweep(args):
    from tqdm import tqdm

    from .scene.load import load_scene
    from .run.sweep import parse_values, run_sweep, sweep_points

    values = parse_values(args.values) if args.values is not None else None
    if (args.param is None) != (values is None):
        raise InputError("--param and --values are not allowed alone: give both (or neither, to use the "
                         "scene's [sweep]).")
    scene = load_scene(args.scene, overrides=args.overrides)
    param, _key, points = sweep_points(scene, args.param, values)
    out = Path(args.out) if args.out else Path("results") / f"{scene.name}-sweep-{param}"
    bar = tqdm(total=len(points), desc=f"sweep {param}", unit="point", disable=args.no_progress or None)

    def progress(done, total, row):
        bar.update(1)
        bar.set_postfix_str(f"{param}={row['value']} {row['status']}")

    try:
        summary = run_sweep(scene, out, parameter=args.param, values=values, workers=args.workers,
                            scheduler=args.scheduler, progress=progress)
    finally:
        bar.close()
    print(f"sweep of {summary['key']} over {len(summary['points'])} values of scene {summary['scene']} "
          f"[units {summary['units']}]")
    print(f"{'value':>12} {'status':>14} {'p_max':>14} {'contact_r':>12} {'approach':>12}")
    for r in summary["points"]:
        fmt = (lambda v: f"{v:.6g}" if isinstance(v, float) else "-")
        print(f"{r['value']!s:>12} {r['status']:>14} {fmt(r.get('p_max')):>14} "
              f"{fmt(r.get('contact_radius')):>12} {fmt(r.get('approach')):>12}")
    print(f"computed {len(summary['computed'])}, reused {len(summary['reused'])}, failed {len(summary['failed'])}; "
          f"files {out}/ (summary.json, summary.csv, points/)")
    bad = summary["failed"] or any(r["status"] != "ok" for r in summary["points"])
    return 1 if bad else 0


def _load(module, what):
    """``module`` imported, or ``None`` after saying on stderr that it is not installed."""
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name is not None and module.startswith(exc.name):
            print(f"contactlab: error: {what} is not available in this installation ({module} is missing).",
                  file=sys.stderr)
            return None
        raise


def _cmd_study(args):
    module = {"error-time": "validation.studies.error_time", "stability": "validation.studies.stability",
              "robustness": "validation.studies.robustness"}
    mod = _load(module[args.study], f"the {args.study} study")
    if mod is None:
        return 2
    code = mod.main(args)
    return 0 if code is None else int(code)


class _ReportBar:
    """tqdm bar (stderr) over the stages of a report build."""

    def __init__(self, disable):
        from tqdm import tqdm

        self.bar = tqdm(total=1, desc="report", unit="stage", disable=disable, leave=False)

    def __call__(self, stage, done, total):
        self.bar.total = total
        self.bar.n = done
        self.bar.set_description(stage)
        self.bar.refresh()

    def close(self):
        self.bar.close()


def _cmd_report(args):
    command = _load("validation.report.command", "the report builder")
    if command is None:
        return 2
    bar = _ReportBar(args.no_progress or None)
    try:
        built = command.build_from_args(args, progress=bar)
    finally:
        bar.close()
    print(f"report written to {built.html}")
    print(f"  (also {built.markdown.name} and {len(built.figures)} figures in {built.out_dir / 'figures'}{os.sep})")
    return 0


@contextlib.contextmanager
def _log_to_stderr(verbose):
    """Show the library's log records on the current stderr while a command runs."""
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("contactlab: %(levelname)s: %(message)s"))
    loggers = [logging.getLogger(name) for name in ("bem", "fem_reference", "validation")]
    saved = [(lg.level, lg.propagate) for lg in loggers]
    for lg in loggers:
        lg.addHandler(handler)
        lg.setLevel(logging.INFO if verbose else logging.WARNING)
        lg.propagate = False
    try:
        yield
    finally:
        for lg, (level, propagate) in zip(loggers, saved):
            lg.removeHandler(handler)
            lg.setLevel(level)
            lg.propagate = propagate


_COMMANDS = {"run": _cmd_run, "scenes": _cmd_scenes, "check": _cmd_check, "sweep": _cmd_sweep,
             "study": _cmd_study, "report": _cmd_report}


def main(argv=None):
    """Entry point of the ``contactlab`` console script; returns the exit code."""
    parser = build_parser()
    try:  # argparse exits on --help (0) and on bad or unknown options (2): return the code instead
        args = parser.parse_args(argv)
    except SystemExit as exc:
        return exc.code
    try:
        with _log_to_stderr(args.verbose):
            return _COMMANDS[args.command](args)
    except (InputError, OutputError) as exc:
        for message in getattr(exc, "errors", None) or (str(exc),):
            print(f"contactlab: error: {message}", file=sys.stderr)
        return 2
    except CalibrationError as exc:
        print(f"contactlab: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("contactlab: interrupted (no partial result directory was left)", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
