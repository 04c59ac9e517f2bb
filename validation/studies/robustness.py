"""Robustness grid: every layer method over 12 decades of layer compliance, exponents and moduli.

Problem: a paraboloid (``R = 1``) on a flat under force ``P = 1`` (force control) or under the
approach that force gives (approach control), with a power layer ``w = lam p^s``, for ``s`` in
:data:`EXPONENTS` (0.05 .. 10), ``k`` in :data:`COMPLIANCES` (the layer's secant compliance at
the Hertz mean pressure, ``w(p_m) / p_m``, over the elastic compliance of the contact
``a_H^2 / (R p_0)``: from a layer far stiffer than the bodies to one far softer), ``E*`` in
:data:`MODULI` (``1e-3 .. 1e12`` relative to ``P / R^2``), each layer method and both controls,
at :data:`NODES_ACROSS` steps across the expected contact diameter. Each point is a scene
(:func:`validation.studies.problems.robustness_scene`, run by :func:`validation.run.execute_scene`;
the region grows when the contact reaches it).

Status (:func:`validation.studies.classify`): ``"converged"`` when the solver says so and the
KKT residual of eq. 14, recomputed with the dense influence matrix (independently of the FFT
path), is at most ``2 rtol``; ``"reported failure"`` (not converged, with a message, every
value finite); ``"wrong"`` (called converged with a larger dense KKT residual, or a NaN).
"""

from __future__ import annotations

import itertools
import math
from collections import Counter
from dataclasses import asdict, dataclass

import numpy as np

from ..progress import each
from ..scene import load_scene
from ..labels import fmt
from . import attempt, classify, finite, no_scene, save
from .problems import robustness_scene

__all__ = ["RobustnessRow", "run_robustness", "summary_table", "matrix_table", "failure_table",
           "rows_from_json", "main", "STEM", "EXPONENTS", "COMPLIANCES", "MODULI", "LAYER_METHODS", "SETTING"]

#: the study's file is ``STEM + ".json"``, named after this module (:data:`validation.studies.STUDY_FILES`)
STEM = __name__.rpartition(".")[2]

EXPONENTS = (0.05, 0.2, 0.5, 1.0, 2.0, 3.0, 10.0)
COMPLIANCES = (1e-6, 1e-3, 1.0, 1e3, 1e6)
MODULI = (1e-3, 1.0, 1e3, 1e6, 1e12)
LAYER_METHODS = ("newton", "variable_compliance", "augmented_gap")
NODES_ACROSS = 16
RTOL = 1e-10
SETTING = (f"Paraboloid R = 1, P = 1, power layer `w = lam p^s`; {NODES_ACROSS} nodes across the contact; "
           f"rtol = {RTOL:g}; KKT of eq. 14 checked with the dense influence matrix. `k`: the layer's secant "
           "compliance at the Hertz mean pressure over the elastic compliance of the contact; E* relative to P/R^2.")


@dataclass
class RobustnessRow:
    """One method on one grid point; ``kkt_dense`` is the independent check (``None`` if it raised);
    ``solver_status`` the solver's ``status`` (:data:`bem.STATUSES`; ``None`` if it raised)."""

    s: float
    k: float
    E_star: float
    control: str
    method: str
    status: str
    converged: bool
    kkt_dense: float | None
    iterations: int
    wall_time_s: float
    message: str
    solver_status: str | None = None


def _dense_kkt(outcome):
    """KKT residual of eq. 14 of a run's BEM answer, with the dense influence matrix."""
    import bem

    res = outcome.bem
    total = bem.InfluenceOperator(res.lattice, res.E_star).dense() @ res.p + outcome.layer.w(res.p)
    g = total + outcome.scene.gap(res.x, res.y) - res.approach
    return float(bem.kkt.kkt_residual(res.p, g, displacement_scale=float(np.abs(total).max()), force=None,
                                      node_area=res.lattice.node_area))


def _row(point, control, method, run):
    outcome, seconds, raised = run
    if outcome is None:
        return RobustnessRow(*point, control, method, "reported failure", False, None, 0, seconds, raised)
    res = outcome.bem
    kkt = _dense_kkt(outcome) if finite(res) else math.inf
    status, _ = classify(res, converged=res.converged, error=kkt if res.converged else None, tolerance=2 * RTOL)
    return RobustnessRow(*point, control, method, status, bool(res.converged), kkt, int(res.iterations),
                         outcome.result.wall_time_s_by_part["bem"], res.message, res.status)


