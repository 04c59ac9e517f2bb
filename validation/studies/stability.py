"""Stability study: every method on stiff and extreme cases, every outcome classified.

Cases (:func:`validation.studies.problems.stability_cases`, scenes run by the runner): layer
compliance over six decades (``1e-3 .. 1e3`` times the elastic compliance over the contact),
power laws ``s = 0.2 .. 3``, an elastic-rigid layer with a tiny ``p_cr``, a contact of a few
nodes, a contact filling most of the candidate region, very dissimilar moduli (``E1/E2 = 1e3``,
``nu2 = 0.49``) and nearly incompressible bodies in the FEM (``nu = 0.49, 0.499``).

Each case runs every BEM method that applies, and the FEM where the case has ``[fem]`` (in the
Newton run). Every outcome gets one status (:func:`validation.studies.classify`):

- ``"converged"``: the solver says converged, every value is finite, and it agrees with the
  reference within the tolerance (or no reference exists: then its KKT residual is the only
  check, and ``error_vs_reference`` is ``None``);
- ``"reported failure"``: the solver says it did not converge (``converged = False`` with a
  message) or raised an error with a message; every returned value finite;
- ``"wrong"``: a NaN or inf anywhere in the returned result, or ``converged = True`` with an
  error against the reference above the tolerance.

``error_vs_reference = max(l2_rel, |peak_rel|)`` (:func:`validation.compare.pair_metrics`).
References and tolerances:

- paper methods and Kalker's QP: Newton at the same resolution, :data:`METHOD_TOL`
  (the same discrete problem, solved to a KKT residual of ``1e-10``);
- Newton: the case's closed form (``outcome.analytic``: Hertz, or a layer limit) with
  :data:`~validation.studies.problems.LIMIT_TOL`, else the FEM with :data:`FEM_TOL` when the
  FEM runs, else none;
- FEM: Hertz for smooth bodies, else BEM Newton, with :data:`FEM_TOL` (two different
  discretisations: 25 BEM steps across the diameter, 16 FEM elements across the radius).

:meth:`StabilityStudy.check` (called by :func:`run_stability` unless ``check=False``) raises
:class:`StabilityFailure` listing every wrong outcome.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import asdict, dataclass, field

from bem.reference import hertz_sphere

from ..compare import pair_metrics
from . import STATUSES, attempt, classify, finite, fmt, markdown_table, write_json, write_text
from .problems import LIMIT_TOL, methods, stability_cases

__all__ = ["StabilityRow", "StabilityStudy", "StabilityFailure", "run_stability", "classify", "main",
           "METHOD_TOL", "FEM_TOL", "STATUSES"]

#: agreement required of a method with Newton on the same lattice
METHOD_TOL = 1e-6
#: agreement required between the FEM and the BEM (or Hertz)
FEM_TOL = 0.05


class StabilityFailure(RuntimeError):
    """A solver returned NaN or a wrong answer it called converged; ``.rows`` lists them."""

    def __init__(self, rows, study=None):
        self.rows, self.study = list(rows), study
        lines = [f"{r.case} / {r.solver} {r.method}: error {fmt(r.error_vs_reference)} > tol {fmt(r.tolerance)} "
                 f"({r.message})" for r in self.rows]
        super().__init__(f"{len(self.rows)} wrong outcome(s) in the stability study:\n  " + "\n  ".join(lines))


@dataclass
class StabilityRow:
    """One solver on one case.

    Attributes
    ----------
    case, solver, method : str
        Case name; ``"bem"`` or ``"fem"``; the method (``"fem"`` for the FEM).
    status : str
        One of :data:`STATUSES` (module docstring).
    kkt_residual : float or None
        BEM: the KKT residual of the returned state; FEM: final relative Newton residual;
        ``None`` when the run raised.
    error_vs_reference, tolerance : float or None
        ``max(l2_rel, |peak_rel|)`` against ``reference`` (``"-"``: nothing), and its tolerance.
    iterations : int
    wall_time_s : float
        The solver's wall time [s] (of the whole run when it raised).
    message : str
        Why the status was given, and the solver's message.
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

    def markdown(self):
        """The study as markdown: a per-method summary, then the full table."""
        summary = markdown_table(["solver / method"] + list(STATUSES),
                                 [[k] + [v[s] for s in STATUSES] for k, v in self.counts().items()])
        table = markdown_table(
            ["case", "solver", "method", "status", "KKT residual", "error vs reference", "reference", "iterations",
             "wall time [s]", "message"],
            [[r.case, r.solver, r.method, r.status, fmt(r.kkt_residual, ".1e"), fmt(r.error_vs_reference),
              r.reference, r.iterations, fmt(r.wall_time_s, ".3g"), _short(r.message)] for r in self.rows])
        return "\n".join([
            "## Stability on stiff and extreme cases", "",
            f"Tolerances: paper methods and QP against Newton on the same lattice {METHOD_TOL:g}; FEM against "
            f"Hertz or BEM Newton {FEM_TOL:g}; Newton against the case's closed form at the case's tolerance.",
            "", summary, "", table, ""])

    def to_dict(self):
        """JSON-ready dict."""
        return {"study": "stability", "settings": self.settings, "counts": self.counts(),
                "rows": [asdict(r) for r in self.rows]}

    def to_json(self, path):
        """Write :meth:`to_dict` to ``path`` atomically. Returns the path."""
        return write_json(path, self.to_dict())


