"""Pressure error against wall time for every BEM method and the FEM reference.

For each problem (:mod:`validation.studies.problems`: the scenes ``"hertz"`` and
``"paper-root"``, run by :func:`validation.run.execute_scene`) every applicable solver runs on
a ladder of resolutions: the BEM at ``n`` lattice steps across the expected contact diameter
(``bem.nodes_across`` 10, 20, 40, 80, 160; a method stops climbing after a run longer than
``time_budget_s``), the FEM at ``fem.n_contact`` elements across the contact radius (4, 8, 16,
32). Errors (:func:`validation.compare.pair_metrics` at the solver's own nodes):

- ``error_l2``: relative L2 error of the pressure over the contact;
- ``error_peak``: ``|p_max / p_max,ref - 1|``.

References: the run's closed form for ``"hertz"`` (Hertz, ``outcome.analytic``); for a problem
without one, the BEM Newton solution at 4 x the finest ladder resolution, whose own error is
estimated by Richardson's rule from the finest ladder level and 2 x and 4 x it
(``references`` in the result). Wall time: the runner's time of the solver
(``result["wall_time_s"]``; FEM: meshing included), median of ``repeats`` runs (one run when
the first takes more than ``slow_s`` or fails).

The augmented gap method is tried with the relaxations ``relaxations`` in turn at each level
until one converges; every attempt is a row. After a level where none converged, the finer
levels run only the first (the paper's ``omega = 1``), and its failure is recorded.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

from bem.checks import InputError, check_choice, check_positive

from ..compare import pair_metrics, relative_l2
from ..run import execute_scene
from . import fmt, markdown_table, timed, write_json, write_text
from .problems import ERROR_TIME_PROBLEMS, get_problem, methods

__all__ = ["ErrorTimeRow", "ErrorTimeStudy", "run_error_time", "main", "LADDERS", "TARGETS"]

#: resolution ladders: BEM steps across the contact diameter, FEM elements across the radius
LADDERS = {"full": {"bem": (10, 20, 40, 80, 160), "fem": (4, 8, 16, 32)},
           "quick": {"bem": (10, 20, 40), "fem": (4, 8, 16)}}
#: error targets of the "first to reach" summary
TARGETS = (1e-2, 1e-3)
_METRICS = ("error_l2", "error_peak")


@dataclass
class ErrorTimeRow:
    """One run of one solver at one resolution.

    Attributes
    ----------
    problem, solver, method : str
        Problem name; ``"bem"`` or ``"fem"``; the BEM method (``"fem"`` for the FEM).
    resolution : int
        BEM: steps across the contact diameter; FEM: elements across the contact radius.
    n : int
        Unknowns: BEM candidate nodes; FEM displacement DOFs.
    error_l2, error_peak : float or None
        Relative L2 and peak-pressure errors against the reference (module docstring).
    wall_time_s : float
        Median wall time [s] of ``runs`` runs.
    iterations : int
        Iterations of the method (BEM outer iterations, FEM Newton steps).
    converged : bool
        The solver's own verdict.
    relaxation : float or None
        Relaxation of the augmented gap method.
    runs : int
        Timed runs.
    message : str
        The solver's message.
    wall_times_s : list of float
        Wall time of every timed run [s] (their spread is drawn in the work-precision plot).
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

    @property
    def label(self):
        """Method name with its relaxation, e.g. ``augmented_gap (omega=0.5)``."""
        return self.method if self.relaxation is None else f"{self.method} (omega={self.relaxation:g})"


