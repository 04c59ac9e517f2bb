"""Run a scene: the BEM always; the FEM reference, closed form, comparisons, stresses only when named.

:func:`run_scene` returns the :class:`validation.run.record.RunResult` and, given ``out_dir``, writes it whole or
not at all (:mod:`validation.io`) with the BEM nodal field and, when the FEM ran, its
field (ParaView ``.vtu``, both by :func:`bem.files.write_vtu`). gmsh and scikit-fem (the
``[fem]`` extra) are imported only by the FEM reference, so a BEM-only scene never loads them.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

import tomli_w

import bem
from bem.files import write_result_vtu, write_stress_vtu, write_text, write_vtu
from bem.layers import beyond_table

from ..compare import compare
from ..io import atomic_directory, check_output_dir, output_errors, recover_output_dir
from ..progress import Progress, stages_of
from ..scene.paper import needs_calibration
from ..scene.checks import SceneError
from ..scene.load import Scene, load_scene
from ..scene.study import refuse_study
from ..scene.trust import refuse_code
from ..scene.sizing import solver_keywords
from .calibrate import CalibrationError, resolve_layer
from .record import FILE_NAME, RunResult
from .region import Region
from .result import build_result

__all__ = ["run_scene", "execute_scene", "write_outputs", "RunOutcome", "planned_stages", "FILES", "RESULT_NAMES",
           "check_result_dir"]

log = logging.getLogger(__name__)

#: Names of the files of a result directory.
FILES = {"result": FILE_NAME, "scene": "scene.toml", "bem_field": "bem_field.vtu",
         "fem_field": "fem_field.vtu", "stress_field": "stress_field.vtu"}
#: What a result directory may hold besides its marker: its files and its default report folder.
RESULT_NAMES = (*FILES.values(), "report")
#: the options of the scene's ``[bem]`` that the calibration solves of a layer take over; they solve with
#: ``method = "newton"`` and its defaults otherwise, whatever the scene's method
CALIBRATION_KEYS = ("rtol", "precondition", "nested")


@dataclass
class RunOutcome:
    """Everything a run produced: its :class:`validation.run.record.RunResult` and the solver objects behind it."""

    scene: Scene
    result: RunResult
    bem: object
    domain: object  # validation.run.region.Region or validation.run.periodic.Cell
    fem: object = None
    analytic: object = None
    layer: object = None
    stress: object = None

    @property
    def spots(self):
        """The contact spot of each node of a periodic cell (:func:`validation.run.periodic.contact_spots`),
        ``None`` for a region."""
        return getattr(self.domain, "spots", None)


def planned_stages(scene, *, write=False):
    """Stage names :func:`run_scene` will report for ``scene`` (for progress bars)."""
    wanted = {"layer": needs_calibration(scene.layer_spec),
              "bem": True,
              "fem": scene.fem is not None,
              "compare": scene.fem is not None or scene.analytic is not None,
              "stress": scene.stress is not None,
              "write": write}
    return [stage for stage, on in wanted.items() if on]


def coating_keywords(scene):
    """``coating1``, ``coating2`` (:class:`bem.Coating` or None) of a coated scene; ``{}`` without a coating."""
    if scene.coatings is None:
        return {}
    return {k: None if c is None else bem.Coating(c["thickness"], c["E"], c["nu"]) for k, c in scene.coatings.items()}


def bodies_keywords(scene):
    """The bodies' keywords of :func:`bem.solve`: ``E_star``, or ``E1, nu1, E2, nu2`` and the coatings."""
    if scene.coatings is None:
        return {"E_star": scene.E_star}
    return {**scene.materials, **coating_keywords(scene)}


def domain_of(scene, messages):
    """The domain of ``scene``: its periodic cell (:class:`validation.run.periodic.Cell`) or its region of
    the half-space (:class:`validation.run.region.Region`); ``messages``: the run's messages."""
    if scene.bem.get("periodic"):
        from .periodic import Cell

        return Cell(scene, messages)
    return Region(scene)