def _short(message, n=110):
    message = " ".join(str(message).split())
    return message if len(message) <= n else message[: n - 3] + "..."


def _part(run, part):
    """``(solver result or None, wall time [s], why it raised)`` of the ``"bem"`` or ``"fem"`` part of a run."""
    outcome, seconds, raised = run
    if outcome is None:
        return None, seconds, f"raised {raised}"
    return getattr(outcome, part), outcome.result["wall_time_s"][part], ""


def _good(part):
    return part[0] is not None and bool(part[0].converged) and finite(part[0])


def _closed(case, limit, run):
    """``(name, closed form, tolerance)`` of a case's ``limit``, or ``None``: the run's ``[analytic]``,
    or Hertz's solution of the run's bodies, gap and load (the limit of a stiff layer)."""
    outcome = run[0]
    if limit is None or outcome is None:
        return None
    scene = outcome.scene
    ref = outcome.analytic or hertz_sphere(scene.gap.R, scene.E_star, **scene.load)
    return (f"{limit} limit" if "layer" in case else "Hertz"), ref, LIMIT_TOL[limit]


def _row(case, solver, method, part, reference):
    """Row of one solver result ``(result, seconds, raised)`` against ``(name, object, tol)`` or ``None``."""
    result, seconds, raised = part
    ref_name, ref, tol = reference if reference is not None else ("-", None, None)
    name = case["scene"]["title"]
    if result is None:
        return StabilityRow(name, solver, method, "reported failure", None, None, ref_name, tol, 0, seconds, raised)
    error = None
    if ref is not None and finite(result):
        m = pair_metrics(result, ref)
        error = math.inf if None in (m["l2_rel"], m["peak_rel"]) else max(m["l2_rel"], abs(m["peak_rel"]))
    status, why = classify(result, converged=bool(result.converged), error=error, tolerance=tol)
    kkt = result.residual if solver == "fem" else result.kkt_residual
    return StabilityRow(name, solver, method, status, float(kkt) if math.isfinite(kkt) else None, error, ref_name,
                        tol, int(result.iterations), seconds, f"{why}; {result.message}")


def _run_case(case, limit):
    bem_only = {k: v for k, v in case.items() if k != "fem"}
    first = attempt(case)  # Newton, with the FEM when the case has [fem]
    fem = _part(first, "fem") if "fem" in case else None
    if first[0] is None and fem is not None:  # the run raised: run Newton alone to tell whose error it was
        first = attempt(bem_only)
    newton, closed = _part(first, "bem"), _closed(case, limit, first)
    rows = [_row(case, "bem", "newton", newton,
                 closed or (("FEM", fem[0], FEM_TOL) if fem is not None and _good(fem) else None))]
    for method in methods(case)[1:]:
        run = attempt(bem_only, {"bem.method": method})
        same = ("Newton, same lattice", newton[0], METHOD_TOL) if _good(newton) else _closed(case, limit, run)
        rows.append(_row(case, "bem", method, _part(run, "bem"), same))
    if fem is not None:
        if "layer" not in case and closed is not None:
            fem_ref = ("Hertz", closed[1], FEM_TOL)
        elif _good(newton):
            fem_ref = ("BEM Newton", newton[0], FEM_TOL)
        else:
            fem_ref = None if closed is None else (closed[0], closed[1], max(FEM_TOL, closed[2]))
        rows.append(_row(case, "fem", "fem", fem, fem_ref))
    return rows


def run_stability(cases=None, *, quick=False, check=True, progress=False):
    """Run the stability study.

    Parameters
    ----------
    cases : list of (dict, str or None), optional
        Scene dicts and their closed-form limits; default
        :func:`validation.studies.problems.stability_cases` (``quick``: the subset).
    quick : bool
        The representative subset of cases (for tests).
    check : bool
        Raise :class:`StabilityFailure` when any outcome is wrong.
    progress : bool
        Show a tqdm progress bar (stderr).

    Returns
    -------
    StabilityStudy

    Raises
    ------
    StabilityFailure
        With ``check``: a NaN anywhere, or a wrong answer called converged.
    """
    from tqdm import tqdm

    cases = stability_cases(quick) if cases is None else list(cases)
    study = StabilityStudy(settings={"mode": "quick" if quick else "full", "method_tol": METHOD_TOL,
                                     "fem_tol": FEM_TOL, "cases": [c["scene"]["title"] for c, _ in cases]})
    for case, limit in tqdm(cases, desc="stability", unit="case", disable=not progress):
        study.rows += _run_case(case, limit)
    return study.check() if check else study


def main(args):
    """Command-line entry: ``contactlab study stability [--out DIR] [--quick]``.

    Writes ``stability.json`` and ``stability.md`` to ``args.out`` (default the current
    directory), prints the markdown, then raises :class:`StabilityFailure` if any outcome is
    wrong. Returns 0.
    """
    from pathlib import Path

    from ..extras import require

    require("fem", "contactlab study stability (the FEM cases)")
    out = Path(getattr(args, "out", None) or ".")
    study = run_stability(quick=bool(getattr(args, "quick", False)), check=False,
                          progress=not getattr(args, "no_progress", False))
    study.to_json(out / "stability.json")
    text = study.markdown()
    write_text(out / "stability.md", text)
    print(text)
    study.check()
    return 0
