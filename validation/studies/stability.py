"""Stability study: every method on stiff and extreme cases, every outcome classified.

Cases (:func:`validation.studies.problems.stability_cases`): layer compliance over six
decades (``1e-3 .. 1e3`` times the elastic compliance over the contact), power laws
``s = 0.2 .. 3``, an elastic-rigid layer with a tiny ``p_cr``, a contact of a few nodes, a
contact filling most of the candidate region, very dissimilar moduli (``E1/E2 = 1e3``,
``nu2 = 0.49``) and nearly incompressible bodies in the FEM (``nu = 0.49, 0.499``).

Each case runs every BEM method that applies, and the FEM where the case marks it relevant.
Every outcome gets one status:

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
- Newton: the case's closed form (Hertz, or a layer limit) with the case's tolerance, else
  the FEM with :data:`FEM_TOL` when the FEM runs, else none;
- FEM: Hertz for smooth bodies, else BEM Newton, with :data:`FEM_TOL` (two different
  discretisations: 25 BEM steps across the diameter, 16 FEM elements across the radius).

:meth:`StabilityStudy.check` (called by :func:`run_stability` unless ``check=False``) raises
:class:`StabilityFailure` listing every wrong outcome.
"""

from __future__ import annotations

import logging
import math
import time
from collections import Counter
from dataclasses import asdict, dataclass, field

import numpy as np

from ..compare import pair_metrics
from . import fmt
from . import markdown_table
from . import write_json
from . import write_text
from .problems import stability_cases

__all__ = ["StabilityRow", "StabilityStudy", "StabilityFailure", "run_stability", "classify", "main",
           "METHOD_TOL", "FEM_TOL", "STATUSES"]

log = logging.getLogger(__name__)

STATUSES = ("converged", "reported failure", "wrong")
#: agreement required of a method with Newton on the same lattice
METHOD_TOL = 1e-6
#: agreement required between the FEM and the BEM (or Hertz)
FEM_TOL = 0.05
#: errors a solver may raise to report a failure (anything else is a bug and propagates)
_REPORTED = (ValueError, ArithmeticError, RuntimeError)


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
        BEM: :func:`bem.kkt.kkt_residual` of the returned state; FEM: final relative Newton
        residual; ``None`` when the solver raised.
    error_vs_reference : float or None
        ``max(l2_rel, |peak_rel|)`` against ``reference``.
    reference : str
        What the result was compared with (``"-"`` for nothing).
    tolerance : float or None
        The tolerance of that comparison.
    iterations : int
    wall_time_s : float
    message : str
        The solver's message (and why the status was given).
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
        bad = self.wrong()
        if bad:
            raise StabilityFailure(bad, self)
        return self

    def counts(self):
        """``{method: {status: count}}`` over all cases."""
        out = {}
        for r in self.rows:
            out.setdefault(f"{r.solver} {r.method}", Counter())[r.status] += 1
        return {k: {s: v.get(s, 0) for s in STATUSES} for k, v in out.items()}

    def table_markdown(self):
        """Markdown table of all rows."""
        head = ["case", "solver", "method", "status", "KKT residual", "error vs reference", "reference",
                "iterations", "wall time [s]", "message"]
        body = [[r.case, r.solver, r.method, r.status, fmt(r.kkt_residual, ".1e"), fmt(r.error_vs_reference),
                 r.reference, r.iterations, fmt(r.wall_time_s, ".3g"), _short(r.message)] for r in self.rows]
        return markdown_table(head, body)

    def markdown(self):
        """The study as markdown: a per-method summary, then the full table."""
        summary = markdown_table(["solver / method"] + list(STATUSES),
                                 [[k] + [v[s] for s in STATUSES] for k, v in self.counts().items()])
        return "\n".join([
            "## Stability on stiff and extreme cases", "",
            f"Tolerances: paper methods and QP against Newton on the same lattice {METHOD_TOL:g}; FEM against "
            f"Hertz or BEM Newton {FEM_TOL:g}; Newton against the case's closed form at the case's tolerance.",
            "", summary, "", self.table_markdown(), ""])

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


def _finite(result):
    """Whether every pressure and scalar of a BEM or FEM result is finite."""
    values = [result.p_max, result.force, result.approach]
    return bool(np.all(np.isfinite(result.p)) and all(math.isfinite(float(v)) for v in values))