class _BemSolves:
    """:func:`bem.solve` of the scene's problem on its domain for a given layer: the run's solve and the
    calibration's. A region grown by one solve is where the next one starts (the calibration's region
    carries over to the run's solve); ``messages`` gets the notes of each solve (how it grew). The run's
    solve caps the pressure at ``bodies.hardness`` when the scene gives one; the calibration of a law of
    the paper's parameters solves the elastic problem its parameters are defined on."""

    def __init__(self, scene, domain, messages):
        opts = scene.bem
        self.domain, self.messages = domain, messages
        self.bem_domain = domain.bem_domain
        problem = dict(bodies_keywords(scene), **domain.load)
        plastic = {} if scene.hardness is None else {"hardness": scene.hardness}
        self.kw = dict(problem, **plastic, **solver_keywords(opts))
        self.calibration_kw = dict(problem, method="newton", **{k: opts[k] for k in CALIBRATION_KEYS if k in opts})
        self.calibration_solves = 0

    def __call__(self, layer, callback=None):
        return self._solve(layer, callback, self.kw)

    def calibrate(self, layer):
        """A calibration solve (:func:`validation.run.calibrate.resolve_layer`) with the robust solver.

        Raises
        ------
        validation.run.calibrate.CalibrationError
            The solve did not converge (the layer's parameters would be wrong).
        """
        self.calibration_solves += 1
        res = self._solve(layer, None, self.calibration_kw)
        if not res.converged:
            raise CalibrationError(
                f"the calibration of the layer law ({layer!r}) did not converge with method 'newton': "
                f"{res.message}. The run stops: the layer parameters would be wrong.")
        return res

    def _solve(self, layer, callback, kw):
        try:
            res = bem.solve(self.domain.gap, domain=self.bem_domain, layer=layer, callback=callback, **kw)
        except bem.RegionTooSmallError as exc:  # the region of the scene's key bem.extent
            raise bem.RegionTooSmallError(f"bem.{exc}") from None
        self.messages.extend(res.notes)
        self.bem_domain = res.domain
        return res


def _analytic(scene, layer):
    from bem import reference as an

    kind = scene.analytic["kind"]
    g, load = scene.gap, scene.load
    rx, ry = (g.R, g.R) if g.type_name == "paraboloid" else (getattr(g, "Rx", None), getattr(g, "Ry", None))
    if kind == "hertz":
        return an.hertz_sphere(rx, scene.E_star, **load)
    if kind == "hertz_elliptic":
        return an.hertz_elliptic(rx, ry, scene.E_star, **load)
    return an.rigid_layer_paraboloid(layer, g.R, **load)


def execute_scene(scene, *, progress=None, overrides=None):
    """Run what ``scene`` names and return a :class:`RunOutcome` (nothing is written).

    Parameters
    ----------
    scene : Scene, str, path-like or dict
        A validated scene, a built-in name, a TOML path or a scene dict.
    progress : callable or validation.progress.Progress, optional
        ``progress(label, done, total)`` (:mod:`validation.progress`) at the start of each stage of
        :func:`planned_stages` (``label`` the stage), after each BEM iteration (``"bem: iteration k"``)
        and at the end (``"done"``); a :class:`~validation.progress.Progress` of a caller's job that
        holds these stages is told them and not the end.
    overrides : dict or list of str, optional
        Dotted-key overrides (:func:`validation.scene.load.apply_overrides`), validated first.
    """
    t0 = time.perf_counter()
    if not isinstance(scene, Scene) or overrides:
        scene = load_scene(scene, overrides=overrides)
    refuse_study(scene, "a run of the solvers")
    if scene.unimported:
        raise SceneError(refuse_code(*scene.unimported[0]))
    stages = stages_of(progress, planned_stages(scene))
    messages, times = [], {"bem": None, "fem": None, "layer_reference": None, "stress": None}
    domain = domain_of(scene, messages)
    solve = _BemSolves(scene, domain, messages)
    if "fem" in scene.skipped:
        messages.append("FEM reference skipped: the scene's [fem] was not run (no_fem).")
    if "layer" in planned_stages(scene):
        stages("layer")
    t = time.perf_counter()
    layer, layer_info = resolve_layer(scene.layer_spec, step=domain.step, E_star=scene.E_star,
                                      solve=solve.calibrate, layer=scene.layer)
    if solve.calibration_solves:
        times["layer_reference"] = time.perf_counter() - t
    stages("bem")

    def callback(k, _p):
        stages.note(f"iteration {k}")

    t = time.perf_counter()
    res = solve(layer, callback=callback if stages.callback is not None else None)
    times["bem"] = time.perf_counter() - t
    asked = scene.bem["method"]
    if res.method != asked and asked != "newton":  # a paper method on a quadratic problem: the QP solved it
        messages.append(f"bem.method = {asked!r} ran as Kalker's QP ({res.method!r}): "
                        + ("the scene has no layer" if layer is None else "the layer is linear")
                        + ", so the problem is a QP and the QP solves it directly.")
    if not res.converged:
        messages.append(f"BEM did not converge: {res.message}")
        log.info("BEM did not converge: %s", res.message)  # bem.solve has logged its warning
    elif (note := beyond_table(layer, res.p_max)) is not None:
        messages.append(f"BEM: {note}")  # bem.solve has logged it
    if "p_max_lambda" in layer_info and scene.layer_spec["law"] == "root":
        layer_info["alpha_b"] = res.p_max / layer_info["p_max_lambda"]
    fem = ref = metrics = None
    if scene.fem is not None:
        import fem_reference

        stages("fem")
        fem = fem_reference.solve(scene.gap, **scene.materials, **coating_keywords(scene), **scene.load, layer=layer,
                                  **scene.fem)
        times["fem"] = fem.wall_time_s
        if not fem.converged:
            messages.append(f"FEM did not converge: {fem.message}")
        elif (note := beyond_table(layer, fem.p_max)) is not None:
            messages.append(f"FEM: {note}")
    if scene.analytic is not None:
        ref = _analytic(scene, layer)
    if fem is not None or ref is not None:
        stages("compare")
        metrics = compare(res, fem=fem, analytic=ref)
    stress = None
    if scene.stress is not None:
        from .stress import run_stress

        stages("stress")
        stress = run_stress(scene, res, fem)
        messages.extend(stress.notes)
        times["stress"] = stress.wall_time_s
    times["total"] = time.perf_counter() - t0
    stress_block = None
    if stress is not None:
        from .stress import stress_summary

        stress_block = stress_summary(stress)
    result = build_result(scene, res, layer_info, domain_parts=domain.parts(res), fem=fem, analytic=ref,
                          metrics=metrics, times=times, messages=messages, stress=stress_block)
    if stages is not progress:
        stages.done()
    return RunOutcome(scene=scene, result=result, bem=res, domain=domain, fem=fem, analytic=ref, layer=layer,
                      stress=stress)


