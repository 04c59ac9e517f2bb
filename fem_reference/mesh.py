"""gmsh meshes of the two axisymmetric bodies in the (r, z) half-plane.

Geometry (lengths in the user's units)::

    z = +H  +------------------+          top      (upper body, "upper")
            |                  |
    axis    |                  |  outer
    r = 0   |                  |  r = R
    z = 0   +==================+          interface (shared 1-D mesh)
            |                  |
            |                  |
    z = -H  +------------------+          bottom   (lower body, "lower")

A body may carry a coating of thickness ``t`` (``coating_thickness``): a line at ``z = +t``
(upper) or ``z = -t`` (lower) splits its rectangle into the coating and the substrate, meshed
conformingly (bonded: the two share the nodes of that line), with at least
``N_ACROSS_COATING`` elements across ``t`` in the fine zone and elements no larger than ``t``
along the whole coating; a bond deeper than the contact is refined near the axis (:func:`fem_reference.sizes.size_field`).
An optional edge band (``edge``) refines the interface around a known contact edge.

Both rectangles are meshed in one gmsh model that shares the interface curve,
so the two sides of the interface get the same 1-D mesh; the nodes on it are
then duplicated (each body gets its own copy), which makes two separate bodies
with MATCHING interface nodes. Elements are quadratic triangles (gmsh order 2,
6 nodes, straight edges: the mid-edge nodes are the edge midpoints), graded
from ``a_est / n_contact_elements`` in the contact zone to coarse far away by a
Distance/Threshold size field around the first point of contact (r, z) = (0, 0).

gmsh physical groups: surfaces ``upper``, ``lower``; curves ``interface``,
``axis``, ``top``, ``bottom``, ``outer``. The scikit-fem mesh carries the same
boundaries split per body (``interface_upper``, ``interface_lower``,
``axis_upper``, ``axis_lower``, ``top``, ``bottom``, ``outer_upper``,
``outer_lower``) and the subdomains ``upper``, ``lower``.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np

from bem.checks import InputError, check_int, check_positive

from .gmsh_session import start_gmsh
from .sizes import N_ACROSS_COATING, check_edge, size_field

__all__ = ["AxiMesh", "build_mesh", "BOUNDARIES"]

log = logging.getLogger(__name__)

#: skfem boundary name -> (gmsh physical group, body)
BOUNDARIES = {"interface_upper": ("interface", "upper"), "interface_lower": ("interface", "lower"),
              "axis_upper": ("axis", "upper"), "axis_lower": ("axis", "lower"), "top": ("top", "upper"),
              "bottom": ("bottom", "lower"), "outer_upper": ("outer", "upper"), "outer_lower": ("outer", "lower")}
BODIES = ("upper", "lower")
_TRIANGLE6 = 9  # gmsh element type: 6-node second-order triangle
_LINE3 = 8  # gmsh element type: 3-node second-order line


@dataclass
class AxiMesh:
    """Mesh of the two bodies (upper ``z >= 0``, lower ``z <= 0``).

    Attributes
    ----------
    mesh : skfem.MeshTri
        Corner-node mesh of both bodies (interface nodes duplicated), with the named
        boundaries of :data:`BOUNDARIES` and subdomains ``upper``, ``lower``; used with
        ``ElementTriP2``, whose mid-edge nodes are gmsh's.
    body : ndarray of int, shape (n_elements,)
        0 for elements of the upper body, 1 for the lower body.
    coated : ndarray of bool, shape (n_elements,)
        True for the elements of a coating.
    nodes6 : ndarray, shape (2, n_nodes6)
        gmsh's nodes (corner and mid-edge) as (r, z), interface nodes once per body.
    cells6 : ndarray of int, shape (6, n_elements)
        gmsh's 6-node triangles (3 corners, then mid-nodes of edges 01, 12, 20) into
        ``nodes6``, in the element order of ``mesh``.
    a_est : float
        Contact radius the sizes were set from [length].
    h_fine : float
        Element size in the contact zone, ``a_est / n_contact_elements`` [length].
    n_contact_elements : int
        Elements across ``a_est``.
    radius, depth : float
        Domain width ``R`` and depth ``H`` of each body [length].
    fine_radius : float
        Radius of the uniformly fine zone around the origin [length].
    h_coarse : float
        Far-field element size [length].
    coating_thickness : tuple
        Coating thickness of the upper and the lower body [length], ``None`` for none.
    n_across_coating : int
        Elements across a coating's thickness in the fine zone (at least).
    edge : tuple or None
        ``(r_e, k)`` of an edge band (:func:`build_mesh`), ``None`` for none.
    mesh_time_s : float
        Wall-clock time of meshing and conversion [s].
    """

    mesh: object
    body: np.ndarray
    nodes6: np.ndarray
    cells6: np.ndarray
    a_est: float
    h_fine: float
    n_contact_elements: int
    radius: float
    depth: float
    fine_radius: float
    h_coarse: float
    coated: np.ndarray = None
    coating_thickness: tuple = (None, None)
    n_across_coating: int = N_ACROSS_COATING
    edge: tuple = None
    mesh_time_s: float = 0.0
    physical_groups: dict = field(default_factory=dict)

    @property
    def n_elements(self):
        """Number of triangles (both bodies)."""
        return int(self.body.size)


def _options(gmsh, h_fine, h_coarse):
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.MeshSizeMin", h_fine)
    gmsh.option.setNumber("Mesh.MeshSizeMax", h_coarse)
    gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay: well-shaped triangles
    gmsh.option.setNumber("Mesh.SecondOrderLinear", 1)  # straight edges: mid-nodes at midpoints
    gmsh.option.setNumber("General.NumThreads", 1)


def _geometry(gmsh, R, H, thickness=(None, None)):
    """Two rectangles sharing the interface curve, each split at its coating's depth.

    Returns the origin's point tag, each body's surfaces (coating first), the curves per
    (group, body) and the physical groups. Without coatings the entities are created in the
    order, and with the orientations, of the plain two-rectangle model.
    """
    geo = gmsh.model.geo
    p0, p1 = geo.addPoint(0, 0, 0), geo.addPoint(R, 0, 0)
    levels, outer_pts, axis_pts = {}, {}, {}
    for name, sign, t in (("upper", 1.0, thickness[0]), ("lower", -1.0, thickness[1])):
        levels[name] = [0.0] + ([t] if t else []) + [H]
        outer_pts[name], axis_pts[name] = [p1], [p0]
        for z in levels[name][1:]:
            outer_pts[name].append(geo.addPoint(R, sign * z, 0))
            axis_pts[name].append(geo.addPoint(0, sign * z, 0))
    interface = geo.addLine(p0, p1)
    lines = {}
    for name in ("upper", "lower"):
        O, A, n = outer_pts[name], axis_pts[name], len(levels[name]) - 1
        if name == "upper":  # outer O_k -> O_k+1, horizontal O_k+1 -> A_k+1, axis A_k+1 -> A_k
            made = [(geo.addLine(O[k], O[k + 1]), geo.addLine(O[k + 1], A[k + 1]), geo.addLine(A[k + 1], A[k]))
                    for k in range(n)]
        else:  # axis A_k -> A_k+1, horizontal A_k+1 -> O_k+1, outer O_k+1 -> O_k
            made = [(geo.addLine(A[k], A[k + 1]), geo.addLine(A[k + 1], O[k + 1]), geo.addLine(O[k + 1], O[k]))
                    for k in range(n)]
            made = [(outer, horizontal, axis) for axis, horizontal, outer in made]
        lines[name] = made
    surfaces = {}
    for name in ("upper", "lower"):
        body, below = [], interface
        for outer, horizontal, axis in lines[name]:
            if name == "upper":  # counter-clockwise: bottom, right, top, left
                loop = [below, outer, horizontal, axis]
                below = -horizontal
            else:  # counter-clockwise: left, bottom, right, top
                loop = [axis, horizontal, outer, -below]
                below = horizontal
            body.append(geo.addPlaneSurface([geo.addCurveLoop(loop)]))
        surfaces[name] = body
    geo.synchronize()
    far = {name: lines[name][-1][1] for name in lines}
    curves = {
        ("interface", "upper"): [interface], ("interface", "lower"): [interface],
        ("axis", "upper"): [m[2] for m in lines["upper"]], ("axis", "lower"): [m[2] for m in lines["lower"]],
        ("top", "upper"): [far["upper"]], ("bottom", "lower"): [far["lower"]],
        ("outer", "upper"): [m[0] for m in lines["upper"]], ("outer", "lower"): [m[0] for m in lines["lower"]],
    }
    groups = {"upper": (2, surfaces["upper"]), "lower": (2, surfaces["lower"]), "interface": (1, [interface]),
              "axis": (1, curves[("axis", "upper")] + curves[("axis", "lower")]),
              "top": (1, [far["upper"]]), "bottom": (1, [far["lower"]]),
              "outer": (1, curves[("outer", "upper")] + curves[("outer", "lower")])}
    for name, (dim, tags) in groups.items():
        gmsh.model.addPhysicalGroup(dim, tags, name=name)
    return p0, surfaces, curves, groups


def _extract(gmsh, surfaces, curves, thickness=(None, None)):
    """Per-body node/element arrays with the interface nodes duplicated."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    lookup = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    lookup[tags.astype(np.int64)] = np.arange(tags.size)
    xy = coords.reshape(-1, 3)[:, :2].T
    out = {}
    for name, t in zip(BODIES, thickness):
        blocks, coated = [], []
        for k, tag in enumerate(surfaces[name]):
            types, _, node_tags = gmsh.model.mesh.getElements(2, tag)
            if list(types) != [_TRIANGLE6]:
                raise RuntimeError(f"gmsh produced element types {list(types)} for the {name} body, "
                                   "expected 6-node triangles")
            blocks.append(lookup[node_tags[0].astype(np.int64)].reshape(-1, 6))
            coated.append(np.full(blocks[-1].shape[0], bool(t) and k == 0))
        cells = np.vstack(blocks)
        corner_ids = np.unique(cells[:, :3])
        all_ids = np.unique(cells)
        out[name] = {"cells": cells, "corner_ids": corner_ids, "all_ids": all_ids, "coated": np.concatenate(coated)}
        edges = {}
        for (group, body), ctags in curves.items():
            if body != name:
                continue
            pairs = []
            for ctag in ctags:
                ctypes, _, cnodes = gmsh.model.mesh.getElements(1, ctag)
                if list(ctypes) != [_LINE3]:
                    raise RuntimeError(f"gmsh produced curve element types {list(ctypes)}, expected 3-node lines")
                pairs.append(lookup[cnodes[0].astype(np.int64)].reshape(-1, 3)[:, :2])
            edges[group] = np.vstack(pairs)
        out[name]["edges"] = edges
    return xy, out