@dataclass
class ErrorTimeStudy:
    """Result of :func:`run_error_time`.

    Attributes
    ----------
    rows : list of ErrorTimeRow
    references : dict
        Per problem: ``kind`` (``"analytic"`` or ``"bem-newton"``), its description, and for a
        BEM reference its resolution and Richardson check (``order_peak``,
        ``error_peak_estimate``, ``order_l2``, ``error_l2_estimate``).
    settings : dict
        Ladders, repeats, budget and relaxations used.
    notes : list of str
        What was skipped and why.
    """

    rows: list = field(default_factory=list)
    references: dict = field(default_factory=dict)
    settings: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)

    @property
    def problems(self):
        """Problem names in the order they were run."""
        return list(dict.fromkeys(r.problem for r in self.rows))

    def _problem(self, problem):
        names = self.problems
        if problem is None:
            if len(names) != 1:
                raise InputError(f"problem = None is not allowed for a study of {len(names)} problems: "
                                 f"give one of {', '.join(map(repr, names))}.")
            return names[0]
        return check_choice("problem", problem, tuple(names))

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
            Count a run only if every converged run of the same solver and method (and
            relaxation) at a finer resolution also reaches ``tol``: a point that meets the
            target by a lucky placement of the nodes (the L2 error at a square-root edge is
            erratic) does not count.

        Returns
        -------
        ErrorTimeRow or None
            Smallest ``wall_time_s`` among the rows that reach ``tol``.
        """
        tol = check_positive("tol", tol)
        check_choice("metric", metric, _METRICS)
        name = self._problem(problem)

        def meets(r):
            return r.converged and getattr(r, metric) is not None and getattr(r, metric) <= tol

        rows = [r for r in self.rows if r.problem == name]
        ok = [r for r in rows if meets(r) and not (sustained and any(
            q.converged and not meets(q) and q.resolution > r.resolution
            and (q.solver, q.method, q.relaxation) == (r.solver, r.method, r.relaxation) for q in rows))]
        return min(ok, key=lambda r: r.wall_time_s, default=None)

    def table_markdown(self, problem=None):
        """Markdown table of the rows (of one problem, or of all with a problem column)."""
        rows = self.rows if problem is None else [r for r in self.rows if r.problem == self._problem(problem)]
        many = problem is None and len(self.problems) > 1
        head = (["problem"] if many else []) + ["solver", "method", "resolution", "N", "error L2", "error peak",
                                                "wall time [s]", "iterations", "converged"]
        body = [([r.problem] if many else []) + [
            r.solver, r.label, r.resolution, r.n, fmt(r.error_l2), fmt(r.error_peak), fmt(r.wall_time_s, ".3g"),
            r.iterations, fmt(r.converged)] for r in rows]
        return markdown_table(head, body)

    def first_to_reach_markdown(self):
        """Markdown section: which method and resolution reach 1 % and 0.1 % first."""
        lines = ["### First to reach the error target", "",
                 "The fastest converged run whose error is at most the target and stays so at every finer "
                 "converged level of its solver and method.", ""]
        body = []
        for name in self.problems:
            for metric in _METRICS:
                for tol in TARGETS:
                    r = self.first_to_reach(tol, problem=name, metric=metric)
                    target = f"{metric.replace('error_', '')} <= {tol:.1%}"
                    if r is None:
                        body.append([name, target, "none reached it", "-", "-"])
                        lines.append(f"- {name}, {target}: no converged run reached it.")
                    else:
                        body.append([name, target, f"{r.solver} {r.label}", r.resolution, fmt(r.wall_time_s, ".3g")])
                        lines.append(f"- {name}, {target}: first reached by {r.solver} {r.label} at resolution "
                                     f"{r.resolution} (N = {r.n}) in {r.wall_time_s:.3g} s.")
        lines += ["", markdown_table(["problem", "target", "first", "resolution", "wall time [s]"], body)]
        return "\n".join(lines)

    def markdown(self):
        """The whole study as markdown: references, one table per problem, first-to-reach, notes."""
        out = ["## Error against run time", ""]
        for name in self.problems:
            ref = self.references.get(name, {})
            out += [f"### {name}", "", ref.get("title", ""), "", f"Reference: {ref.get('description', '-')}", "",
                    self.table_markdown(name), ""]
        out.append(self.first_to_reach_markdown())
        if self.notes:
            out += ["", "Notes:", ""] + [f"- {n}" for n in self.notes]
        return "\n".join(out) + "\n"

    def to_dict(self):
        """JSON-ready dict of the whole study."""
        first = {name: {m: {f"{tol:g}": (None if (r := self.first_to_reach(tol, problem=name, metric=m)) is None
                                         else {"solver": r.solver, "method": r.label, "resolution": r.resolution,
                                               "wall_time_s": r.wall_time_s})
                            for tol in TARGETS} for m in _METRICS} for name in self.problems}
        return {"study": "error-time", "settings": self.settings, "references": self.references,
                "rows": [asdict(r) for r in self.rows], "first_to_reach": first, "notes": list(self.notes)}

    def to_json(self, path):
        """Write :meth:`to_dict` to ``path`` atomically. Returns the path."""
        return write_json(path, self.to_dict())


def _errors(result, reference):
    m = pair_metrics(result, reference)
    return m["l2_rel"], None if m["peak_rel"] is None else abs(m["peak_rel"])


def _row(name, part, method, n, overrides, reference, problem, opts, relaxation=None):
    """One timed row: ``problem`` with ``overrides`` (``reference`` ``None``: the run's closed form)."""
    outcome, t, times = timed(problem, part, overrides=overrides, repeats=opts["repeats"], slow_s=opts["slow_s"])
    res = getattr(outcome, part)
    l2, peak = _errors(res, outcome.analytic if reference is None else reference)
    size = res.p.size if part == "bem" else res.n_dofs
    return ErrorTimeRow(name, part, method if part == "bem" else "fem", n, int(size), l2, peak, t,
                        int(res.iterations), bool(res.converged), relaxation, len(times), res.message, times)


def _richardson(coarse, mid, fine):
    """Order and error estimate of ``fine`` from three BEM levels of halving steps."""
    p1, p2, p4 = coarse.p_max, mid.p_max, fine.p_max
    e12 = relative_l2(coarse.p, mid.pressure(coarse.x, coarse.y))
    e24 = relative_l2(mid.p, fine.pressure(mid.x, mid.y))

    def estimate(d1, d2):
        if not (d1 > 0 and d2 > 0) or d1 <= d2:
            return None, d2  # no asymptotic range: the last difference bounds the error
        order = math.log2(d1 / d2)
        return order, d2 / (2.0**order - 1.0)

    order_peak, err_peak = estimate(abs(p1 - p2) / abs(p4), abs(p2 - p4) / abs(p4))
    order_l2, err_l2 = estimate(e12, e24)
    return {"order_peak": order_peak, "error_peak_estimate": err_peak, "order_l2": order_l2,
            "error_l2_estimate": err_l2}


def _reference(problem, finest, bar):
    """The reference of ``problem`` (``None``: the closed form of each run) and its description (dict)."""
    title = problem["scene"]["description"]
    if "analytic" in problem:
        return None, {"kind": "analytic", "title": title, "description": "Hertz's closed form (exact for this problem)"}
    levels = [execute_scene(problem, overrides={"bem.nodes_across": k * finest}).bem for k in (1, 2, 4)]
    bar.update(3)
    ref = levels[-1]
    check = _richardson(*levels)
    desc = (f"BEM Newton at {4 * finest} steps across the contact ({ref.p.size} nodes, KKT residual "
            f"{ref.kkt_residual:.1e}); Richardson from {finest}/{2 * finest}/{4 * finest}: peak order "
            f"{fmt(check['order_peak'], '.2f')}, estimated reference error peak {fmt(check['error_peak_estimate'])}, "
            f"L2 order {fmt(check['order_l2'], '.2f')}, estimated reference error L2 {fmt(check['error_l2_estimate'])}")
    return ref, {"kind": "bem-newton", "title": title, "description": desc, "resolution": 4 * finest,
                 "n": int(ref.p.size), "converged": bool(ref.converged), **check}


def _bem_method(study, problem, method, ladder, reference, opts, bar):
    name = problem["scene"]["title"]
    relaxations = opts["relaxations"] if method == "augmented_gap" else (None,)
    for i, n in enumerate(ladder):
        for omega in relaxations:
            over = {"bem.nodes_across": n, "bem.method": method, **({} if omega is None else {"bem.relaxation": omega})}
            row = _row(name, "bem", method, n, over, reference, problem, opts, omega)
            study.rows.append(row)
            bar.update(1)
            if row.converged:
                break
        else:
            relaxations = relaxations[:1]
        if row.wall_time_s > opts["time_budget_s"] and i + 1 < len(ladder):
            study.notes.append(f"{name}: {method} took {row.wall_time_s:.3g} s at {n} steps across "
                               f"(> budget {opts['time_budget_s']:g} s); finer levels skipped")
            bar.update(len(ladder) - i - 1)
            return


def _methods(problem):
    return ("kalker",) if "layer" not in problem else methods(problem)


def run_error_time(problems=None, *, quick=False, bem_ladder=None, fem_ladder=None, repeats=3, slow_s=2.0,
                   time_budget_s=60.0, relaxations=None, fem=True, progress=False):
    """Run the error-time study.

    Parameters
    ----------
    problems : list of dict or str, optional
        Scene dicts or built-in problem names; default all of
        :data:`validation.studies.problems.ERROR_TIME_PROBLEMS`.
    quick : bool
        Use the short ladders of :data:`LADDERS` (for tests).
    bem_ladder, fem_ladder : sequence of int, optional
        Override the ladders.
    repeats : int
        Timed runs per point (median reported); 1 for slow or failed points.
    slow_s : float
        A first run longer than this [s] is not repeated.
    time_budget_s : float
        A method stops climbing its ladder after a run longer than this [s].
    relaxations : sequence of float, optional
        Relaxations of the augmented gap method, tried in turn (default ``(1, 0.5, 0.2)``,
        quick ``(1, 0.3)``).
    fem : bool
        Run the FEM ladder.
    progress : bool
        Show a tqdm progress bar (stderr).

    Returns
    -------
    ErrorTimeStudy
    """
    from tqdm import tqdm

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
    total = sum(3 * ("analytic" not in p) + len(fem_ladder) + len(bem_ladder) * (
        len(_methods(p)) + ("augmented_gap" in _methods(p)) * (len(relaxations) - 1)) for p in problems)
    with tqdm(total=total, desc="error-time", unit="run", disable=not progress) as bar:
        for problem in problems:
            name = problem["scene"]["title"]
            reference, study.references[name] = _reference(problem, max(bem_ladder), bar)
            if "layer" not in problem:
                study.notes.append(f"{name}: without a layer every BEM method is Kalker's QP "
                                   "(bem.solve dispatches them to it), so only 'kalker' is run")
            for method in _methods(problem):
                _bem_method(study, problem, method, bem_ladder, reference, opts, bar)
            for n in fem_ladder:  # the run's BEM part on the coarsest lattice: only the FEM is timed
                over = {"fem.n_contact": n, "bem.nodes_across": min(bem_ladder)}
                study.rows.append(_row(name, "fem", "fem", n, over, reference, problem, opts))
                bar.update(1)
        bar.total = bar.n  # relaxations not tried (after failures) were counted in the estimate
        bar.refresh()
    return study


def main(args):
    """Command-line entry: ``contactlab study error-time [SCENE] [--out DIR] [--quick]``.

    ``args`` has ``scene`` (a built-in problem name or ``None`` for all), ``out`` (directory,
    default the current one) and ``quick``. Writes ``error_time.json`` and ``error_time.md``
    there and prints the markdown. Returns 0.
    """
    from pathlib import Path

    from ..extras import require

    require("fem", "contactlab study error-time (the FEM reference)")
    scene = getattr(args, "scene", None)
    problems = None if scene is None else [get_problem(str(scene))]
    out = Path(getattr(args, "out", None) or ".")
    study = run_error_time(problems, quick=bool(getattr(args, "quick", False)),
                           progress=not getattr(args, "no_progress", False))
    study.to_json(out / "error_time.json")
    text = study.markdown()
    write_text(out / "error_time.md", text)
    print(text)
    return 0
