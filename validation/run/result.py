"""The result dictionary of a scene run (the content of ``result.json``).

Every field and its unit: docs/results.md. Contract: ``p_max``, ``force``, ``approach``, ``contact_area``,
``contact_radius`` (axisymmetric scenes), ``iterations``, ``converged``, ``kkt_residual``,
``wall_time_s`` per part, and the comparison metrics when a comparison was asked. The scalars
at the top level are the BEM's (the product); ``converged`` is true only when every part that
ran converged. Units are those of the scene (``units``). ``provenance`` records what made the
result (:mod:`validation.provenance`).
"""

from __future__ import annotations

import numpy as np

from ..provenance import provenance

__all__ = ["build_result", "axial_profile", "SCHEMA", "CONTRACT_KEYS"]

SCHEMA = "contactlab.result/1"
#: Keys every result.json holds (contact_radius: axisymmetric scenes only).
CONTRACT_KEYS = ("scene", "units", "method", "p_max", "force", "approach", "contact_area", "iterations",
                 "converged", "kkt_residual", "wall_time_s", "messages")


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


def _history(res):
    """Per-iteration scalar lists of the BEM history (iterates left out)."""
    out = {}
    for key, values in (res.history or {}).items():
        if key == "p" or not isinstance(values, (list, tuple, np.ndarray)):
            continue
        arr = np.asarray(values)
        if arr.ndim == 1 and arr.dtype.kind in "biuf":
            out[key] = arr.tolist()
    return out


def _analytic_summary(kind, ref, lattice):
    """Scalars of the closed-form reference (:mod:`bem.reference`, shared names), and its pressure
    along the x and y axes over the candidate region (801 points each), which the reports draw."""
    out = {"kind": kind, "force": ref.force, "approach": ref.approach, "p_max": ref.p_max,
           "contact_area": ref.contact_area}
    if kind == "hertz_elliptic":
        out.update(a=ref.a, b=ref.b)
    else:
        out["contact_radius"] = ref.contact_radius
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


def build_result(scene, res, layer_info, *, fem=None, analytic=None, metrics=None, times, messages, extent):
    """Assemble the JSON-ready result dict of a run (see the module docstring)."""
    converged = bool(res.converged) and (fem is None or bool(fem.converged))
    bem_part = dict(res.summary(), E_star=scene.E_star, extent=list(extent), n_nodes=int(res.p.size),
                    nodes_across_contact=(2 * res.contact_radius / res.step), history=_history(res))
    out = {
        "schema": SCHEMA,
        "scene": scene.name, "title": scene.title, "units": scene.units.label,
        "unit_symbols": scene.units.as_dict(), "source": scene.source,
        "overrides": list(scene.overrides), "method": res.method,
        "p_max": res.p_max, "force": res.force, "approach": res.approach, "contact_area": res.contact_area,
    }
    if scene.axisymmetric:
        out["contact_radius"] = res.contact_radius
    out.update({
        "contact_extent": {axis: float(np.abs(coord[res.p > 0]).max(initial=0.0))
                           for axis, coord in (("x", res.x), ("y", res.y))},
        "iterations": res.iterations, "converged": converged, "kkt_residual": res.kkt_residual,
        "message": res.message, "messages": list(messages),
        "wall_time_s": dict(times),
        "bem": bem_part, "layer": layer_info,
    })
    if "alpha_b" in layer_info:
        out["alpha_b"] = layer_info["alpha_b"]
    if fem is not None:
        out["fem"] = fem.summary()
        out["fem_profile"] = {"r": fem.r, "p": fem.p}
    if analytic is not None:
        out["analytic"] = _analytic_summary(scene.analytic["kind"], analytic, res.lattice)
    if metrics is not None:
        out["comparison"] = metrics
    scales = _scales(scene)
    if scales is not None:
        out["scales"] = scales
    out["profile"] = axial_profile(res)
    if scene.report is not None:
        out["report"] = scene.report
    out["provenance"] = provenance()
    from ..io import to_jsonable

    return to_jsonable(out)