def _facet_ids(mesh, pairs):
    """Facet indices of ``mesh`` for vertex-index pairs (shape (n, 2))."""
    nv = np.int64(mesh.p.shape[1])
    keys = mesh.facets[0].astype(np.int64) * nv + mesh.facets[1]
    order = np.argsort(keys)
    sp = np.sort(pairs, axis=1).astype(np.int64)
    query = sp[:, 0] * nv + sp[:, 1]
    pos = np.searchsorted(keys[order], query)
    pos = np.minimum(pos, keys.size - 1)
    if not np.array_equal(keys[order][pos], query):
        raise RuntimeError("a gmsh boundary edge is not an edge of the triangulation")
    return np.sort(order[pos]).astype(np.int32)


def _to_skfem(xy, parts):
    """Assemble the two bodies into one skfem ``MeshTri`` (disconnected at the interface)."""
    from skfem import MeshTri

    p_blocks, t_blocks, body, n6_blocks, c6_blocks, coated = [], [], [], [], [], []
    v_off = n6_off = 0
    vmaps = {}
    for k, name in enumerate(BODIES):
        part = parts[name]
        vmap = np.full(xy.shape[1], -1, dtype=np.int64)
        vmap[part["corner_ids"]] = v_off + np.arange(part["corner_ids"].size)
        nmap = np.full(xy.shape[1], -1, dtype=np.int64)
        nmap[part["all_ids"]] = n6_off + np.arange(part["all_ids"].size)
        p_blocks.append(xy[:, part["corner_ids"]])
        n6_blocks.append(xy[:, part["all_ids"]])
        t_blocks.append(vmap[part["cells"][:, :3]].T)
        c6_blocks.append(nmap[part["cells"]].T)
        body.append(np.full(part["cells"].shape[0], k, dtype=np.int8))
        coated.append(part["coated"])
        vmaps[name] = vmap
        v_off += part["corner_ids"].size
        n6_off += part["all_ids"].size
    t = np.ascontiguousarray(np.hstack(t_blocks), dtype=np.int32)
    mesh = MeshTri(np.ascontiguousarray(np.hstack(p_blocks)), t)
    # MeshTri sorts the corners of each triangle; cells6 keeps gmsh's own node order
    # (the same triangles, element by element).
    boundaries = {}
    for name, (group, bname) in BOUNDARIES.items():
        pairs = vmaps[bname][parts[bname]["edges"][group]]
        boundaries[name] = _facet_ids(mesh, pairs)
    body = np.concatenate(body)
    mesh = mesh.with_boundaries(boundaries).with_subdomains(
        {name: np.nonzero(body == k)[0].astype(np.int32) for k, name in enumerate(BODIES)}
    )
    return mesh, body, np.hstack(n6_blocks), np.hstack(c6_blocks), np.concatenate(coated)


