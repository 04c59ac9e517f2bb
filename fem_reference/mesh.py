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
import signal
import threading
import time
from dataclasses import dataclass, field

import numpy as np

from bem.checks import InputError, check_int, check_positive

__all__ = ["AxiMesh", "build_mesh", "BOUNDARIES"]

log = logging.getLogger(__name__)

#: skfem boundary name -> (gmsh physical group, body)
BOUNDARIES = {
    "interface_upper": ("interface", "upper"),
    "interface_lower": ("interface", "lower"),
    "axis_upper": ("axis", "upper"),
    "axis_lower": ("axis", "lower"),
    "top": ("top", "upper"),
    "bottom": ("bottom", "lower"),
    "outer_upper": ("outer", "upper"),
    "outer_lower": ("outer", "lower"),
}
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


def _geometry(gmsh, R, H):
    """Two rectangles sharing the interface curve; returns the physical-group entity tags."""
    geo = gmsh.model.geo
    p0, p1 = geo.addPoint(0, 0, 0), geo.addPoint(R, 0, 0)
    p2, p3 = geo.addPoint(R, H, 0), geo.addPoint(0, H, 0)
    p4, p5 = geo.addPoint(R, -H, 0), geo.addPoint(0, -H, 0)
    interface = geo.addLine(p0, p1)
    outer_u, top, axis_u = geo.addLine(p1, p2), geo.addLine(p2, p3), geo.addLine(p3, p0)
    axis_l, bottom, outer_l = geo.addLine(p0, p5), geo.addLine(p5, p4), geo.addLine(p4, p1)
    upper = geo.addPlaneSurface([geo.addCurveLoop([interface, outer_u, top, axis_u])])
    lower = geo.addPlaneSurface([geo.addCurveLoop([axis_l, bottom, outer_l, -interface])])
    geo.synchronize()
    curves = {
        ("interface", "upper"): [interface], ("interface", "lower"): [interface],
        ("axis", "upper"): [axis_u], ("axis", "lower"): [axis_l],
        ("top", "upper"): [top], ("bottom", "lower"): [bottom],
        ("outer", "upper"): [outer_u], ("outer", "lower"): [outer_l],
    }
    groups = {"upper": (2, [upper]), "lower": (2, [lower]), "interface": (1, [interface]),
              "axis": (1, [axis_u, axis_l]), "top": (1, [top]), "bottom": (1, [bottom]),
              "outer": (1, [outer_u, outer_l])}
    for name, (dim, tags) in groups.items():
        gmsh.model.addPhysicalGroup(dim, tags, name=name)
    return p0, {"upper": upper, "lower": lower}, curves, groups


def _size_field(gmsh, origin, h_fine, h_coarse, fine_radius, growth):
    """Size ``h_fine`` within ``fine_radius`` of the origin, growing linearly (slope ``growth``)."""
    fld = gmsh.model.mesh.field
    dist = fld.add("Distance")
    fld.setNumbers(dist, "PointsList", [origin])
    thr = fld.add("Threshold")
    fld.setNumber(thr, "InField", dist)
    fld.setNumber(thr, "SizeMin", h_fine)
    fld.setNumber(thr, "SizeMax", h_coarse)
    fld.setNumber(thr, "DistMin", fine_radius)
    fld.setNumber(thr, "DistMax", fine_radius + (h_coarse - h_fine) / growth)
    fld.setAsBackgroundMesh(thr)


def _extract(gmsh, surfaces, curves):
    """Per-body node/element arrays with the interface nodes duplicated."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    lookup = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    lookup[tags.astype(np.int64)] = np.arange(tags.size)
    xy = coords.reshape(-1, 3)[:, :2].T
    out = {}
    for name in BODIES:
        types, _, node_tags = gmsh.model.mesh.getElements(2, surfaces[name])
        if list(types) != [_TRIANGLE6]:
            raise RuntimeError(f"gmsh produced element types {list(types)} for the {name} body, "
                               "expected 6-node triangles")
        cells = lookup[node_tags[0].astype(np.int64)].reshape(-1, 6)
        corner_ids = np.unique(cells[:, :3])
        all_ids = np.unique(cells)
        out[name] = {"cells": cells, "corner_ids": corner_ids, "all_ids": all_ids}
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

    p_blocks, t_blocks, body, n6_blocks, c6_blocks = [], [], [], [], []
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
    return mesh, body, np.hstack(n6_blocks), np.hstack(c6_blocks)


def _start_gmsh(gmsh):
    """``gmsh.initialize``, keeping the process's ``SIGINT`` and ``SIGTERM`` handlers.

    The gmsh library installs handlers of its own when it starts (its ``SIGTERM`` handler ends the
    process at once, with no clean-up); the Python handlers are put back, the two signals blocked
    meanwhile so that one arriving then reaches them (main thread; another cannot set handlers).
    """
    if threading.current_thread() is not threading.main_thread():
        gmsh.initialize(readConfigFiles=False, interruptible=False)
        return
    signums = {signal.SIGINT, signal.SIGTERM}
    handlers = {signum: signal.getsignal(signum) for signum in signums}
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, signums) if hasattr(signal, "pthread_sigmask") else None
    try:
        gmsh.initialize(readConfigFiles=False, interruptible=False)
    finally:
        for signum, handler in handlers.items():
            if handler is not None:  # None: a handler not installed from Python, left as it is
                signal.signal(signum, handler)
        if blocked is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, blocked)


def build_mesh(a_est, *, n_contact_elements=16, domain_factor=40.0, fine_radius=1.5, growth=0.25, h_coarse=None):
    """Mesh the two bodies with gmsh and convert the mesh to scikit-fem.

    Parameters
    ----------
    a_est : float
        Expected contact radius [length] (see :func:`bem.reference.estimate_contact_radius`).
    n_contact_elements : int
        Elements across ``a_est`` in the contact zone: ``h_fine = a_est / n_contact_elements``.
    domain_factor : float
        Domain width and depth of each body in units of ``a_est``: ``R = H = domain_factor a_est``.
    fine_radius : float
        Radius of the uniformly fine zone in units of ``a_est``.
    growth : float
        Slope ``dh/d(distance)`` of the linear size grading outside the fine zone [-].
    h_coarse : float, optional
        Far-field size [length]; default ``R / 8``.

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
    R = H = domain_factor * a_est
    h_fine = a_est / int(n_contact_elements)
    h_coarse = R / 8.0 if h_coarse is None else check_positive("h_coarse", h_coarse)
    h_coarse = max(h_coarse, h_fine)

    import gmsh

    _start_gmsh(gmsh)
    try:
        _options(gmsh, h_fine, h_coarse)
        gmsh.model.add("contactlab_axisymmetric")
        origin, surfaces, curves, groups = _geometry(gmsh, R, H)
        _size_field(gmsh, origin, h_fine, h_coarse, fine_radius * a_est, growth)
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(2)
        xy, parts = _extract(gmsh, surfaces, curves)
    finally:
        gmsh.finalize()
    mesh, body, nodes6, cells6 = _to_skfem(xy, parts)
    elapsed = time.perf_counter() - t0
    log.info("mesh: %d triangles, h_fine = %.3g, R = H = %.3g (%.2f s)", body.size, h_fine, R, elapsed)
    return AxiMesh(mesh=mesh, body=body, nodes6=nodes6, cells6=cells6, a_est=a_est, h_fine=h_fine,
                   n_contact_elements=int(n_contact_elements), radius=R, depth=H, fine_radius=fine_radius * a_est,
                   h_coarse=h_coarse, mesh_time_s=elapsed,
                   physical_groups={k: v[0] for k, v in groups.items()})
