"""The ``[stress]`` part of a coated body: :func:`bem.coated_stress` in the scene's run and in ``result.json``.

A coated body (``[bodies] coating1``, ``coating2``) named in ``stress.bodies`` gets the stresses of
:func:`bem.coated_stress` (in its coating, in its substrate and at their interface from both sides);
an uncoated body keeps :func:`bem.subsurface_stress` (:mod:`validation.run.stress`).

Depths ``"auto"`` (:func:`interface_depths`): the homogeneous rule (``n_depths`` equal steps from
the surface down to ``max_depth`` contact half-widths), plus, for each coated body, its interface
depth ``t``, three depths ``t/4, t/2, 3t/4`` in the coating when fewer than three of the equal steps
fall inside it, and three depths ``1.25 t, 1.5 t, 2 t`` in the substrate when fewer than three fall
below ``t``. The interface itself is evaluated from both sides (:meth:`bem.CoatedStress.layers`):
the body's profiles and section hold the depth ``t`` twice, the coating's side first. A rigid
substrate (``E = inf``) has no stresses: that body is evaluated at the depths ``<= t`` only.

The body's maxima over all depths (``max_von_mises``, ``max_tresca`` and their locations) are
found as a homogeneous body's (:func:`bem.stress.peak_in_depth`: the largest sample refined in
depth by a parabola through its neighbours) in each material separately, its side of the
interface included, and the larger kept: no parabola spans the material boundary. The ``coated``
block of ``result.json`` (:func:`coated_block`) adds :func:`bem.coated_stress`'s own maxima per
material (the largest samples) and the interface tractions.
"""

from __future__ import annotations

import math

import numpy as np

import bem
from bem.stress import SubsurfaceStress, peak_in_depth

__all__ = ["coated_layers", "interface_depths", "coated_body_stress", "coated_block"]

#: fewer equal-step depths than this inside the coating (or below it) get the extra depths of the module docstring
_FEW = 3


def coated_layers(scene):
    """``{body name: (thickness [length], rigid substrate)}`` of the coated bodies in the scene's ``stress.bodies``
    (:func:`validation.scene.coatings.coated_stress_bodies`)."""
    from ..scene.coatings import coated_stress_bodies

    return coated_stress_bodies(scene.stress, scene.materials, scene.coatings)


def interface_depths(depths, layers):
    """The ``"auto"`` depths ``depths`` (increasing) with each coated body's interface and the depths around it
    (module docstring); ``depths`` unchanged without a coated body. ``layers``: :func:`coated_layers`."""
    extra = []
    for t, rigid in layers.values():
        extra.append(t)
        if np.count_nonzero((depths > 0) & (depths < t)) < _FEW:
            extra += [0.25 * t, 0.5 * t, 0.75 * t]
        if not rigid and np.count_nonzero(depths > t) < _FEW:
            extra += [1.25 * t, 1.5 * t, 2.0 * t]
    return np.unique(np.concatenate([depths, extra])) if extra else depths


def coated_body_stress(res, depths, body, rigid, thickness):
    """The stresses of coated ``body`` (1 or 2) at ``depths`` [length]: ``(stress, coated)``.

    ``coated`` is the :class:`bem.CoatedStress` of :func:`bem.coated_stress` (depths ``<= thickness`` only when
    the substrate is ``rigid``); ``stress`` a :class:`bem.SubsurfaceStress` of its rows with the interface from
    both sides (:meth:`bem.CoatedStress.layers`), ``nu`` the substrate's, maxima as in the module docstring.
    """
    if rigid:
        depths = depths[depths <= thickness]
    cs = bem.coated_stress(res, depths, body=body)
    z, sigma, vm, inside = cs.layers()

    def peak(field):  # the larger of the two materials' maxima, each refined within its material
        value, depth, n = max((peak_in_depth(field[m], z[m]) for m in (inside, ~inside) if m.any()),
                              key=lambda found: found[0])
        return value, depth, (float(cs.x[n]), float(cs.y[n]), depth)

    vm_max, vm_depth, vm_at = peak(vm)
    stress = SubsurfaceStress(
        x=cs.x, y=cs.y, z=z, sigma=sigma, von_mises=vm, nu=cs.nu_substrate, max_von_mises=vm_max,
        depth_of_max=vm_depth, location_of_max=vm_at, max_tresca=math.nan, depth_of_max_tresca=math.nan,
        location_of_max_tresca=(), on_nodes=cs.on_nodes, wall_time_s=cs.wall_time_s, meta=dict(cs.meta))
    stress.max_tresca, stress.depth_of_max_tresca, stress.location_of_max_tresca = peak(stress.tresca)
    return stress, cs


def _where(cs, n):
    return [float(cs.x[n]), float(cs.y[n])]


def coated_block(cs, row):
    """The ``coated`` object of a coated body in ``result.json``'s ``stress.bodies``: the maxima of von Mises per
    material, the interface tractions' extremes and where, and the interface along the section ``row`` (point
    indices of the x-z section, :meth:`bem.SubsurfaceStress.section`). The tractions are the coating side's
    (:meth:`bem.CoatedStress.interface_traction`; the substrate side's equal them to round-off)."""
    tr = cs.interface_traction("coating")
    k_min, k_max, k_shear = int(np.argmin(tr["zz"])), int(np.argmax(tr["zz"])), int(np.argmax(tr["shear"]))
    z, _, vm, in_coating = cs.layers()
    at = z == cs.coating.thickness
    vm_c = vm[np.flatnonzero(at & in_coating)[0]]
    vm_s = vm[np.flatnonzero(at & ~in_coating)[0]] if cs.interface_substrate is not None else None
    sub = cs.location_of_max_substrate
    return {
        "thickness": cs.coating.thickness,
        "max_von_mises_coating": cs.max_von_mises_coating,
        "location_of_max_coating": [float(v) for v in cs.location_of_max_coating],
        "max_von_mises_substrate": cs.max_von_mises_substrate,
        "location_of_max_substrate": None if sub is None else [float(v) for v in sub],
        "interface_min_sigma_zz": float(tr["zz"][k_min]), "location_of_interface_min_sigma_zz": _where(cs, k_min),
        "interface_max_sigma_zz": float(tr["zz"][k_max]), "location_of_interface_max_sigma_zz": _where(cs, k_max),
        "interface_max_shear": float(tr["shear"][k_shear]), "location_of_interface_max_shear": _where(cs, k_shear),
        "interface": {"x": cs.x[row], "y": float(cs.y[row[0]]), "sigma_zz": tr["zz"][row], "shear": tr["shear"][row],
                      "von_mises_coating": vm_c[row], "von_mises_substrate": None if vm_s is None else vm_s[row]},
    }