def check_result_dir(out_dir, *, what="out_dir", value=None):
    """Clean up after a killed writer of ``out_dir`` and refuse it if it is not a result directory.

    Raises
    ------
    validation.io.OutputError
        :func:`validation.io.check_output_dir` (kind ``"result"``); ``what`` and ``value`` name
        the argument in the message.
    """
    with output_errors(out_dir, what):
        recover_output_dir(out_dir)
        check_output_dir(out_dir, "result", RESULT_NAMES, what=what, value=value)


def write_outputs(outcome, out_dir, *, progress=None, what="out_dir"):
    """Write the result directory of ``outcome`` atomically (whole or not at all); returns its path.

    ``out_dir`` must be new, empty or a result directory (:func:`check_result_dir`); errors name
    it as ``what``. ``progress`` as for :func:`execute_scene`, of the stage ``"write"``.
    """
    stages = stages_of(progress, ["write"])
    stages("write")
    res, scene = outcome.bem, outcome.scene
    absent = {"fem_field": outcome.fem is None, "stress_field": outcome.stress is None}
    files = {key: name for key, name in FILES.items() if not absent.get(key, False)}
    outcome.result.files = files
    with atomic_directory(out_dir, "result", RESULT_NAMES, what=what) as tmp:
        write_result_vtu(tmp / files["bem_field"], res, **outcome.domain.field(res))
        if outcome.fem is not None:
            write_vtu(tmp / files["fem_field"], **outcome.fem.field())
        if outcome.stress is not None:
            run = outcome.stress  # a coated body's field: its coating and substrate (bem.CoatedStress)
            upper, lower = (run.coated.get(name, run.bodies.get(name)) for name in ("body1", "body2"))
            write_stress_vtu(tmp / files["stress_field"], res, upper=upper, lower=lower)
        write_text(tmp / files["scene"], tomli_w.dumps(scene.raw))
        outcome.result.write(tmp, files["result"])
    stages.done()
    return out_dir


def run_scene(scene, out_dir=None, *, progress=None, overrides=None):
    """Run a scene and (given ``out_dir``) write its result directory.

    Parameters
    ----------
    scene : Scene, str, path-like or dict
        A validated scene, a built-in name, a TOML path or a scene dict.
    out_dir : path-like, optional
        Result directory: ``result.json``, ``scene.toml`` (the effective scene, re-runnable),
        ``bem_field.vtu``, with an FEM reference ``fem_field.vtu``, with a ``[stress]`` section
        ``stress_field.vtu``, and the marker ``.contactlab`` (:mod:`validation.io`). Written
        atomically: an existing result directory is replaced only when the run succeeded; a
        directory holding anything else is refused before the run.
    progress : callable, optional
        See :func:`execute_scene`.
    overrides : dict or list of str, optional
        Dotted-key overrides, validated with the scene before any work.

    Returns
    -------
    validation.run.record.RunResult
        The typed result (the content of ``result.json``).

    Raises
    ------
    validation.scene.SceneError
        Bad scene (nothing run, nothing written).
    bem.RegionTooSmallError
        The contact reaches the border of an explicitly given region.
    validation.io.OutputError
        ``out_dir`` may not be written (nothing run) or writing it failed.
    """
    if out_dir is not None:
        check_result_dir(out_dir)
    if not isinstance(scene, Scene) or overrides:
        scene = load_scene(scene, overrides=overrides)
    refuse_study(scene, "a run of the solvers")
    stages = Progress(planned_stages(scene, write=out_dir is not None), progress)
    outcome = execute_scene(scene, progress=stages)
    if out_dir is not None:
        write_outputs(outcome, out_dir, progress=stages)
    else:
        stages.done()
    return outcome.result