def run_robustness(*, exponents=EXPONENTS, compliances=COMPLIANCES, moduli=MODULI, methods=LAYER_METHODS,
                   progress=None):
    """Run the grid; returns the list of :class:`RobustnessRow`.

    Every run of a point has the lattice step of its force-controlled scene; approach control
    uses the approach of the force-controlled Newton run (the same discrete problem), or, if that
    failed, the layer-only closed form. ``progress(label, done, total)``: :mod:`validation.progress`.
    """
    from bem.layers import Power
    from bem.reference import rigid_layer_paraboloid

    rows = []
    for point in each(itertools.product(exponents, compliances, moduli), progress,
                      lambda p: "s = {:g}, k = {:g}, E* = {:g}".format(*p)):
        scene = load_scene(robustness_scene(*point, nodes_across=NODES_ACROSS, extent_factor=1.5, rtol=RTOL))
        approach = None
        for control in ("force", "approach"):
            if control == "approach" and approach is None:
                layer = Power(scene.layer_spec["lam"], scene.layer_spec["s"])
                approach = rigid_layer_paraboloid(layer, 1.0, force=1.0).approach
            load = {} if control == "force" else {"load.approach": approach, "bem.step": scene.bem["step"]}
            for method in methods:
                run = attempt(scene, {"bem.method": method, **load})
                rows.append(_row(point, control, method, run))
                if control == "force" and method == "newton" and run[0] is not None and run[0].bem.converged:
                    approach = run[0].bem.approach
    return rows


def summary_table(rows):
    """``(headers, body)``: outcomes, times and the worst dense KKT residual per method and control."""
    groups = {}
    for r in rows:
        groups.setdefault((r.method, r.control), []).append(r)
    body = []
    for (method, control), sel in sorted(groups.items()):
        c = Counter(r.status for r in sel)
        times = [r.wall_time_s for r in sel]
        kkts = [r.kkt_dense for r in sel if r.converged and r.kkt_dense is not None]
        body.append([method, control, c["converged"], c["reported failure"], c["wrong"], fmt(float(np.median(times)),
                     ".3f"), fmt(max(times), ".3f"), fmt(max(kkts), ".1e") if kkts else "-"])
    return (["method", "control", "converged", "reported failure", "wrong", "median time [s]", "max time [s]",
             "worst dense KKT when converged"], body)


def matrix_table(rows, method):
    """``(headers, body)``: converged out of all (E*, control) per exponent ``s`` (rows) and ``k`` (columns)."""
    sel = [r for r in rows if r.method == method]
    ks = sorted({r.k for r in rows})
    body = []
    for s in sorted({r.s for r in sel}):
        cells = [[r.status for r in sel if r.s == s and r.k == k] for k in ks]
        body.append([fmt(s, "g")] + [f"{c.count('converged')}/{len(c)}" + (
            f" ({c.count('wrong')} wrong)" if "wrong" in c else "") for c in cells])
    return ["s \\ k"] + [fmt(k, "g") for k in ks], body


def failure_table(rows):
    """``(headers, body)``: every outcome that is not converged."""
    return (["method", "control", "s", "k", "E*", "status", "dense KKT", "message"],
            [[r.method, r.control, fmt(r.s, "g"), fmt(r.k, "g"), fmt(r.E_star, "g"), r.status, fmt(r.kkt_dense, ".1e"),
              r.message[:110]] for r in rows if r.status != "converged"])


def rows_from_json(data):
    """:class:`RobustnessRow` objects from the content of ``robustness.json``."""
    return [RobustnessRow(**{**d, "kkt_dense": None if d["kkt_dense"] is None else float(d["kkt_dense"])})
            for d in data]


def _json_row(row):
    """The row as a dict; a non-finite KKT residual (an overflowed closure) becomes the string "inf"."""
    out = asdict(row)
    if out["kkt_dense"] is not None and not math.isfinite(out["kkt_dense"]):
        out["kkt_dense"] = str(out["kkt_dense"])
    return out


def main(*, out=None, scene=None, quick=False, progress=None):
    """``contactlab study robustness``: the whole grid, or a small one when ``quick``; writes
    ``robustness.json`` into the folder ``out`` (``None``: the current directory). Returns the
    :class:`~validation.studies.StudyRun`, status 1 if any outcome is wrong, else 0. The study takes
    no ``scene``; ``progress(label, done, total)``: :mod:`validation.progress`."""
    no_scene("robustness", scene)
    quick_grid = dict(exponents=(0.05, 1.0, 10.0), compliances=(1e-6, 1.0, 1e6), moduli=(1e-3, 1e12))
    rows = run_robustness(progress=progress, **(quick_grid if quick else {}))
    return save(out, STEM, [_json_row(r) for r in rows], status=int(any(r.status == "wrong" for r in rows)))
