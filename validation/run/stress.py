"""Subsurface stresses of a scene run (the ``[stress]`` section) and their check against the FEM.

:func:`run_stress` evaluates :func:`bem.subsurface_stress` for the bodies the scene names
(``body1``: ``E1, nu1``, the upper body; ``body2``: ``E2, nu2``, the lower one) at the scene's
depths (``"auto"``: ``n_depths`` equal steps from the surface down to ``max_depth`` contact
half-widths), and :func:`bem.coated_stress` for a coated one (:mod:`validation.run.stress_coated`:
its interface, from both sides, among the depths); :func:`stress_summary` turns the result into
the ``stress`` block of ``result.json`` (maxima, their depths and locations, the profile on the
axis and the x-z section through the axis for the report; a coated body's maxima per material
and interface tractions), and, when the FEM reference ran, the same maxima of an uncoated body
are taken from its recovered nodal stresses (:func:`fem_body_stresses`) and compared
(:func:`compare_with_fem`).

Depth of a maximum, FEM against BEM: the von Mises stress is flat around its maximum (it
changes by about 1.6 % over +-0.1 a for Hertz), so the depth of the largest nodal value of the
FEM moves with the node-to-node scatter of the recovered stresses. Both depths are therefore
taken the same way, on the axis: a least-squares parabola through the axis values within 4 %
of the largest one (:func:`peak_fit`), the BEM evaluated at the FEM's axis nodes. Where the
largest value lies off the axis (a flat punch: under its edge) only the values are compared
with the body's maximum; the depths are those of the axis maximum.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

import bem
from bem.stress import principal_stresses

from .stress_coated import coated_block, coated_body_stress, coated_layers, interface_depths

__all__ = ["BODIES", "StressRun", "run_stress", "stress_summary", "fem_body_stresses", "peak_fit",
           "compare_with_fem", "contact_half_width"]

#: body name (upper, lower) -> its Poisson-ratio key in [bodies]
BODIES = {"body1": "nu1", "body2": "nu2"}
_SECTION_POINTS = 400  # at most this many x positions of the x-z section kept in result.json
_BAND = 0.04


@dataclass
class StressRun:
    """The stresses of one run: one :class:`bem.SubsurfaceStress` per body, on the candidate nodes.

    Attributes
    ----------
    bodies : dict
        ``name -> SubsurfaceStress``.
    depths : ndarray
        Depths [length], increasing.
    scale : float
        Contact half-width the ``"auto"`` depths were set from [length].
    fem : dict
        ``name -> comparison`` (:func:`compare_with_fem`) when the FEM ran (uncoated bodies).
    wall_time_s : float
    coated : dict
        ``name -> bem.CoatedStress`` of the coated bodies (:mod:`validation.run.stress_coated`); their
        ``bodies`` entry holds its rows with the interface from both sides.
    notes : list of str
        Messages for the run (a coated body not compared with the FEM).
    """

    bodies: dict
    depths: np.ndarray
    scale: float
    fem: dict = field(default_factory=dict)
    wall_time_s: float = 0.0
    coated: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)


def contact_half_width(res):
    """Smaller half-width of the loaded region [length] (the contact radius when axisymmetric)."""
    loaded = res.p > 0
    if not loaded.any():
        return 0.0
    extent = min(float(np.abs(res.x[loaded]).max()), float(np.abs(res.y[loaded]).max()))
    return max(min(extent, res.contact_radius), res.step)


def run_stress(scene, res, fem=None):
    """Stresses of the scene's bodies under the BEM pressure ``res``; compared with ``fem`` when given."""
    t0 = time.perf_counter()
    spec = scene.stress
    scale = contact_half_width(res)
    layers = coated_layers(scene)
    if spec["depths"] == "auto":
        depths = interface_depths(np.linspace(0.0, spec["max_depth"] * scale, spec["n_depths"]), layers)
    else:
        depths = np.unique(np.asarray(spec["depths"], dtype=float))
    bodies, coated = {}, {}
    for name in spec["bodies"]:
        body = int(name.removeprefix("body"))
        if name in layers:
            thickness, rigid = layers[name]
            bodies[name], coated[name] = coated_body_stress(res, depths, body, rigid=rigid, thickness=thickness)
        else:
            bodies[name] = bem.subsurface_stress(res, depths, nu=scene.materials[BODIES[name]], body=body)
    run = StressRun(bodies=bodies, depths=depths, scale=scale, coated=coated)
    if fem is not None and set(bodies) - set(coated):
        fem_stresses = fem_body_stresses(fem)
        run.fem = {name: compare_with_fem(res, st, fem_stresses[name]) for name, st in bodies.items()
                   if name not in coated}
    if fem is not None:
        run.notes += [f"stress: {name} is coated; its stresses are not compared with the FEM's, whose nodal "
                      "recovery averages them across the coating/substrate interface." for name in coated]
    run.wall_time_s = time.perf_counter() - t0
    return run


