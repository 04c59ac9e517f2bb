"""Make the :class:`validation.run.record.RunResult` of a scene run (the content of ``result.json``).

Every field and its unit: docs/results.md. The scalars at the top level are the BEM's (the
product); ``converged`` is true only when every part that ran converged; the parts that did
not run are ``None``. Units are those of the scene (``units``). ``provenance`` records what
made the result (:mod:`validation.provenance`).
"""

from __future__ import annotations

import math
from dataclasses import fields

import numpy as np

from ..compare import RADIUS_KEYS
from ..provenance import provenance
from .parts import (SCHEMA, BemPart, ClosedForm, Comparison, FemMesh, FemPart, FemProfile, ForceBalance,
                    PairMetrics, Scales, StressPart)
from .record import RunResult

__all__ = ["build_result", "bem_part", "unit_symbols", "axial_profile", "SCHEMA"]


def axial_profile(res):
    """Pressure along the x axis (lattice row ``y = 0``) and along the y axis (interpolated at x = 0).

    Returns
    -------
    dict
        ``{"x": [...], "p": [...], "closure": [...]}`` on the nodes of the row ``y = 0``, and
        ``"y_axis": {"y": [...], "p": [...]}`` at the row ordinates.
    """
    lat = res.lattice
    row = lat.half_rows  # lattice row j = 0
    x = lat.x[row]
    p = res.grid()[row]
    closure = res.grid(res.closure)[row]
    y = lat.y[:, 0]
    p_y = res.pressure(np.zeros_like(y), y)
    return {"x": x, "p": p, "closure": closure, "y_axis": {"y": y, "p": p_y}}


def unit_symbols(units):
    """``{"length", "pressure", "force"}`` symbols of :class:`validation.units.Units` (``None``: not known)."""
    return {"length": units.length, "pressure": units.pressure, "force": units.force}


def _history(res):
    """Per-iteration scalar lists of the BEM history and its finite scalars (iterates left out)."""
    out = {}
    for key, values in (res.history or {}).items():
        if isinstance(values, (int, float, np.integer, np.floating)) and math.isfinite(values):
            out[key] = values.item() if isinstance(values, np.generic) else values
            continue
        if key == "p" or not isinstance(values, (list, tuple, np.ndarray)):
            continue
        arr = np.asarray(values)
        if arr.ndim == 1 and arr.dtype.kind in "biuf":
            out[key] = arr.tolist()
    return out


def _analytic_summary(kind, ref, lattice):
    """Scalars of the closed-form reference (:mod:`bem.reference`, shared names), and its pressure
    along the x and y axes over the candidate region (801 points each), which the reports draw."""
    elliptic = kind == "hertz_elliptic"
    out = {"kind": kind, "force": ref.force, "approach": ref.approach, "p_max": ref.p_max,
           "contact_area": ref.contact_area, "contact_radius": None if elliptic else ref.contact_radius,
           "a": ref.a if elliptic else None, "b": ref.b if elliptic else None}
    x = np.linspace(lattice.x.min(), lattice.x.max(), 801)
    y = np.linspace(lattice.y.min(), lattice.y.max(), 801)
    out["profile"] = {"x": x, "p": ref.pressure(x, 0.0), "y": y, "p_y": ref.pressure(0.0, y)}
    return out


def _scales(scene):
    """Hertz's peak, radius and approach of the gap's paraboloid (no layer): Fig. 5's scale."""
    if scene.gap.type_name != "paraboloid":
        return None
    from bem.reference import hertz_sphere

    hz = hertz_sphere(scene.gap.R, scene.E_star, **scene.load)
    return {"p_hertz": hz.p_max, "a_hertz": hz.contact_radius, "approach_hertz": hz.approach, "force_hertz": hz.force}


def _pair(metrics):
    """:class:`PairMetrics` of :func:`validation.compare.pair_metrics`, which gives one of the radius
    comparisons (:data:`validation.compare.RADIUS_KEYS`); the other is ``None``."""
    if metrics is None:
        return None
    return PairMetrics(**({key: None for key in RADIUS_KEYS} | metrics))


