"""Studies over the solvers; every problem is a scene run by :func:`validation.run.execute_scene`.

- :mod:`~validation.studies.problems`: the problems, as scene dicts (docs/scenes.md);
- :mod:`~validation.studies.error_time`: pressure error against wall time over a ladder of
  resolutions for every BEM method and the FEM reference;
- :mod:`~validation.studies.stability`: every method on stiff and extreme cases; a wrong answer
  or a NaN raises ``StabilityFailure``;
- :mod:`~validation.studies.robustness`: the layer methods over 12 decades of layer compliance,
  every converged answer checked against the KKT conditions with the dense influence matrix;
- :mod:`~validation.studies.two_scale`: a fully resolved rough sphere against the smooth sphere
  with the layer law of its roughness and Greenwood-Tripp;
- :mod:`~validation.studies.coating_winkler`: a sphere on a coated flat against the bare substrate
  with a linear Winkler layer (the oedometric one and the best one), over thickness, moduli and
  Poisson's ratio (the axisymmetric ring solutions of :mod:`~validation.studies.coating_rings`);
- :mod:`~validation.studies.coating_fem`: the coated BEM against the FEM reference with the coating
  meshed, both refined, with their observed orders and extrapolated values;
- :mod:`~validation.studies.paper_problem`: the paper's test problem (section 6) on one lattice,
  its cases, sweeps and methods, which the paper report draws (``contactlab report paper``).

The first six are the studies of :data:`STUDIES` (``contactlab study NAME``); each has
``main(out=..., scene=..., quick=..., progress=...)``, which writes the study's JSON file
(``STEM + ".json"``, :data:`STUDY_FILES`) and returns a :class:`StudyRun`, which the report renders
(:mod:`validation.report.documents.studies`).
This module holds what they share: running a scene (:func:`attempt`, :func:`timed`), the status of an
outcome (:func:`classify`) and the files (:func:`save`).
"""

from __future__ import annotations

import json
import math
import statistics
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bem.checks import InputError
from bem.files import write_text

from ..run import execute_scene
from ..scene import load_scene

__all__ = ["StudyRun", "attempt", "timed", "classify", "finite", "save", "write_json", "no_scene", "STATUSES",
           "STUDIES", "STUDY_FILES"]

#: the studies of ``contactlab study NAME``, in the order their reports show them: name -> the module
#: that runs it (its ``main``); the study's file is named after the module (its ``STEM + ".json"``)
STUDIES = {"error-time": "validation.studies.error_time", "stability": "validation.studies.stability",
           "robustness": "validation.studies.robustness", "two-scale": "validation.studies.two_scale",
           "coating-winkler": "validation.studies.coating_winkler", "coating-fem": "validation.studies.coating_fem"}
#: the file each study of :data:`STUDIES` writes, in the same order
STUDY_FILES = tuple(f"{module.rpartition('.')[2]}.json" for module in STUDIES.values())

#: status of an outcome (:func:`classify`)
STATUSES = ("converged", "reported failure", "wrong")
#: errors a run may raise to report a failure (anything else is a bug and propagates)
_REPORTED = (ValueError, ArithmeticError, RuntimeError)


@dataclass
class StudyRun:
    """What a study's ``main`` wrote: ``path`` (``<stem>.json``), ``data`` (its content as written),
    ``status`` (the exit status: 1 if any outcome is wrong) and ``fields`` (nodal fields the study
    kept for its figures, or ``None``)."""

    stem: str
    path: Path
    data: object
    status: int = 0
    fields: object = None


def attempt(scene, overrides=None):
    """Run a scene: ``(RunOutcome or None, wall time [s], "" or "<Error>: <message>")``.

    The scene is validated first (a bad scene is a bug of the study and propagates); an error of
    the run itself (a solver that refuses with a message) is returned as a reported failure.
    """
    scene = load_scene(scene, overrides=overrides)
    t0 = time.perf_counter()
    try:
        return execute_scene(scene), time.perf_counter() - t0, ""
    except _REPORTED as exc:
        return None, time.perf_counter() - t0, f"{type(exc).__name__}: {exc}"


def timed(scene, part="bem", *, overrides=None, repeats=3, slow_s=2.0):
    """Run a scene up to ``repeats`` times: ``(last outcome, median wall time [s], every wall time [s])``.

    The times are the runner's for ``part`` (``"bem"`` or ``"fem"``, meshing included). When the
    first run takes longer than ``slow_s`` [s] or that part did not converge, it is the only one.
    """
    scene = load_scene(scene, overrides=overrides)
    times = []
    for k in range(max(1, repeats)):
        outcome = execute_scene(scene)
        times.append(outcome.result.wall_time_s_by_part[part])
        if k == 0 and (times[0] > slow_s or not getattr(outcome, part).converged):
            break
    return outcome, statistics.median(times), times


def finite(result):
    """Whether every pressure and scalar of a BEM or FEM result is finite."""
    values = (result.p_max, result.force, result.approach)
    return bool(np.all(np.isfinite(result.p)) and all(math.isfinite(float(v)) for v in values))


def classify(result, *, converged, error, tolerance):
    """Status of one outcome and the reason: ``(status, why)``.

    ``"wrong"``: a NaN or inf in ``result`` or ``error``, or ``converged`` with ``error`` above
    ``tolerance``; ``"reported failure"``: no ``result`` (the run raised) or not ``converged``;
    else ``"converged"`` (with ``error`` ``None`` there was no reference to check).
    """
    if result is None:
        return "reported failure", "raised"
    if not finite(result) or (error is not None and not math.isfinite(error)):
        return "wrong", "NaN or inf in the result"
    if not converged:
        return "reported failure", "not converged"
    if error is not None and error > tolerance:
        return "wrong", f"called converged but off the reference by {error:.2e} > {tolerance:.1e}"
    return "converged", "agrees with the reference" if error is not None else "no reference: KKT only"


def write_json(path, data):
    """Write ``data`` as indented JSON, whole or not at all (``NaN``/``inf`` refused: JSON has none)."""
    return write_text(path, json.dumps(data, indent=2, allow_nan=False) + "\n")


def save(out, stem, data, *, status=0, fields=None):
    """Write ``data`` as ``<stem>.json`` into the folder ``out`` (``None``: the current directory), whole
    or not at all; returns the :class:`StudyRun` (its ``data`` read back from the file)."""
    path = write_json(Path(out or ".") / f"{stem}.json", data)
    return StudyRun(stem, path, json.loads(path.read_text(encoding="utf-8")), status, fields)


def no_scene(study, scene):
    """Refuse a ``scene`` for a study that builds its own problems (``None`` passes)."""
    if scene is not None:
        raise InputError(f"scene = {scene!r} is not allowed: the {study} study takes no scene (it builds its own "
                         "problems; --quick chooses the short run).")


