"""The paper's test problem (section 6, Fig. 4-11) as scenes, run by the runner: the study the paper
report draws (:mod:`validation.report.documents.paper`).

Every case is a built-in scene (``paper_smooth``, ``paper_linear``, ``paper_elastic_rigid``,
``paper_root``, ``paper_bilinear``: the problem and the paper's layer parameters, see
:mod:`validation.scene.paper`) run by :func:`validation.run.execute_scene` with overrides: one
lattice for all, ``bem.step = a_H / n`` (Hertz's radius ``a_H`` of the smooth problem) on the
candidate region ``|x|, |y| <= 1.9 a_H``, the iteration histories with ``bem.record``, the
methods with ``bem.method`` and their options, the sweeps with ``layer.alpha_a``,
``layer.alpha_c`` and the root coefficient ``layer.lam``, the subsurface stresses with
``[stress] depths``, the FEM reference with ``[fem] n_contact_elements``. The scenes give the layer
compliance in physical units (the paper's ``10 C_nn`` at the step ``a_H / 20``), so the quick
preview (``n = 8``) and the full report (``n = 20``) solve the same problem on two lattices.
"""

from __future__ import annotations

import contextlib
import copy
import logging
import math
import statistics
import time
import tomllib
from dataclasses import dataclass, field

import numpy as np

__all__ = ["PaperRuns", "CaseRunner", "run_paper_problem", "SCENES", "SOLVE_STAGES", "AG_RELAXATION",
           "ALPHA_A_ITERATIONS"]

log = logging.getLogger(__name__)

#: the built-in scene of each case of Fig. 4 and 5
SCENES = {"smooth": "paper_smooth", "linear Winkler": "paper_linear", "elastic-rigid": "paper_elastic_rigid",
          "root": "paper_root", "bilinear": "paper_bilinear"}
#: the stages of :func:`run_paper_problem`, as reported to its ``progress``
SOLVE_STAGES = ("layer laws", "parameter sweeps", "methods and stability", "FEM reference")
#: relaxation of the augmented gap method where it is run relaxed (omega = 1 stalls here)
AG_RELAXATION = 0.08
#: threshold of the elastic-rigid law whose iterations are drawn (Fig. 6, 8)
ALPHA_A_ITERATIONS = 0.6
#: half-width of the candidate region [a_H]; KKT tolerance of every solve
EXTENT, RTOL = 1.9, 1e-8
#: depths of the subsurface stresses [a_H]
STRESS_DEPTHS = np.linspace(0.0, 3.0, 61)
#: timed runs per point of the resolution study; one for runs slower than WP_SLOW_S [s]
WP_REPEATS, WP_SLOW_S = 3, 2.0


@dataclass
class PaperRuns:
    """Everything the paper report draws: :class:`validation.run.RunOutcome` of the cases and the
    :class:`bem.ContactResult` of the iterations and sweeps.

    Attributes
    ----------
    quick : bool
    nodes_per_radius : int
        ``a_H / c`` of the lattice.
    p0, a, approach : float
        Hertz's peak [pressure], radius and approach [length] of the smooth problem
        (``result.scales``): the scales of every figure.
    outcomes : dict
        Case -> outcome of Fig. 5 (Newton; ``"bilinear, variable compliance"`` too), with stresses.
    iterations : dict
        Label -> result solved with ``bem.record = true`` (Fig. 6, 8, 10, 11).
    sweep_a, sweep_c : list of (float, bem.ContactResult)
        ``alpha_a`` (0 and 1: the smooth and linear cases) and ``alpha_c``.
    sweep_b : list of (float, float, bem.ContactResult)
        ``(lam_b / lam_b of Fig. 5, alpha_b, result)`` of the root law.
    stability : list of dict
        One row per (law, method): ``law, method, status, iterations, p_max/p0, kkt_residual, wall_time_s, message``.
    validation : dict
        Case -> outcome with the FEM reference (empty when the FEM was not run).
    work_precision : list of dict
        Rows ``solver, method, resolution, N, error, wall_time_s`` (median), ``wall_times_s`` (every repeat).
    wall_time_s : float
    """

    quick: bool
    nodes_per_radius: int
    p0: float = 1.0
    a: float = 1.0
    approach: float = 1.0
    outcomes: dict = field(default_factory=dict)
    iterations: dict = field(default_factory=dict)
    sweep_a: list = field(default_factory=list)
    sweep_b: list = field(default_factory=list)
    sweep_c: list = field(default_factory=list)
    stability: list = field(default_factory=list)
    validation: dict = field(default_factory=dict)
    work_precision: list = field(default_factory=list)
    wall_time_s: float = 0.0

    @property
    def base(self):
        """Case -> :class:`bem.ContactResult` of Fig. 5."""
        return {k: o.bem for k, o in self.outcomes.items()}

    @property
    def laws(self):
        """Case -> layer law (``None``: smooth) of Fig. 4 and 5."""
        return {k: self.outcomes[k].layer for k in SCENES}

    @property
    def p_lin(self):
        """``p_max^lambda``: the peak pressure with the linear layer."""
        return self.outcomes["linear Winkler"].bem.p_max

    @property
    def lam(self):
        """Compliance of the linear layer [length/pressure]."""
        return self.outcomes["linear Winkler"].layer.lam

    @property
    def lam_over_cnn(self):
        """``lam / C_nn`` with ``C_nn`` of the lattice in use (how soft the layer is on the scale of one node)."""
        from validation.scene.paper import c_nn

        o = self.outcomes["linear Winkler"]
        return self.lam / c_nn(o.result.bem.step, o.scene.E_star)

    @property
    def stress(self):
        """Case -> :class:`bem.SubsurfaceStress` of the upper body (``nu = 0.3``)."""
        return {k: self.outcomes[k].stress.bodies["body1"] for k in SCENES}

    @property
    def fem(self):
        """Case -> ``(bem result, FEM result)`` of the validation."""
        return {k: (o.bem, o.fem) for k, o in self.validation.items()}


