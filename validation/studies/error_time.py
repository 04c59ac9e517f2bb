"""Pressure error against wall time for every BEM method and the FEM reference.

Each problem (:data:`validation.studies.problems.ERROR_TIME_PROBLEMS`: ``"hertz"``,
``"paper-root"``) runs with every applicable solver on a ladder of resolutions: the BEM at
``bem.nodes_across`` steps across the expected contact diameter (10, 20, 40, 80, 160; a method
stops climbing after a run longer than ``time_budget_s``), the FEM at ``fem.n_contact_elements`` elements
across the contact radius (4, 8, 16, 32). The errors, at the solver's own nodes
(:func:`validation.compare.pair_metrics`), are ``error_l2`` (relative L2 error of the pressure
over the contact) and ``error_peak`` (``|p_max / p_max,ref - 1|``) against the run's closed form
(Hertz, ``outcome.analytic``) or, for a problem without one, the BEM Newton solution at 4 x the
finest ladder level, whose own error is estimated by Richardson's rule from the finest level,
2 x and 4 x it (``references``). Wall time: the runner's time of the solver (FEM: meshing
included), median of ``repeats`` runs (one when the first takes more than ``slow_s`` or fails).

The augmented gap method is tried with the relaxations ``relaxations`` in turn at each level
until one converges, every attempt a row; after a level where none converged the finer levels
run only the first (the paper's ``omega = 1``), and its failure is recorded.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

from bem.checks import InputError, check_choice, check_positive

from ..compare import pair_metrics, relative_l2
from ..progress import each
from ..run import execute_scene
from ..labels import fmt
from . import save, timed, write_json
from .problems import ERROR_TIME_PROBLEMS, get_problem, methods

__all__ = ["method_with_relaxation", "ErrorTimeRow", "ErrorTimeStudy", "run_error_time", "main", "STEM", "LADDERS", "TARGETS"]

#: the study's file is ``STEM + ".json"``, named after this module (:data:`validation.studies.STUDY_FILES`)
STEM = __name__.rpartition(".")[2]

#: resolution ladders: BEM steps across the contact diameter, FEM elements across the radius
LADDERS = {"full": {"bem": (10, 20, 40, 80, 160), "fem": (4, 8, 16, 32)},
           "quick": {"bem": (10, 20, 40), "fem": (4, 8, 16)}}
#: error targets of the "first to reach" summary
TARGETS = (1e-2, 1e-3)
_METRICS = ("error_l2", "error_peak")


def method_with_relaxation(method, relaxation=None):
    """The method's key with its relaxation when one was set, e.g. ``augmented_gap (omega=1)``.

    The run's identity in a study's rows; the readable name of a method for figures is
    ``validation.report.render.style.method_label``.
    """
    return method if relaxation is None else f"{method} (omega={relaxation:g})"


@dataclass
class ErrorTimeRow:
    """One run of one solver (``"bem"`` or ``"fem"``) at one resolution.

    ``method``: the BEM method (``"fem"`` for the FEM) with its ``relaxation`` (augmented gap);
    ``resolution``: BEM steps across the contact diameter or FEM elements across its radius;
    ``n``: unknowns (BEM candidate nodes, FEM displacement DOFs); ``error_l2``, ``error_peak``:
    against the reference (module docstring); ``wall_time_s``: median of the ``runs`` timed runs
    [s], ``wall_times_s`` every one of them [s]; ``iterations``, ``converged``, ``message``: the
    solver's; ``solver_status``: the solver's ``status`` (:data:`bem.STATUSES`,
    :data:`fem_reference.STATUSES`).
    """

    problem: str
    solver: str
    method: str
    resolution: int
    n: int
    error_l2: float | None
    error_peak: float | None
    wall_time_s: float
    iterations: int
    converged: bool
    relaxation: float | None = None
    runs: int = 1
    message: str = ""
    wall_times_s: list = field(default_factory=list)
    solver_status: str | None = None

    @property
    def label(self):
        """Method name with its relaxation (:func:`method_with_relaxation`)."""
        return method_with_relaxation(self.method, self.relaxation)


@dataclass
class ErrorTimeStudy:
    """Result of :func:`run_error_time`: ``rows``; ``references`` per problem (``kind``
    ``"analytic"`` or ``"bem-newton"``, ``title``, ``description``, and for a BEM reference its
    ``resolution`` and Richardson check ``order_peak``, ``error_peak_estimate``, ``order_l2``,
    ``error_l2_estimate``); ``settings`` (ladders, repeats, budget, relaxations); ``notes``."""

    rows: list = field(default_factory=list)
    references: dict = field(default_factory=dict)
    settings: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)

    @property
    def problems(self):
        """Problem names in the order they were run."""
        return list(dict.fromkeys(r.problem for r in self.rows))

    def first_to_reach(self, tol, *, problem=None, metric="error_l2", sustained=True):
        """The fastest converged run whose error is at most ``tol``, or ``None``.

        Parameters
        ----------
        tol : float
            Error target (relative, e.g. ``1e-2`` for 1 %).
        problem : str, optional
            Problem name; may be left out when the study holds one problem.
        metric : {"error_l2", "error_peak"}
            The error compared with ``tol``.
        sustained : bool
            Count a run only if every converged run of the same solver, method and relaxation at
            a finer resolution also reaches ``tol`` (not a lucky placement of the nodes: the L2
            error at a square-root edge is erratic).

        Returns
        -------
        ErrorTimeRow or None
            Smallest ``wall_time_s`` among the rows that reach ``tol``.
        """
        tol = check_positive("tol", tol)
        check_choice("metric", metric, _METRICS)
        if problem is None and len(self.problems) != 1:
            raise InputError(f"problem = None is not allowed for a study of {len(self.problems)} problems: "
                             f"give one of {', '.join(map(repr, self.problems))}.")
        name = self.problems[0] if problem is None else check_choice("problem", problem, tuple(self.problems))
        rows = [r for r in self.rows if r.problem == name]

        def meets(r):
            return r.converged and getattr(r, metric) is not None and getattr(r, metric) <= tol

        ok = [r for r in rows if meets(r) and not (sustained and any(
            q.converged and not meets(q) and q.resolution > r.resolution
            and (q.solver, q.method, q.relaxation) == (r.solver, r.method, r.relaxation) for q in rows))]
        return min(ok, key=lambda r: r.wall_time_s, default=None)

    def to_dict(self):
        """JSON-ready dict of the whole study."""

        def hit(r):
            return r and {"solver": r.solver, "method": r.label, "resolution": r.resolution,
                          "wall_time_s": r.wall_time_s}

        first = {name: {m: {f"{tol:g}": hit(self.first_to_reach(tol, problem=name, metric=m)) for tol in TARGETS}
                        for m in _METRICS} for name in self.problems}
        return {"study": "error-time", "settings": self.settings, "references": self.references,
                "rows": [asdict(r) for r in self.rows], "first_to_reach": first, "notes": list(self.notes)}

    def to_json(self, path):
        """Write :meth:`to_dict` to ``path`` atomically. Returns the path."""
        return write_json(path, self.to_dict())


def _richardson(coarse, mid, fine):
    """Order and error estimate of ``fine`` from three BEM levels of halving steps."""
    e12 = relative_l2(coarse.p, mid.pressure(coarse.x, coarse.y))
    e24 = relative_l2(mid.p, fine.pressure(mid.x, mid.y))

    def estimate(d1, d2):
        if not (d1 > 0 and d2 > 0) or d1 <= d2:
            return None, d2  # no asymptotic range: the last difference bounds the error
        order = math.log2(d1 / d2)
        return order, d2 / (2.0**order - 1.0)

    p1, p2, p4 = coarse.p_max, mid.p_max, fine.p_max
    order_peak, err_peak = estimate(abs(p1 - p2) / abs(p4), abs(p2 - p4) / abs(p4))
    order_l2, err_l2 = estimate(e12, e24)
    return {"order_peak": order_peak, "error_peak_estimate": err_peak, "order_l2": order_l2,
            "error_l2_estimate": err_l2}


def _reference(problem, finest):
    """The reference of ``problem`` (``None``: each run's closed form) and its description (dict)."""
    title = problem["scene"]["description"]
    kind = problem.get("analytic", {}).get("kind")
    if kind is not None:
        desc = "Hertz's closed form (exact for this problem)" if kind == "hertz" else f"the closed form {kind!r}"
        return None, {"kind": "analytic", "title": title, "description": desc}
    levels = [execute_scene(problem, overrides={"bem.nodes_across": k * finest}).bem for k in (1, 2, 4)]
    ref, check = levels[-1], _richardson(*levels)
    desc = (f"BEM Newton at {4 * finest} steps across the contact ({ref.p.size} nodes, KKT residual "
            f"{ref.kkt_residual:.1e}); Richardson from {finest}/{2 * finest}/{4 * finest}: peak order "
            f"{fmt(check['order_peak'], '.2f')}, estimated reference error peak "
            f"{fmt(check['error_peak_estimate'], '.2e')}, L2 order {fmt(check['order_l2'], '.2f')}, "
            f"estimated reference error L2 {fmt(check['error_l2_estimate'], '.2e')}")
    return ref, {"kind": "bem-newton", "title": title, "description": desc, "resolution": 4 * finest,
                 "n": int(ref.p.size), "converged": bool(ref.converged), **check}


def _climb(study, problem, method, ladder, reference, opts):
    """The rows of one solver and method up its ladder (the FEM: ``method = "fem"``, its BEM part on the
    coarsest BEM level, not timed)."""
    name, part = problem["scene"]["title"], "fem" if method == "fem" else "bem"
    relaxations = opts["relaxations"] if method == "augmented_gap" else (None,)
    for i, n in enumerate(ladder):
        for omega in relaxations:
            if part == "fem":
                over = {"fem.n_contact_elements": n, "bem.nodes_across": opts["coarsest"]}
            else:
                over = {"bem.nodes_across": n, "bem.method": method}
                over.update({} if omega is None else {"bem.relaxation": omega})
            outcome, t, times = timed(problem, part, overrides=over, repeats=opts["repeats"], slow_s=opts["slow_s"])
            res = getattr(outcome, part)
            m = pair_metrics(res, outcome.analytic if reference is None else reference)
            study.rows.append(ErrorTimeRow(
                name, part, method, n, int(res.p.size if part == "bem" else res.n_dofs), m["l2_rel"],
                None if m["peak_rel"] is None else abs(m["peak_rel"]), t, int(res.iterations), bool(res.converged),
                omega, len(times), res.message, times, res.status))
            if res.converged:
                break
        else:
            relaxations = relaxations[:1]
        if t > opts["time_budget_s"] and i + 1 < len(ladder):
            study.notes.append(f"{name}: {method} took {t:.3g} s at resolution {n} "
                               f"(> budget {opts['time_budget_s']:g} s); finer levels skipped")
            return


def run_error_time(problems=None, *, quick=False, bem_ladder=None, fem_ladder=None, repeats=3, slow_s=2.0,
                   time_budget_s=60.0, relaxations=None, fem=True, progress=None):
    """Run the error-time study.

    Parameters
    ----------
    problems : list of dict or str, optional
        Scene dicts or problem names; default all of :data:`~validation.studies.problems.ERROR_TIME_PROBLEMS`.
    quick : bool
        The short ladders of :data:`LADDERS` (for tests).
    bem_ladder, fem_ladder : sequence of int, optional
        Other ladders.
    repeats : int
        Timed runs per point (median reported); 1 for slow or failed points.
    slow_s, time_budget_s : float
        A first run longer than ``slow_s`` [s] is not repeated; a method stops climbing its ladder
        after a run longer than ``time_budget_s`` [s].
    relaxations : sequence of float, optional
        Relaxations of the augmented gap method, tried in turn (default ``(1, 0.5, 0.2)``, quick ``(1, 0.3)``).
    fem : bool
        Run the FEM ladder.
    progress : callable, optional
        ``progress(label, done, total)`` (:mod:`validation.progress`), one step per ladder.

    Returns
    -------
    ErrorTimeStudy
    """
    mode = "quick" if quick else "full"
    bem_ladder = tuple(LADDERS[mode]["bem"] if bem_ladder is None else bem_ladder)
    fem_ladder = tuple(LADDERS[mode]["fem"] if fem_ladder is None else fem_ladder) if fem else ()
    relaxations = tuple(((1.0, 0.3) if quick else (1.0, 0.5, 0.2)) if relaxations is None else relaxations)
    problems = [get_problem(p) if isinstance(p, str) else p
                for p in (ERROR_TIME_PROBLEMS.values() if problems is None else problems)]
    opts = {"repeats": int(repeats), "slow_s": float(slow_s), "time_budget_s": float(time_budget_s),
            "relaxations": relaxations}
    study = ErrorTimeStudy(settings={"mode": mode, "bem_ladder": list(bem_ladder), "fem_ladder": list(fem_ladder),
                                     **opts, "relaxations": list(relaxations)})
    ladders = [(p, m, fem_ladder if m == "fem" else bem_ladder) for p in problems
               for m in (methods(p) if "layer" in p else ("kalker",)) + (("fem",) if fem_ladder else ())]
    for problem, method, ladder in each(ladders, progress, lambda t: f"{t[0]['scene']['title']} {t[1]}"):
        name = problem["scene"]["title"]
        if name not in study.references:
            reference, study.references[name] = _reference(problem, max(bem_ladder))
            if "layer" not in problem:
                study.notes.append(f"{name}: without a layer every BEM method is Kalker's QP "
                                   "(bem.solve dispatches them to it), so only 'kalker' is run")
        _climb(study, problem, method, ladder, reference, {**opts, "coarsest": min(bem_ladder)})
    return study


def main(*, out=None, scene=None, quick=False, progress=None):
    """``contactlab study error-time``: the problem ``scene`` (a name of
    :data:`~validation.studies.problems.ERROR_TIME_PROBLEMS`; ``None``: all), a short ladder when
    ``quick``; writes ``error_time.json`` into the folder ``out`` (``None``: the current directory)
    (:class:`~validation.studies.StudyRun`, status 0). ``progress(label, done, total)``: :mod:`validation.progress`."""
    from ..extras import require

    require("fem", "contactlab study error-time (the FEM reference)")
    study = run_error_time(None if scene is None else [scene], quick=bool(quick), progress=progress)
    return save(out, STEM, study.to_dict())