def classify(result, *, converged, error, tolerance):
    """Status of one outcome (module docstring) and the reason.

    Parameters
    ----------
    result : bem.ContactResult or fem_reference.FemResult or None
        ``None`` when the solver raised (a reported failure).
    converged : bool
        The solver's verdict.
    error : float or None
        Error against the reference (``None``: no reference).
    tolerance : float or None
        Allowed error.

    Returns
    -------
    (str, str)
        Status and a short reason.
    """
    if result is None:
        return "reported failure", "raised"
    if not _finite(result) or (error is not None and not math.isfinite(error)):
        return "wrong", "NaN or inf in the result"
    if not converged:
        return "reported failure", "not converged"
    if error is not None and error > tolerance:
        return "wrong", f"called converged but off the reference by {error:.2e} > {tolerance:.1e}"
    return "converged", "agrees with the reference" if error is not None else "no reference: KKT only"


def _error(result, reference):
    m = pair_metrics(result, reference)
    if m["l2_rel"] is None or m["peak_rel"] is None:
        return math.inf
    return max(m["l2_rel"], abs(m["peak_rel"]))


def _attempt(fn):
    """``(result, seconds, exception message or "")``."""
    t0 = time.perf_counter()
    try:
        return fn(), time.perf_counter() - t0, ""
    except _REPORTED as exc:  # a solver that refuses with a message has reported its failure
        return None, time.perf_counter() - t0, f"raised {type(exc).__name__}: {exc}"


def _row(case, solver, method, outcome, reference):
    """Build a row from ``(result, seconds, raised)`` and ``(name, object, tol)`` or ``None``."""
    result, seconds, raised = outcome
    ref_name, ref, tol = reference if reference is not None else ("-", None, None)
    if result is None:
        return StabilityRow(case.name, solver, method, "reported failure", None, None, ref_name, tol, 0, seconds,
                            raised)
    is_fem = solver == "fem"
    finite = _finite(result)
    error = _error(result, ref) if (ref is not None and finite) else None
    status, why = classify(result, converged=bool(result.converged), error=error, tolerance=tol)
    kkt = result.residual if is_fem else result.kkt_residual
    message = result.message if is_fem else result.message
    return StabilityRow(case.name, solver, method, status, float(kkt) if math.isfinite(kkt) else None, error,
                        ref_name, tol, int(result.iterations), seconds, f"{why}; {message}")


def _good(outcome):
    result = outcome[0]
    return result is not None and bool(result.converged) and _finite(result)


def _run_case(case):
    rows = []
    newton = _attempt(lambda: case.run_bem("newton"))
    fem = _attempt(case.run_fem) if case.fem else None
    analytic = case.reference_solution()
    closed = None if analytic is None else (f"{case.analytic} limit" if case.layer is not None else "Hertz",
                                            analytic, case.analytic_tol)
    if closed is not None:
        newton_ref = closed
    elif fem is not None and _good(fem):
        newton_ref = ("FEM", fem[0], FEM_TOL)
    else:
        newton_ref = None
    rows.append(_row(case, "bem", "newton", newton, newton_ref))
    same = ("Newton, same lattice", newton[0], METHOD_TOL) if _good(newton) else closed
    for method in case.methods:
        if method != "newton":
            rows.append(_row(case, "bem", method, _attempt(lambda m=method: case.run_bem(m)), same))
    if fem is not None:
        if case.layer is None and case.analytic == "hertz":
            fem_ref = ("Hertz", analytic, FEM_TOL)
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
    cases : list of Problem, optional
        Default :func:`validation.studies.problems.stability_cases` (``quick``: the subset).
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
                                     "fem_tol": FEM_TOL, "cases": [c.name for c in cases]})
    for case in tqdm(cases, desc="stability", unit="case", disable=not progress):
        study.rows += _run_case(case)
    if check:
        study.check()
    return study


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
    study = run_stability(quick=bool(getattr(args, "quick", False)), check=False, progress=True)
    study.to_json(out / "stability.json")
    text = study.markdown()
    write_text(out / "stability.md", text)
    print(text)
    study.check()
    return 0
