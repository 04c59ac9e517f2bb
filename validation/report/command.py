"""The report of a target (``contactlab report TARGET``): :func:`build` takes the target and plain keywords."""

from __future__ import annotations

import logging
from pathlib import Path

from bem.checks import InputError

from ..extras import require as require_extra

__all__ = ["main", "build", "refused_options", "applies_to", "target_kind", "DEFAULT_PAPER_OUT", "OPTIONS"]

log = logging.getLogger(__name__)

#: where ``contactlab report paper`` writes without ``--out`` (relative to the working directory): a
#: report folder beside the result folders of ``contactlab run``, never the reports a repository keeps
DEFAULT_PAPER_OUT = Path("results") / "paper" / "report"

#: which targets each keyword of :func:`build` applies to: keyword -> (default, kinds)
OPTIONS = {"quick": (False, ("paper",)),
           "units": (None, ("scene", "results", "sweep")),
           "overrides": ((), ("scene",)),
           "allow_code": (False, ("scene",)),
           "allow_outside_files": (False, ("scene",))}


def target_kind(target):
    """What ``target`` is: ``"paper"``, ``"studies"``, ``"sweep"``, ``"results"``, ``"scene"``.

    Raises
    ------
    bem.InputError
        None of them (a scene must be a built-in name or an existing ``.toml`` file).
    """
    from validation.scene import builtin_scenes

    from .documents.studies import is_study_dir
    from .documents.sweep import is_sweep_dir

    path = Path(target)
    if target == "paper":
        return "paper"
    if path.is_dir():
        if (path / "result.json").is_file():
            return "results"
        if is_sweep_dir(path):
            return "sweep"
        if is_study_dir(path):
            return "studies"
        return "results"  # load_results explains what is missing
    if target in builtin_scenes() or (target.endswith(".toml") and path.is_file()):
        return "scene"
    raise InputError(
        f"target = {target!r} is not allowed: it must be 'paper', a built-in scene name, a scene TOML file, "
        "a results directory holding result.json, a sweep directory (summary.json, points/) or a directory "
        "of study files (see `contactlab scenes`)."
    )


def refused_options(kind, given):
    """The keywords of :func:`build` in ``given`` (keyword -> value) that are set but do not apply to a
    ``kind`` target (:func:`target_kind`), in the order of :data:`OPTIONS`."""
    return [key for key, (default, kinds) in OPTIONS.items()
            if given.get(key, default) not in (default, None, [], ()) and kind not in kinds]


def applies_to(key):
    """The targets the keyword ``key`` of :func:`build` applies to, in words."""
    kinds = OPTIONS[key][1]
    return " and ".join(f"{k} targets" if k != "paper" else "'paper'" for k in kinds)