class CaseRunner:
    """Runs the paper's cases on one lattice: ``run(case, **overrides)`` -> :class:`validation.run.RunOutcome`."""

    def __init__(self, nodes_per_radius):
        from bem.reference import hertz_sphere
        from validation.scene import builtin_path, load_scene

        self.raw = {}
        for case, name in SCENES.items():
            with open(builtin_path(name), "rb") as fh:
                self.raw[case] = {k: v for k, v in tomllib.load(fh).items() if k not in ("fem", "sweep", "report")}
        smooth = load_scene(self.raw["smooth"])
        self.a = hertz_sphere(smooth.gap.R, smooth.E_star, **smooth.load).contact_radius
        self.bem = {"step": self.a / nodes_per_radius, "extent": EXTENT * self.a, "rtol": RTOL}

    def __call__(self, case, overrides=None, *, analytic=False, **sections):
        """Run ``case`` with dotted-key ``overrides`` (``{"bem.method": "newton"}``, as a scene's
        ``--set``: :func:`validation.scene.load.apply_overrides`); ``section=dict`` sets a whole section."""
        from validation.run import execute_scene

        raw = copy.deepcopy(self.raw[case])
        raw["bem"] = dict(self.bem)
        if not analytic:
            raw.pop("analytic", None)
        raw.update(sections)
        return execute_scene(raw, overrides=dict(overrides or {}))


def _cases(run, res, quick):
    depths = {"stress": {"depths": list(STRESS_DEPTHS * run.a), "bodies": ["body1"]}}
    for case in SCENES:
        res.outcomes[case] = run(case, analytic=True, **depths)
    res.outcomes["bilinear, variable compliance"] = run("bilinear", {"bem.method": "variable_compliance"})
    scales = res.outcomes["smooth"].result.scales
    res.p0, res.a, res.approach = scales.p_hertz, scales.a_hertz, scales.approach_hertz


def _sweeps(run, res, quick):
    alphas = (0.2, 0.5, 0.8) if quick else (0.05, *np.round(np.linspace(0.1, 0.9, 9), 2), 0.95)
    res.sweep_a = [(0.0, res.base["smooth"])] + [
        (float(al), run("elastic-rigid", {"layer.alpha_a": float(al)}).bem) for al in alphas] + [
        (1.0, res.base["linear Winkler"])]
    lam_b = res.laws["root"].lam
    for f in (0.5, 2.0) if quick else (0.25, 0.5, 1.0, 2.0, 4.0):
        r = run("root", layer={"law": "root", "lam": f * lam_b}).bem
        res.sweep_b.append((f, r.p_max / res.p_lin, r))
    angles = (0.0, math.pi / 4, 1.3) if quick else (0.0, math.atan(0.1), math.atan(0.3), math.pi / 4, math.atan(3.0),
                                                   math.atan(10.0))
    res.sweep_c = [(float(t), run("bilinear", {"layer.alpha_c": float(t)}).bem) for t in angles]


class _AugmentedGapWarnings(logging.Filter):
    """Holds back the solver's warning of an augmented gap run that does not converge: the
    stability table records it, and :func:`validation.report.documents.paper.expected_stalls`
    says once that it is the expected behaviour on this problem."""

    def filter(self, record):
        return not (record.levelno == logging.WARNING and record.getMessage().startswith("augmented_gap: "))


@contextlib.contextmanager
def _stability_runs():
    """The stability runs: the augmented gap's non-convergence warnings of the solver held back."""
    logger, quiet = logging.getLogger("bem.solve"), _AugmentedGapWarnings()
    logger.addFilter(quiet)
    try:
        yield
    finally:
        logger.removeFilter(quiet)