def fem_body_stresses(fem):
    """Recovered nodal stresses of each FEM body by name (:func:`fem_reference.fields.body_stresses`)."""
    from fem_reference.fields import body_stresses

    return dict(zip(BODIES, body_stresses(fem.model, fem.displacement_dofs)))


def peak_fit(depth, values, band=_BAND):
    """``(value, depth)`` of a least-squares parabola through the samples within ``band`` of the largest.

    Falls back to the largest sample when fewer than three samples lie in the band or the
    parabola does not open downwards.
    """
    depth, values = np.asarray(depth, dtype=float), np.asarray(values, dtype=float)
    k = int(np.argmax(values))
    near = values >= (1.0 - band) * values[k]
    if near.sum() >= 3:
        c2, c1, c0 = np.polyfit(depth[near], values[near], 2)
        if c2 < 0:
            top = -c1 / (2.0 * c2)
            if depth[near].min() <= top <= depth[near].max():
                return float(c0 + top * (c1 + top * c2)), float(top)
    return float(values[k]), float(depth[k])


def compare_with_fem(res, st, fem_body):
    """Maxima of one body, BEM against FEM.

    Values: the largest BEM von Mises stress and maximum shear (all nodes, all depths) and the
    largest FEM nodal values. Depths: of the maximum of von Mises on the axis, by :func:`peak_fit`
    of the axis profiles, the BEM evaluated at the FEM's axis nodes (module docstring); that is
    the depth of the largest value where ``on_axis`` (the BEM's largest value lies within one
    lattice step of the axis), else that of the axis only.
    """
    on_axis = (fem_body["r"] <= 1e-12 * max(1.0, float(fem_body["r"].max()))) & (fem_body["depth"] >= 0)
    order = np.argsort(fem_body["depth"][on_axis])
    depth = fem_body["depth"][on_axis][order]
    vm_fem = fem_body["von_mises"][on_axis][order]
    top = depth[int(np.argmax(vm_fem))]
    window = (depth >= 0.25 * top) & (depth <= 2.0 * top)
    depth, vm_fem = depth[window], vm_fem[window]
    axis = bem.subsurface_stress(res, depth, nu=st.nu, x=[0.0], y=[0.0])
    fit_fem, fit_bem = peak_fit(depth, vm_fem), peak_fit(depth, axis.von_mises[:, 0])
    out = {
        "max_von_mises": float(fem_body["von_mises"].max()),
        "max_tresca": float(fem_body["max_shear"].max()),
        "on_axis": bool(math.hypot(*st.location_of_max[:2]) <= res.step),
        "axis_depth_of_max": fit_fem[1],
        "bem_axis_depth_of_max": fit_bem[1],
        "axis": {"z": depth, "von_mises": vm_fem},
    }
    out["max_von_mises_rel"] = st.max_von_mises / out["max_von_mises"] - 1.0
    out["max_tresca_rel"] = st.max_tresca / out["max_tresca"] - 1.0
    out["axis_depth_of_max_rel"] = fit_bem[1] / fit_fem[1] - 1.0
    return out


def _thin(index, limit):
    """At most ``limit`` of ``index``, evenly spread, the middle one kept."""
    if index.size <= limit:
        return index
    step = math.ceil(index.size / limit)
    mid = index.size // 2
    return index[mid % step::step]


def stress_summary(run):
    """The ``stress`` block of ``result.json``: per body the maxima, the axis profile and the x-z section."""
    out = {"depths": run.depths, "scale": run.scale, "wall_time_s": run.wall_time_s, "bodies": {}}
    for name, st in run.bodies.items():
        n = st.nearest(0.0, 0.0)
        row = _thin(st.section(0.0), _SECTION_POINTS)
        body = dict(st.summary())
        principal = principal_stresses(st.sigma[:, n])
        body["axis"] = {"x": float(st.x[n]), "y": float(st.y[n]), "z": st.z, "von_mises": st.von_mises[:, n],
                        "tresca": 0.5 * (principal[:, 0] - principal[:, 2]), "sigma_zz": st.sigma[:, n, 2],
                        "sigma_xx": st.sigma[:, n, 0]}
        body["section"] = {"x": st.x[row], "y": float(st.y[row[0]]), "z": st.z, "von_mises": st.von_mises[:, row]}
        body["fem"] = run.fem.get(name)  # None: the FEM did not run, or the body is coated
        body["coated"] = coated_block(run.coated[name], row) if name in run.coated else None
        out["bodies"][name] = body
    return out
