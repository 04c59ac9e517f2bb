"""``contactlab run SCENE``: run a scene and write its result directory."""

from __future__ import annotations

import math
from pathlib import Path

from .common import ProgressBar, add_set, add_trust, trust

PARSER = {"help": "run a scene and write its result directory",
          "description": "Run a scene: the BEM, and the FEM/closed form/comparison it names; a scene with\n"
                         "[study] runs that built-in study and writes its files (docs/scenes.md).\n"
                         "--out DIR is the result directory itself; it must be new, empty or a result\n"
                         "directory contactlab wrote (marked by DIR/.contactlab), which is replaced.",
          "epilog": "examples:\n  contactlab run hertz                         writes results/hertz/\n"
                    "  contactlab run my.toml --out out/my --set bem.method=\"augmented_gap\"\n"
                    "                                               writes out/my/result.json, ...\n"
                    "  contactlab run punch --set fem.n_contact_elements=32\n"
                    "  contactlab run rough_sphere_two_scale       the small two-scale check (a [study] scene)"}


def add_args(p):
    p.add_argument("scene", metavar="SCENE", help="built-in scene name or path to a .toml file")
    p.add_argument("--out", metavar="DIR", help="the result directory written (default: results/<scene name>)")
    p.add_argument("--no-fem", action="store_true",
                   help="skip the scene's [fem]: no FEM reference, and no need of the fem extra (gmsh, scikit-fem)")
    add_set(p)
    add_trust(p)


def _g(value, spec=".6g"):
    """``value`` formatted by ``spec``; ``-`` for a missing (``None``) or non-numeric value."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return "-"
    return format(value, spec)


def _relative(value, reference):
    """``(value - reference) / reference`` in percent, or ``""`` when it is not a finite number."""
    if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in (value, reference)) or reference == 0:
        return ""
    change = 100 * (value - reference) / reference
    return f", {change:+.2f} %" if math.isfinite(change) else ""


def _summary(result, out_dir):
    """The lines ``contactlab run`` prints: the :class:`validation.run.record.RunResult`'s numbers with their
    units, and its files.

    Any number may be ``None`` (a non-finite value in ``result.json``): it prints as ``-``.
    """
    L, Pa, N = (result.unit_symbols[k] or "" for k in ("length", "pressure", "force"))
    lines = [f"scene      {result.scene}: {result.title}   [units {result.units}]"]
    p_line = f"p_max      {_g(result.p_max)} {Pa}"
    for name, ref in (("FEM", result.fem), (None, result.analytic)):
        if ref is not None:  # the closed form names its kind
            p_line += f"   ({name or ref.kind} {_g(ref.p_max)}{_relative(result.p_max, ref.p_max)})"
    lines.append(p_line)
    if result.periodic is not None:
        lines += _periodic_lines(result.periodic, L, Pa)
    elif result.contact_radius is not None:
        lines.append(f"contact    radius {_g(result.contact_radius)} {L}, area {_g(result.contact_area)} {L}^2")
    else:
        ext = result.contact_extent
        lines.append(f"contact    |x| <= {_g(ext['x'])} {L}, |y| <= {_g(ext['y'])} {L}, "
                     f"area {_g(result.contact_area)} {L}^2")
    on = " on one cell" if result.periodic is not None else ""
    lines.append(f"load       force {_g(result.force)} {N}{on}, approach {_g(result.approach)} {L}")
    if result.alpha_b is not None:
        lines.append(f"layer      alpha_b = p_max^root / p_max^lambda = {_g(result.alpha_b, '.4f')}")
    conv = "yes" if result.converged else "NO"
    lines.append(f"converged  {conv} ({result.method}, {result.iterations} iterations, "
                 f"KKT residual {_g(result.kkt_residual, '.2e')})")
    times = ", ".join(f"{k} {_g(v, '.2f')} s" for k, v in result.wall_time_s_by_part.items() if v is not None)
    lines.append(f"time       {times}")
    for name, body in ({} if result.stress is None else result.stress.bodies).items():
        x, y, z = body.location_of_max
        lines.append(f"stress     {name}: max von Mises {_g(body.max_von_mises)} {Pa} at depth {_g(z)} {L} "
                     f"(x {_g(x, '.3g')}, y {_g(y, '.3g')}), max shear {_g(body.max_tresca)} {Pa}")
        if (c := body.coated) is not None:
            lines.append(f"           coating max von Mises {_g(c.max_von_mises_coating)} {Pa}, substrate "
                         f"{_g(c.max_von_mises_substrate)} {Pa}; interface at depth {_g(c.thickness)} {L}: sigma_zz "
                         f"down to {_g(c.interface_min_sigma_zz)} {Pa}, shear up to {_g(c.interface_max_shear)} {Pa}")
    lines += [f"note       {msg}" for msg in result.messages]
    if out_dir is not None:
        lines.append(f"files      {out_dir}/ ({', '.join(result.files.values())})")
    return "\n".join(lines)


def _periodic_lines(cell, L, Pa):
    """The lines of a periodic cell (:class:`validation.run.record.PeriodicPart`): contact fraction, spots,
    mean gap and the surface's statistics."""
    s, sp = cell.surface, cell.spots
    lines = [f"cell       mean pressure {_g(cell.mean_pressure)} {Pa}, contact fraction "
             f"{_g(cell.contact_fraction, '.4f')}, {cell.n_spots} contact spots (largest "
             f"{_g(sp.largest_area, '.4g')} {L}^2), mean gap {_g(cell.mean_gap, '.4g')} {L}",
             f"surface    rms height {_g(s['rms_height'], '.4g')} {L}, rms slope {_g(s['rms_slope'], '.4g')}, "
             f"edge jump {_g(s['edge_jump'], '.4g')} {L}{' (LARGE)' if s['edge_jump_large'] else ''}, "
             f"stretch_y {_g(s['stretch_y'], '.5f')}"]
    return lines


