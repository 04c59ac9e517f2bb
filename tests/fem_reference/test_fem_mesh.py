"""gmsh meshes: matching interface nodes, named groups, quadratic elements, grading."""

import numpy as np
import pytest

from bem.checks import InputError
from fem_reference import build_mesh
from fem_reference.mesh import BOUNDARIES


def _facet_nodes(mesh, name):
    f = mesh.boundaries[name]
    return np.unique(np.concatenate([mesh.facets[:, f].ravel(), mesh.nvertices + f]))


def test_interface_nodes_match_and_are_distinct(coarse_mesh):
    from skfem import Basis, ElementTriP2

    mesh = coarse_mesh.mesh
    x = Basis(mesh, ElementTriP2()).doflocs
    up, lo = _facet_nodes(mesh, "interface_upper"), _facet_nodes(mesh, "interface_lower")
    assert up.size == lo.size > 10
    assert np.intersect1d(up, lo).size == 0  # separate node sets
    ru, rl = np.sort(x[0, up]), np.sort(x[0, lo])
    np.testing.assert_array_equal(ru, rl)  # same 1-D mesh on both sides, exactly
    assert np.all(x[1, up] == 0.0) and np.all(x[1, lo] == 0.0)
    assert ru[0] == 0.0 and ru[-1] == pytest.approx(coarse_mesh.radius)


def test_bodies_and_named_boundaries(coarse_mesh):
    mesh, R, H = coarse_mesh.mesh, coarse_mesh.radius, coarse_mesh.depth
    assert set(BOUNDARIES) <= set(mesh.boundaries)
    assert set(mesh.subdomains) == {"upper", "lower"}
    mid = mesh.p[:, mesh.t].mean(axis=1)
    assert np.all(mid[1, mesh.subdomains["upper"]] > 0) and np.all(mid[1, mesh.subdomains["lower"]] < 0)
    assert mesh.subdomains["upper"].size + mesh.subdomains["lower"].size == mesh.nelements
    where = {"axis_upper": (0, 0.0), "axis_lower": (0, 0.0), "outer_upper": (0, R), "outer_lower": (0, R),
             "top": (1, H), "bottom": (1, -H), "interface_upper": (1, 0.0), "interface_lower": (1, 0.0)}
    for name, (coord, value) in where.items():
        nodes = mesh.facets[:, mesh.boundaries[name]]
        assert nodes.size > 0
        np.testing.assert_allclose(mesh.p[coord, nodes], value, atol=1e-12 * R, err_msg=name)
    # the interface facets of each body belong to elements of that body
    for name, body in (("interface_upper", 0), ("interface_lower", 1)):
        elems = mesh.f2t[0, mesh.boundaries[name]]
        assert np.all(coarse_mesh.body[elems] == body)
    # total area of the two rectangles
    (x0, y0), (x1, y1), (x2, y2) = (mesh.p[:, mesh.t[k]] for k in range(3))
    area = np.sum(0.5 * np.abs((x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)))
    assert area == pytest.approx(2 * R * H, rel=1e-12)


def test_quadratic_elements_from_gmsh(coarse_mesh):
    """gmsh's 6-node triangles: mid-nodes at edge midpoints, the same nodes as skfem's P2."""
    from skfem import Basis, ElementTriP2

    n6, c6 = coarse_mesh.nodes6, coarse_mesh.cells6
    assert c6.shape == (6, coarse_mesh.n_elements)
    for corner_a, corner_b, mid in ((0, 1, 3), (1, 2, 4), (2, 0, 5)):
        np.testing.assert_allclose(n6[:, c6[mid]], 0.5 * (n6[:, c6[corner_a]] + n6[:, c6[corner_b]]),
                                   atol=1e-12 * coarse_mesh.radius)
    x = Basis(coarse_mesh.mesh, ElementTriP2()).doflocs
    assert x.shape[1] == n6.shape[1]
    key = lambda pts: np.round(pts / coarse_mesh.h_fine * 1e6).astype(np.int64)  # noqa: E731
    # same multiset of points (each body has its own interface copy in both)
    a = np.unique(key(x), axis=1, return_counts=True)
    b = np.unique(key(n6), axis=1, return_counts=True)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])