def _thicknesses(coating_thickness):
    """The two coating thicknesses, checked: ``None`` or finite and ``> 0``."""
    if not isinstance(coating_thickness, (tuple, list)) or len(coating_thickness) != 2:
        raise InputError(f"coating_thickness = {coating_thickness!r} is not allowed: it must be a pair "
                         "(upper, lower) of thicknesses or None.")
    return tuple(None if t is None else check_positive(f"coating_thickness[{k}]", t)
                 for k, t in enumerate(coating_thickness))


def build_mesh(a_est, *, n_contact_elements=16, domain_factor=40.0, fine_radius=1.5, growth=0.25, h_coarse=None,
               coating_thickness=(None, None), n_across_coating=N_ACROSS_COATING, edge=None):
    """Mesh the two bodies with gmsh and convert the mesh to scikit-fem.

    Parameters
    ----------
    a_est : float
        Expected contact radius [length] (see :func:`bem.reference.estimate_contact_radius`).
    n_contact_elements : int
        Elements across ``a_est`` in the contact zone: ``h_fine = a_est / n_contact_elements``.
    domain_factor : float
        Domain width and depth of each body in units of the larger of ``a_est`` and the thickest
        coating: ``R = H = domain_factor max(a_est, t)``.
    fine_radius : float
        Radius of the uniformly fine zone in units of ``a_est``.
    growth : float
        Slope ``dh/d(distance)`` of the linear size grading outside the fine zone [-].
    h_coarse : float, optional
        Far-field size [length]; default ``R / 8``.
    coating_thickness : tuple of (float or None), optional
        Coating thickness of the upper and the lower body [length] (``None``: no coating): the
        body's elements within it form its coating (``AxiMesh.coated``).
    n_across_coating : int
        Elements across a coating's thickness in the fine zone (at least ``N_ACROSS_COATING``).
    edge : tuple of (float, int), optional
        ``(r_e, k)``: sizes ``h_fine / k`` within ``h_fine`` of the interface point ``(r_e, 0)``
        (a contact edge at radius ``r_e`` [length], ``0 < r_e < fine_radius a_est``; ``k >= 2``).

    Returns
    -------
    AxiMesh
    """
    t0 = time.perf_counter()
    a_est = check_positive("a_est", a_est)
    n_contact_elements = check_int("n_contact_elements", n_contact_elements, minimum=2)
    domain_factor = check_positive("domain_factor", domain_factor)
    fine_radius = check_positive("fine_radius", fine_radius)
    growth = check_positive("growth", growth)
    if domain_factor < 4.0 * fine_radius:
        raise InputError(f"domain_factor = {domain_factor!r} is not allowed: it must be >= 4 * fine_radius = "
                         f"{4 * fine_radius!r}.")
    thickness = _thicknesses(coating_thickness)
    across = check_int("n_across_coating", n_across_coating, minimum=N_ACROSS_COATING)
    if edge is not None:
        edge = check_edge(edge, fine_radius * a_est)
    R = H = domain_factor * max([a_est] + [t for t in thickness if t])
    h_fine = a_est / int(n_contact_elements)
    h_coarse = R / 8.0 if h_coarse is None else check_positive("h_coarse", h_coarse)
    h_coarse = max(h_coarse, h_fine)

    import gmsh

    start_gmsh(gmsh)
    try:
        _options(gmsh, min([h_fine / (edge[1] if edge else 1)] + [t / across for t in thickness if t]), h_coarse)
        gmsh.model.add("contactlab_axisymmetric")
        origin, surfaces, curves, groups = _geometry(gmsh, R, H, thickness)
        strips = [(0.0, t, t) if k == 0 else (-t, 0.0, t) for k, t in enumerate(thickness) if t]
        size_field(gmsh, origin, h_fine, h_coarse, fine_radius * a_est, growth, strips, a_est, across, edge)
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(2)
        xy, parts = _extract(gmsh, surfaces, curves, thickness)
    finally:
        gmsh.finalize()
    mesh, body, nodes6, cells6, coated = _to_skfem(xy, parts)
    elapsed = time.perf_counter() - t0
    log.info("mesh: %d triangles, h_fine = %.3g, R = H = %.3g (%.2f s)", body.size, h_fine, R, elapsed)
    return AxiMesh(mesh=mesh, body=body, nodes6=nodes6, cells6=cells6, a_est=a_est, h_fine=h_fine,
                   n_contact_elements=int(n_contact_elements), radius=R, depth=H, fine_radius=fine_radius * a_est,
                   h_coarse=h_coarse, coated=coated, coating_thickness=thickness, n_across_coating=across,
                   edge=edge, mesh_time_s=elapsed,
                   physical_groups={k: v[0] for k, v in groups.items()})