def _methods(run, res, quick):
    """Iteration histories (Fig. 6, 8, 10, 11) and the stability table."""
    er, record = {"layer.alpha_a": ALPHA_A_ITERATIONS}, {"bem.record": True}
    relaxed = {"bem.method": "augmented_gap", "bem.relaxation": AG_RELAXATION, "bem.maxiter": 400}
    vc, newton = {"bem.method": "variable_compliance"}, {"bem.method": "newton", "bem.nested": False}
    it = res.iterations
    it["elastic-rigid, variable compliance"] = run("elastic-rigid", {**record, **er, **vc}).bem
    it["elastic-rigid, augmented gap"] = run("elastic-rigid", {**record, **er, **relaxed}).bem
    it["elastic-rigid, Newton"] = run("elastic-rigid", {**record, **er, **newton}).bem
    it["root, variable compliance"] = run("root", {**record, **vc}).bem
    it["root, Newton"] = run("root", {**record, **newton}).bem
    laws = [(f"elastic-rigid (alpha_a = {ALPHA_A_ITERATIONS})", "elastic-rigid", er), ("root", "root", {})]
    if not quick:
        alpha_c = res.outcomes["bilinear"].result.layer["alpha_c"]
        laws.append((f"bilinear (alpha_c = {alpha_c:.3f})", "bilinear", {}))
    methods = [("Newton", {}), ("variable compliance", vc), ("augmented gap, omega = 1 (paper)",
                                                            {"bem.method": "augmented_gap"}),
               (f"augmented gap, omega = {AG_RELAXATION}", relaxed)]
    for law, case, params in laws:
        for label, opts in methods:
            with _stability_runs():
                r = run(case, {**params, **opts}).bem
            res.stability.append({"law": law, "method": label, "status": r.status, "iterations": r.iterations,
                                  "p_max/p0": r.p_max / res.p0, "kkt_residual": r.kkt_residual,
                                  "wall_time_s": r.wall_time_s, "message": r.message})


def _work_point(solve, part, p0, **row):
    """Row of the resolution study: ``solve()`` WP_REPEATS times (once if slower than WP_SLOW_S), timed on ``part``."""
    runs = [solve()]
    if getattr(runs[0], part).wall_time_s <= WP_SLOW_S:
        runs += [solve() for _ in range(WP_REPEATS - 1)]
    last, times = getattr(runs[-1], part), [getattr(o, part).wall_time_s for o in runs]
    return {**row, "N": last.p.size if part == "bem" else last.n_dofs, "error": abs(last.p_max - p0) / p0,
            "wall_time_s": statistics.median(times), "wall_times_s": times}


def _validation(run, res, quick):
    n_fem = 8 if quick else 24
    for case in ("smooth", "linear Winkler", "elastic-rigid", "root"):
        res.validation[case] = run(case, analytic=True, fem={"n_contact_elements": n_fem})
    res.work_precision += [_work_point(lambda: run("smooth", {"bem.step": res.a / m, "bem.nested": True}), "bem",
                                       res.p0, solver="BEM", method="Kalker QP", resolution=f"a/c = {m}")
                           for m in ((4, 8) if quick else (5, 10, 20, 40, 80))]
    # the BEM of these runs on a coarse lattice: only the FEM is timed
    res.work_precision += [_work_point(lambda: run("smooth", {"bem.step": res.a / 4}, fem={"n_contact_elements": n}), "fem",
                                       res.p0, solver="FEM", method="P2 axisymmetric", resolution=f"{n} el./a")
                           for n in ((4, 8) if quick else (8, 16, 32))]


def run_paper_problem(*, quick=False, fem=True, progress=None):
    """Run every case of the paper report.

    Parameters
    ----------
    quick : bool
        Small version for tests and previews: 8 nodes per Hertz radius instead of 20, fewer
        sweep values (measured times: docs/performance.md, "Studies and reports").
    fem : bool
        Also run the FEM reference and the resolution study.
    progress : callable or validation.progress.Progress, optional
        ``progress(label, done, total)`` (:mod:`validation.progress`) at the start of each stage of
        :data:`SOLVE_STAGES` (the FEM stage only with ``fem``) and at the end (``"done"``); a
        :class:`~validation.progress.Progress` of a caller's job that holds these stages is told them
        and not the end.

    Returns
    -------
    PaperRuns
    """
    from ..progress import stages_of

    notify = stages_of(progress, [s for s in SOLVE_STAGES if fem or s != SOLVE_STAGES[3]])
    t0 = time.perf_counter()
    n = 8 if quick else 20
    run, res = CaseRunner(n), PaperRuns(quick=quick, nodes_per_radius=n)
    for stage, step in zip(SOLVE_STAGES, (_cases, _sweeps, _methods, _validation)):
        if stage != SOLVE_STAGES[3] or fem:
            notify(stage)
            step(run, res, quick)
    if notify is not progress:
        notify.done()
    res.wall_time_s = time.perf_counter() - t0
    log.info("paper problem run in %.1f s", res.wall_time_s)
    return res