def _comparison(metrics):
    if metrics is None:
        return None
    balance = metrics.get("force_balance")
    return Comparison(bem_vs_fem=_pair(metrics.get("bem_vs_fem")),
                      bem_vs_analytic=_pair(metrics.get("bem_vs_analytic")),
                      fem_vs_analytic=_pair(metrics.get("fem_vs_analytic")),
                      force_balance=None if balance is None else ForceBalance(
                          target=balance["target"], bem=balance["bem"], fem=balance.get("fem")))


def _fem_part(fem):
    """:class:`FemPart` of a :class:`fem_reference.FemResult` (its interpolated edge: ``edge_radius``)."""
    mesh = fem.mesh
    return FemPart(p_max=float(fem.p_max), force=float(fem.force), approach=float(fem.approach),
                   edge_radius=float(fem.edge_radius), converged=bool(fem.converged), status=fem.status,
                   message=fem.message, iterations=int(fem.iterations), n_dofs=int(fem.n_dofs),
                   n_elements=int(fem.n_elements), n_elements_across_contact=float(fem.n_elements_across_contact),
                   timings={k: float(v) for k, v in fem.timings.items()}, penalty=dict(fem.penalty),
                   truncation=dict(fem.truncation),
                   mesh=FemMesh(a_est=mesh["a_est"], h_fine=mesh["h_fine"], n_contact_elements=mesh["n_contact_elements"],
                                domain_factor=mesh["domain_factor"], remeshed=mesh["remeshed"], edge=mesh["edge"]))


def bem_part(res, **extra):
    """:class:`BemPart` of a BEM result: its :meth:`summary` with ``extra`` (``E_star``, the lattice)."""
    names = {f.name for f in fields(BemPart)}
    data = {"contact_radius": None, **res.summary(), **extra, "history": _history(res)}
    return BemPart(**{k: v for k, v in data.items() if k in names})


def build_result(scene, res, layer_info, *, domain_parts, fem=None, analytic=None, metrics=None, times, messages,
                 stress=None):
    """The :class:`validation.run.record.RunResult` of a run (see the module docstring), JSON-ready.

    ``domain_parts``: the parts its domain makes (``parts(res)`` of :class:`validation.run.region.Region`
    or :class:`validation.run.periodic.Cell`): the domain's fields of the ``bem`` part, ``contact_extent``,
    ``profile`` and ``periodic``. ``stress``: the ``stress`` block
    (:func:`validation.run.stress.stress_summary`) of a scene with ``[stress]``.
    """
    from ..io import to_jsonable

    converged = bool(res.converged) and (fem is None or bool(fem.converged))
    own = dict(domain_parts)
    bem = bem_part(res, E_star=scene.E_star, **own.pop("bem"))
    contact_extent = own.pop("contact_extent")
    parts = {
        "bem": bem,
        "fem": None if fem is None else _fem_part(fem),
        "fem_profile": None if fem is None else FemProfile(r=fem.r, p=fem.p),
        "analytic": None if analytic is None else ClosedForm(
            **_analytic_summary(scene.analytic["kind"], analytic, res.lattice)),
        "comparison": _comparison(metrics),
        "scales": None if (scales := _scales(scene)) is None else Scales(**scales),
        "profile": own["profile"],
        "stress": None if stress is None else StressPart.from_json(to_jsonable(stress), where="stress",
                                                                     source="the run"),
        "periodic": own["periodic"],
    }
    parts = {k: None if v is None else type(v).from_json(v.to_json(), where=k, source="the run")
             for k, v in parts.items()}  # JSON-ready values: a result equals itself read back
    top = to_jsonable({
        "scene": scene.name, "title": scene.title, "units": scene.units.label,
        "unit_symbols": unit_symbols(scene.units), "source": scene.source,
        "overrides": list(scene.overrides), "method": res.method,
        "p_max": res.p_max, "force": res.force, "approach": res.approach, "contact_area": res.contact_area,
        "contact_radius": res.contact_radius if scene.axisymmetric else None,
        "contact_extent": contact_extent,
        "iterations": res.iterations, "converged": converged, "kkt_residual": res.kkt_residual,
        "message": res.message, "messages": list(messages), "wall_time_s_by_part": dict(times),
        "layer": layer_info, "alpha_b": layer_info.get("alpha_b"), "report": scene.report,
        "provenance": provenance(),
    })
    return RunResult(**top, **parts)
