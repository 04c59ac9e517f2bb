"""Element sizes of the FEM meshes: gmsh size fields around the contact, a coating and a contact edge."""

from __future__ import annotations

import math

from bem.checks import check_int, check_positive, fail

__all__ = ["N_ACROSS_COATING", "size_field", "check_edge"]

#: Elements across a coating's thickness in the fine zone (at least).
N_ACROSS_COATING = 4


def _threshold(fld, distance, size, h_coarse, radius, growth):
    """Size ``size`` where the field ``distance`` is below ``radius``, growing with slope ``growth``."""
    thr = fld.add("Threshold")
    fld.setNumber(thr, "InField", distance)
    fld.setNumber(thr, "SizeMin", size)
    fld.setNumber(thr, "SizeMax", h_coarse)
    fld.setNumber(thr, "DistMin", radius)
    fld.setNumber(thr, "DistMax", radius + max(h_coarse - size, 0.0) / growth)
    return thr


def size_field(gmsh, origin, h_fine, h_coarse, fine_radius, growth, coatings=(), a_est=None, across=N_ACROSS_COATING,
               edge=None):
    """Size ``h_fine`` within ``fine_radius`` of the origin, growing linearly (slope ``growth``).

    ``coatings``: ``(z_low, z_high, t)`` per coating strip. Each caps the size at ``t`` along the
    whole strip and at ``t / across`` in its part within ``fine_radius`` (both growing
    with the same slope outside), the smallest size applying. A bond deeper than ``a_est`` gets sizes
    ``h_fine t / a_est`` within ``fine_radius t / a_est`` of its point on the axis. ``edge = (r_e, k)``:
    sizes ``h_fine / k`` within ``h_fine`` of the interface point ``(r_e, 0)``.
    """
    fld = gmsh.model.mesh.field
    dist = fld.add("Distance")
    fld.setNumbers(dist, "PointsList", [origin])
    fields = [_threshold(fld, dist, h_fine, h_coarse, fine_radius, growth)]
    if edge is not None:
        ring = fld.add("MathEval")
        fld.setString(ring, "F", f"Sqrt((x - {float(edge[0])!r})^2 + y^2)")
        fields.append(_threshold(fld, ring, h_fine / edge[1], h_coarse, h_fine, growth))
    for z_low, z_high, t in coatings:
        if t > a_est:  # a deep bond: sizes h_fine t / a_est within fine_radius t / a_est of its axis point
            bond = fld.add("MathEval")
            fld.setString(bond, "F", f"Sqrt(x^2 + (y - ({z_low if z_low < 0 else z_high!r}))^2)")
            fields.append(_threshold(fld, bond, h_fine * t / a_est, h_coarse, fine_radius * t / a_est, growth))
        boxes = [(math.inf, t)]
        if t / across < h_fine:
            boxes.append((fine_radius, t / across))
        for x_max, size in boxes:
            box = fld.add("Box")
            fld.setNumber(box, "VIn", size)
            fld.setNumber(box, "VOut", h_coarse)
            fld.setNumber(box, "XMin", -1.0)
            fld.setNumber(box, "XMax", min(x_max, 1e300))
            fld.setNumber(box, "YMin", z_low)
            fld.setNumber(box, "YMax", z_high)
            fld.setNumber(box, "ZMin", -1.0)
            fld.setNumber(box, "ZMax", 1.0)
            fld.setNumber(box, "Thickness", max(h_coarse - size, 0.0) / growth)
            fields.append(box)
    smallest = fld.add("Min")
    fld.setNumbers(smallest, "FieldsList", fields)
    fld.setAsBackgroundMesh(smallest)


def check_edge(edge, fine):
    """``edge = (r_e, k)`` of :func:`fem_reference.build_mesh` with ``fine = fine_radius a_est``, checked."""
    if not (isinstance(edge, (tuple, list)) and len(edge) == 2):
        fail("edge", edge, "a pair (r_e, k): the edge radius [length] and the refinement factor")
    r_e = check_positive("edge[0]", edge[0])
    if r_e >= fine:
        fail("edge[0]", r_e, f"inside the fine zone, below fine_radius * a_est = {fine!r}")
    return r_e, check_int("edge[1]", edge[1], minimum=2)
