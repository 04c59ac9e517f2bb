"""Stability study: every method on stiff and extreme cases, every outcome classified.

Cases (:func:`validation.studies.problems.stability_cases`): layer compliance over six decades
(``1e-3 .. 1e3`` times the elastic compliance over the contact), power laws ``s = 0.2 .. 3``, an
elastic-rigid layer with a tiny ``p_cr``, a contact of a few nodes, a contact filling most of the
candidate region, very dissimilar moduli (``E1/E2 = 1e3``, ``nu2 = 0.49``) and nearly
incompressible bodies in the FEM (``nu = 0.49, 0.499``). Each case runs every BEM method that
applies, and the FEM where the case has ``[fem]`` (in the Newton run); each outcome gets a status
of :func:`validation.studies.classify` against its reference, by
``error_vs_reference = max(l2_rel, |peak_rel|)`` (:func:`validation.compare.pair_metrics`):

- paper methods and Kalker's QP: Newton at the same resolution, :data:`METHOD_TOL` (the same
  discrete problem, solved to a KKT residual of ``1e-10``);
- Newton: the case's closed-form limit (Hertz, or the rigid-body layer) with
  :data:`~validation.studies.problems.LIMIT_TOL`, else the FEM with :data:`FEM_TOL` when it runs;
- FEM: Hertz for smooth bodies, else BEM Newton on a lattice 4 x finer than the case's, with
  :data:`FEM_TOL` (at the case's 25 steps across the diameter the BEM's own interpolation error
  at a steep contact edge dominates the difference: 6.0 % against the FEM for ``s = 3``, 0.4 %
  at 100 steps, where the FEM has 16 elements across the radius).

Without a reference a converged answer is checked by its KKT residual only. A NaN or a wrong
answer called converged makes :meth:`StabilityStudy.check` raise :class:`StabilityFailure`.
"""

from __future__ import annotations

import logging
import math
from collections import Counter
from dataclasses import asdict, dataclass, field

from bem.reference import hertz_sphere

from ..compare import pair_metrics
from ..labels import fmt
from ..progress import each
from . import STATUSES, attempt, classify, finite, no_scene, save
from .problems import LIMIT_TOL, methods, stability_cases

__all__ = ["StabilityRow", "StabilityStudy", "StabilityFailure", "run_stability", "classify", "main", "STEM",
           "METHOD_TOL", "FEM_TOL", "STATUSES"]

#: the study's file is ``STEM + ".json"``, named after this module (:data:`validation.studies.STUDY_FILES`)
STEM = __name__.rpartition(".")[2]

log = logging.getLogger(__name__)

#: agreement required of a method with Newton on the same lattice
METHOD_TOL = 1e-6
#: agreement required between the FEM and the BEM (or Hertz)
FEM_TOL = 0.05


class StabilityFailure(RuntimeError):
    """A solver returned NaN or a wrong answer it called converged; ``.rows`` lists them."""

    def __init__(self, rows, study=None):
        self.rows, self.study = list(rows), study
        lines = [f"{r.case} / {r.solver} {r.method}: error {fmt(r.error_vs_reference, '.2e')} > "
                 f"tol {fmt(r.tolerance, '.2e')} ({r.message})" for r in self.rows]
        super().__init__(f"{len(self.rows)} wrong outcome(s) in the stability study:\n  " + "\n  ".join(lines))


@dataclass
class StabilityRow:
    """One solver (``"bem"`` or ``"fem"``) and method (``"fem"`` for the FEM) on one case.

    ``kkt_residual``: BEM KKT residual, FEM final relative Newton residual (``None`` when the run
    raised); ``error_vs_reference`` against ``reference`` (``"-"``: none) with ``tolerance``;
    ``wall_time_s`` [s]: the solver's (the whole run's when it raised); ``message``: why the
    status, and the solver's message; ``solver_status``: the solver's ``status``
    (:data:`bem.STATUSES`, :data:`fem_reference.STATUSES`; ``None`` when the run raised).
    """

    case: str
    solver: str
    method: str
    status: str
    kkt_residual: float | None
    error_vs_reference: float | None
    reference: str
    tolerance: float | None
    iterations: int
    wall_time_s: float
    message: str
    solver_status: str | None = None


@dataclass
class StabilityStudy:
    """Result of :func:`run_stability`: ``rows`` and the ``settings`` used."""

    rows: list = field(default_factory=list)
    settings: dict = field(default_factory=dict)

    def wrong(self):
        """Rows with status ``"wrong"``."""
        return [r for r in self.rows if r.status == "wrong"]

    def check(self):
        """Raise :class:`StabilityFailure` if any outcome is wrong; else return ``self``."""
        if self.wrong():
            raise StabilityFailure(self.wrong(), self)
        return self

    def counts(self):
        """``{"solver method": {status: count}}`` over all cases."""
        out = {}
        for r in self.rows:
            out.setdefault(f"{r.solver} {r.method}", Counter())[r.status] += 1
        return {k: {s: v.get(s, 0) for s in STATUSES} for k, v in out.items()}

    def to_dict(self):
        """JSON-ready dict."""
        return {"study": "stability", "settings": self.settings, "counts": self.counts(),
                "rows": [asdict(r) for r in self.rows]}


def _part(run, part):
    """``(result or None, wall time [s], why it raised)`` of the ``"bem"`` or ``"fem"`` part of an attempt."""
    outcome, seconds, raised = run
    if outcome is None:
        return None, seconds, f"raised {raised}"
    return getattr(outcome, part), outcome.result.wall_time_s_by_part[part], ""