def build(target, *, out=None, fmt="png", units=None, quick=False, overrides=(), allow_code=False,
          allow_outside_files=False, progress=None, what="out", names=None):
    """Write the report of ``target`` and return it.

    Parameters
    ----------
    target : str
        ``"paper"`` (solve the paper's test problem and report it), a built-in scene name or a
        scene TOML file (run it, with ``overrides``, into the result directory ``results/NAME`` as
        ``contactlab run`` does, then report that), a results directory holding ``result.json``
        (:mod:`validation.report.documents.results`), a sweep directory
        (:mod:`validation.report.documents.sweep`) or a directory of study files
        (``error_time.json``, ``stability.json``: :mod:`validation.report.documents.studies`).
    out : path-like, optional
        The report directory written, for every target (default ``results/paper/report`` for ``paper``,
        ``TARGET/report`` for a directory, ``results/NAME/report`` for a scene).
    fmt : {"png", "svg", "pdf"}
        The figure files.
    units : {"auto", "scene", "dimensionless"}, optional
        Scenes, results and sweeps only (default ``"auto"``).
    quick : bool
        ``paper`` only: a coarse preview.
    overrides : list of str
        ``KEY=VALUE`` scene overrides; scenes only.
    allow_code, allow_outside_files : bool
        Scenes only (:mod:`validation.scene.trust`).
    progress : callable, optional
        ``progress(stage, done, total)`` at the start of each stage and at the end
        (:class:`validation.progress.Progress`).
    what : str
        How errors name ``out`` (the command line's ``--out``).
    names : dict, optional
        How errors name the keywords ``quick``, ``units``, ``overrides``, ``allow_code`` and
        ``allow_outside_files`` (the command line's options); default ``"key = value"``.

    Returns
    -------
    validation.report.render.BuiltReport

    Raises
    ------
    bem.InputError
        Unknown target or an option that does not apply to it.
    validation.io.OutputError
        The report directory (or a scene's result directory) holds files contactlab did not
        write there, or cannot be written; checked before any work.
    validation.extras.MissingExtraError
        matplotlib or pillow (``contactlab[report]``), or for ``paper`` gmsh or scikit-fem
        (``contactlab[fem]``), cannot be imported; nothing has run.
    """
    target = str(target or "")
    fmt = fmt or "png"
    units = units or "auto"
    kind = target_kind(target)
    given = dict(quick=quick, units=units if units != "auto" else None, overrides=overrides, allow_code=allow_code,
                 allow_outside_files=allow_outside_files)
    for key in refused_options(kind, given):
        name = (names or {}).get(key) or f"{key} = {given[key]!r}"
        raise InputError(f"{name} is not allowed with target {target!r} (a {kind} target): it "
                         f"applies to {applies_to(key)}.")
    require_extra("report", "contactlab report (figures)")
    from .render.build import check_report_dir

    what = "out_dir" if out is None else what
    if kind == "paper":
        require_extra("fem", "contactlab report paper (the FEM validation)")
        from .documents.paper import report_paper_problem

        out_dir = DEFAULT_PAPER_OUT if out is None else Path(out)
        check_report_dir(out_dir, what=what)
        return report_paper_problem(out_dir, quick=bool(quick), fmt=fmt, progress=progress)
    if kind == "scene":
        return _report_scene(target, out, what, units=units, fmt=fmt, progress=progress,
                             overrides=list(overrides or ()), allow_code=bool(allow_code),
                             allow_outside_files=bool(allow_outside_files))
    out_dir = Path(target) / "report" if out is None else Path(out)
    check_report_dir(out_dir, what=what)
    if kind == "studies":
        from .documents.studies import report_studies_dir

        return report_studies_dir(target, out_dir, fmt=fmt, progress=progress)
    if kind == "sweep":
        from .documents.sweep import report_sweep_dir

        return report_sweep_dir(target, out_dir, units=units, fmt=fmt, progress=progress)
    from .documents.sections import report_results_dir

    return report_results_dir(target, out_dir, units=units, fmt=fmt, progress=progress)


def _report_scene(target, out, what, *, units, fmt, progress, overrides, allow_code, allow_outside_files):
    """Run a scene into ``results/NAME`` and report it into ``out`` (default ``results/NAME/report``)."""
    from validation.run import check_result_dir, run_scene
    from validation.scene import load_scene
    from validation.scene.study import refuse_study

    from .documents.sections import report_results_dir
    from .render.build import check_report_dir

    scene = load_scene(target, overrides=overrides or None, allow_code=allow_code,
                       allow_outside_files=allow_outside_files)
    refuse_study(scene, "a report of a scene")
    result_dir = Path("results") / scene.name
    out_dir = result_dir / "report" if out is None else Path(out)
    check_result_dir(result_dir, what="scene.name", value=scene.name)
    check_report_dir(out_dir, what="scene.name" if out is None else what, value=scene.name if out is None else None)
    if progress is not None:
        progress("running the scene", 0, 1)
    run_scene(scene, result_dir)
    return report_results_dir(result_dir, out_dir, units=units, fmt=fmt, progress=progress)


def main(target, **options):
    """Write the report of ``target`` (:func:`build`, with its keyword ``options``), log where, and
    return it."""
    built = build(target, **options)
    log.info("report written: %s and %s (%d figures)", built.html, built.markdown, len(built.figures))
    for note in getattr(built, "notes", ()):
        log.info("note: %s", note)
    return built