def _run_study(scene, out_dir, what, value):
    """Run the built-in study of a ``[study]`` scene; write its files, the scene and the marker into ``out_dir``."""
    import importlib

    import tomli_w
    from bem.files import write_text

    from ..io import atomic_directory, check_output_dir, output_errors, recover_output_dir
    from .study import STUDIES, write_study

    study = importlib.import_module(STUDIES[scene.study])
    names = (*study.OUTPUT_NAMES, "scene.toml", "report")
    with output_errors(out_dir, what):
        recover_output_dir(out_dir)
        check_output_dir(out_dir, "result", names, what=what, value=value)  # before the study runs
    with atomic_directory(out_dir, "result", names, what=what) as tmp:
        data = write_study(scene.study, tmp, **scene.options)[0].data
        write_text(tmp / "scene.toml", tomli_w.dumps(scene.raw))
    lines = [f"scene      {scene.name}: {scene.title}   [study {scene.study}]"]
    lines += [f"error      {line}" for line in study.summary_lines(data)]
    lines.append(f"files      {out_dir}/ ({', '.join(names[:-1])})")
    print("\n".join(lines))
    return 0


def run(args):
    from ..progress import Progress
    from ..run import check_result_dir, execute_scene, planned_stages, write_outputs
    from ..scene import StudyScene, load_scene

    scene = load_scene(args.scene, overrides=args.overrides, no_fem=args.no_fem, **trust(args))
    if args.out:
        out_dir, what, value = Path(args.out), "--out", None
    else:
        out_dir, what, value = Path("results") / scene.name, "scene.name", scene.name
    if isinstance(scene, StudyScene):
        return _run_study(scene, out_dir, what, value)
    check_result_dir(out_dir, what=what, value=value)  # before the solve
    bar = ProgressBar("run", "stage", args.no_progress or None)
    stages = Progress(planned_stages(scene, write=True), bar)
    try:
        outcome = execute_scene(scene, progress=stages)
        write_outputs(outcome, out_dir, progress=stages, what="--out" if args.out else "out_dir")
    finally:
        bar.close()
    print(_summary(outcome.result, out_dir))
    return 0 if outcome.result.converged else 1