def _good(part):
    return part[0] is not None and bool(part[0].converged) and finite(part[0])


def _closed(case, limit, run):
    """``(name, closed form, tolerance)`` of the case's ``limit`` or ``None``: the run's ``[analytic]``,
    else Hertz's solution of the run's bodies, gap and load (the limit of a stiff layer)."""
    outcome = run[0]
    if limit is None or outcome is None:
        return None
    scene = outcome.scene
    ref = outcome.analytic or hertz_sphere(scene.gap.R, scene.E_star, **scene.load)
    return (f"{limit} limit" if "layer" in case else "Hertz"), ref, LIMIT_TOL[limit]


def _row(case, solver, method, part, reference):
    """The row of ``part`` (:func:`_part`) against ``reference`` ``(name, object, tolerance)`` or ``None``."""
    result, seconds, raised = part
    ref_name, ref, tol = reference or ("-", None, None)
    row = dict(case=case["scene"]["title"], solver=solver, method=method, reference=ref_name, tolerance=tol)
    if result is None:
        return StabilityRow(**row, status="reported failure", kkt_residual=None, error_vs_reference=None,
                            iterations=0, wall_time_s=seconds, message=raised)
    error = None
    if ref is not None and finite(result):
        m = pair_metrics(result, ref)
        error = math.inf if None in (m["l2_rel"], m["peak_rel"]) else max(m["l2_rel"], abs(m["peak_rel"]))
    status, why = classify(result, converged=bool(result.converged), error=error, tolerance=tol)
    kkt = float(result.residual if solver == "fem" else result.kkt_residual)
    return StabilityRow(**row, status=status, kkt_residual=kkt if math.isfinite(kkt) else None,
                        error_vs_reference=error, iterations=int(result.iterations), wall_time_s=seconds,
                        message=f"{why}; {result.message}", solver_status=result.status)


def _run_case(case, limit):
    bem_only = {k: v for k, v in case.items() if k != "fem"}
    first = attempt(case)  # Newton, and the FEM when the case has [fem]
    fem = _part(first, "fem") if "fem" in case else None
    if first[0] is None and fem is not None:  # it raised: Newton alone tells whose error it was
        first = attempt(bem_only)
    newton, closed = _part(first, "bem"), _closed(case, limit, first)
    fem_ok = fem is not None and _good(fem)
    rows = [_row(case, "bem", "newton", newton, closed or (("FEM", fem[0], FEM_TOL) if fem_ok else None))]
    for method in methods(case)[1:]:
        run = attempt(bem_only, {"bem.method": method})
        same = ("Newton, same lattice", newton[0], METHOD_TOL) if _good(newton) else _closed(case, limit, run)
        rows.append(_row(case, "bem", method, _part(run, "bem"), same))
    if fem is not None:
        fine = (None,)
        if "layer" in case and newton[0] is not None:  # Newton on a 4x finer lattice (module docstring)
            fine = _part(attempt(bem_only, {"bem.step": newton[0].step / 4}), "bem")
        if "layer" not in case and closed is not None:
            fem_ref = ("Hertz", closed[1], FEM_TOL)
        elif _good(fine):
            fem_ref = ("BEM Newton, 4x finer", fine[0], FEM_TOL)
        else:
            fem_ref = closed and (closed[0], closed[1], max(FEM_TOL, closed[2]))
        rows.append(_row(case, "fem", "fem", fem, fem_ref))
    return rows


def run_stability(cases=None, *, quick=False, check=True, progress=None):
    """Run the stability study.

    Parameters
    ----------
    cases : list of (dict, str or None), optional
        Scene dicts and their closed-form limits; default :func:`~validation.studies.problems.stability_cases`.
    quick : bool
        The representative subset of the default cases (for tests).
    check : bool
        Raise :class:`StabilityFailure` when any outcome is wrong (a NaN anywhere, or a wrong answer
        called converged).
    progress : callable, optional
        ``progress(label, done, total)`` (:mod:`validation.progress`), one step per case.

    Returns
    -------
    StabilityStudy
    """
    cases = stability_cases(quick) if cases is None else list(cases)
    study = StabilityStudy(settings={"mode": "quick" if quick else "full", "method_tol": METHOD_TOL,
                                     "fem_tol": FEM_TOL, "cases": [c["scene"]["title"] for c, _ in cases]})
    for case, limit in each(cases, progress, lambda c: c[0]["scene"]["title"]):
        study.rows += _run_case(case, limit)
    return study.check() if check else study


def main(*, out=None, scene=None, quick=False, progress=None):
    """``contactlab study stability``: every case, or a short list when ``quick``; writes
    ``stability.json`` into the folder ``out`` (``None``: the current directory). Returns the
    :class:`~validation.studies.StudyRun`, status 1 if any outcome is wrong (logged as an error with
    the :class:`StabilityFailure` message), else 0. The study takes no ``scene``;
    ``progress(label, done, total)``: :mod:`validation.progress`."""
    from ..extras import require

    no_scene("stability", scene)
    require("fem", "contactlab study stability (the FEM cases)")
    study = run_stability(quick=bool(quick), check=False, progress=progress)
    if study.wrong():
        log.error("%s", StabilityFailure(study.wrong(), study))
    return save(out, STEM, study.to_dict(), status=int(bool(study.wrong())))