def test_grading_fine_at_contact_coarse_far(coarse_mesh):
    mesh = coarse_mesh.mesh
    L = np.linalg.norm(mesh.p[:, mesh.facets[0]] - mesh.p[:, mesh.facets[1]], axis=0)
    mid = 0.5 * (mesh.p[:, mesh.facets[0]] + mesh.p[:, mesh.facets[1]])
    dist = np.linalg.norm(mid, axis=0)
    near = L[dist < 0.8 * coarse_mesh.a_est]
    far = L[dist > 0.5 * coarse_mesh.radius]
    assert near.max() < 1.6 * coarse_mesh.h_fine and near.mean() > 0.5 * coarse_mesh.h_fine
    assert far.mean() > 10 * coarse_mesh.h_fine
    # interface elements across a_est: about n_contact_elements
    iface = np.sort(np.unique(mesh.p[0, mesh.facets[:, mesh.boundaries["interface_upper"]]]))
    across = np.count_nonzero(iface[1:] <= coarse_mesh.a_est * (1 + 1e-9))
    assert abs(across - coarse_mesh.n_contact_elements) <= 2


def test_mesh_keeps_the_physical_groups_and_writes_no_file(tmp_path, monkeypatch, hertz_same):
    monkeypatch.chdir(tmp_path)
    mesh = build_mesh(hertz_same[0], n_contact_elements=3, domain_factor=20.0)
    assert {"upper", "lower", "interface", "axis", "top", "bottom", "outer"} <= set(mesh.physical_groups)
    assert not list(tmp_path.iterdir())  # fem_reference returns data; writes no files


def test_gmsh_finalized_on_error(monkeypatch):
    import gmsh

    import fem_reference.mesh as mesh_module

    def boom(*args, **kwargs):
        raise RuntimeError("simulated failure")

    monkeypatch.setattr(mesh_module, "_extract", boom)
    with pytest.raises(RuntimeError, match="simulated"):
        build_mesh(1.0, n_contact_elements=3, domain_factor=20.0)
    assert gmsh.isInitialized() == 0


def _interface_facets(amesh):
    mesh = amesh.mesh
    r = mesh.p[0, mesh.facets[:, mesh.boundaries["interface_upper"]]]
    return np.abs(r[1] - r[0]), 0.5 * (r[0] + r[1])


def test_an_edge_band_refines_the_interface_around_the_edge_only(hertz_same):
    """``edge = (r_e, k)``: interface elements within ``h_fine`` of ``r_e`` are ``k`` times smaller; the
    rest of the contact zone keeps ``h_fine``."""
    a = hertz_same[0]
    plain = build_mesh(a, n_contact_elements=8, domain_factor=30.0)
    banded = build_mesh(a, n_contact_elements=8, domain_factor=30.0, edge=(0.93 * a, 4))
    assert banded.edge == (0.93 * a, 4) and plain.edge is None
    h = banded.h_fine
    for amesh, size in ((plain, h), (banded, h / 4)):
        length, mid = _interface_facets(amesh)
        band = np.abs(mid - 0.93 * a) < 0.5 * h
        assert band.sum() >= (1 if amesh is plain else 3)
        assert length[band].max() < 1.3 * size and length[band].min() > 0.6 * size
    length, mid = _interface_facets(banded)
    inner = mid < 0.93 * a - 4 * h  # beyond the band and its grading
    assert inner.any() and length[inner].min() > 0.6 * h


@pytest.mark.parametrize("kwargs, name", [
    ({"a_est": 1.0, "edge": (0.9, 1)}, r"edge\[1\]"), ({"a_est": 1.0, "edge": (2.0, 4)}, r"edge\[0\]"),
    ({"a_est": 1.0, "edge": 0.9}, "edge"), ({"a_est": 1.0, "edge": (-0.5, 4)}, r"edge\[0\]"),
    ({"a_est": 1.0, "n_across_coating": 2}, "n_across_coating"),
    ({"a_est": -1.0}, "a_est"), ({"a_est": 1.0, "n_contact_elements": 1}, "n_contact_elements"),
    ({"a_est": 1.0, "n_contact_elements": 4.5}, "n_contact_elements"),
    ({"a_est": 1.0, "domain_factor": 2.0}, "domain_factor"),
    ({"a_est": float("nan")}, "a_est"), ({"a_est": 1.0, "growth": 0.0}, "growth"),
])
def test_bad_mesh_input(kwargs, name):
    with pytest.raises(InputError, match=name):
        build_mesh(**kwargs)
