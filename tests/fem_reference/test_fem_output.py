"""Result file, failure reporting, input validation, inputs left untouched."""

import re

import numpy as np
import pytest
from .fem_cases import E, NU, P

import fem_reference as fr
from bem.checks import InputError
from bem.files import write_vtu
from bem.layers import Linear, Root


@pytest.fixture(scope="module")
def result(gap, coarse_mesh):
    return fr.solve(gap, E1=E, nu1=NU, E2=E, nu2=NU, force=P, mesh=coarse_mesh)


def test_vtu_readable_with_expected_fields(result, tmp_path):
    import meshio

    path = tmp_path / "field.vtu"
    assert write_vtu(path, **result.field()) == path
    m = meshio.read(path)
    assert [c.type for c in m.cells] == ["triangle6"]
    assert m.cells[0].data.shape == (result.n_elements, 6)
    assert m.points.shape == (result.n_dofs // 2, 3)
    names = {"displacement", "sigma_rr", "sigma_zz", "sigma_tt", "sigma_rz", "von_mises", "contact_pressure"}
    assert names <= set(m.point_data)
    assert m.point_data["displacement"].shape == (m.points.shape[0], 3)
    np.testing.assert_array_equal(np.unique(m.cell_data["body"][0]), [0, 1])
    for values in m.point_data.values():
        assert np.all(np.isfinite(values))
    # contact traction equals -sigma_zz at the interface centre (projected stress, coarse mesh)
    centre = np.nonzero((np.abs(m.points[:, 0]) < 1e-12) & (np.abs(m.points[:, 1]) < 1e-12))[0]
    assert centre.size == 2
    np.testing.assert_allclose(-m.point_data["sigma_zz"][centre], result.p_max, rtol=0.05)
    np.testing.assert_allclose(m.point_data["contact_pressure"][centre], result.p[0])
    # the top moved down by the far-boundary approach
    top = m.points[:, 1] == m.points[:, 1].max()
    np.testing.assert_allclose(m.point_data["displacement"][top, 1], -result.truncation["approach_far"], rtol=1e-12)
    # same materials: the lower body mirrors the upper one about z = 0, with the top moved down by
    # approach_far and the bottom held, so u_z(r, z) + u_z(r, -z) = -approach_far, u_r and the normal
    # stresses are even in z, sigma_rz is odd; compared at the nodes whose mirror image is a node
    _assert_mirror_symmetric(m, result.truncation["approach_far"], scale=result.p_max)
    assert [p.name for p in tmp_path.iterdir()] == ["field.vtu"]  # no temporary file left


def _assert_mirror_symmetric(m, approach_far, *, scale):
    key = {(round(r, 9), round(z, 9)): i for i, (r, z) in enumerate(m.points[:, :2] / m.points[:, 0].max())}
    pairs = np.array([(i, key[(r, -z)]) for (r, z), i in key.items() if z > 0 and (r, -z) in key])
    up, lo = pairs.T
    assert np.count_nonzero(m.points[up, 0] > 0) >= 20 and np.count_nonzero(m.points[up, 0] == 0) >= 20
    u, d = m.point_data["displacement"], m.point_data
    np.testing.assert_allclose(u[up, 1] + u[lo, 1], -approach_far, rtol=0, atol=1e-3 * approach_far)
    np.testing.assert_allclose(u[up, 0], u[lo, 0], rtol=0, atol=1e-3 * np.abs(u[:, 0]).max())
    for name in ("sigma_rr", "sigma_zz", "sigma_tt", "von_mises"):
        np.testing.assert_allclose(d[name][up], d[name][lo], rtol=0, atol=1e-2 * scale, err_msg=name)
    np.testing.assert_allclose(d["sigma_rz"][up], -d["sigma_rz"][lo], rtol=0, atol=1e-2 * scale)


def test_solve_writes_no_file_and_the_field_is_written_whole_or_not_at_all(gap, coarse_mesh, tmp_path,
                                                                             monkeypatch):
    import meshio

    monkeypatch.chdir(tmp_path)
    res = fr.solve(gap, E1=E, nu1=NU, E2=E, nu2=NU, force=P, mesh=coarse_mesh)
    assert res.converged and not list(tmp_path.iterdir())  # fem_reference returns data; writes no files
    path = write_vtu(tmp_path / "solve.vtu", **res.field())

    def broken(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(meshio, "write", broken)
    target = tmp_path / "never.vtu"
    with pytest.raises(OSError, match="disk full"):
        write_vtu(target, **res.field())
    assert not target.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]


def test_not_converged_says_so_without_nan(gap, coarse_mesh):
    res = fr.solve(gap, E1=E, nu1=NU, E2=E, nu2=NU, force=P, mesh=coarse_mesh, layer=Root(1e-3),
                   maxiter=1, rtol=1e-14)
    assert res.converged is False and res.status == "maxiter"
    for value in (res.p, res.overlap, [res.approach, res.force, res.p_max, res.edge_radius]):
        assert np.all(np.isfinite(value))


def test_inputs_not_modified(gap, coarse_mesh):
    layer = Linear(2e-6)
    before = {k: getattr(coarse_mesh, k).copy() for k in ("body", "nodes6", "cells6")}
    p_before, t_before = coarse_mesh.mesh.p.copy(), coarse_mesh.mesh.t.copy()
    fr.solve(gap, E1=E, nu1=NU, E2=E, nu2=NU, force=P, mesh=coarse_mesh, layer=layer)
    for k, v in before.items():
        np.testing.assert_array_equal(getattr(coarse_mesh, k), v)
    np.testing.assert_array_equal(coarse_mesh.mesh.p, p_before)
    np.testing.assert_array_equal(coarse_mesh.mesh.t, t_before)
    assert layer.lam == 2e-6


#: (arguments replaced, the name and the value the message shows): every argument of solve
BAD = [
    ({"E1": -1.0}, "E1", -1.0), ({"nu2": 0.5}, "nu2", 0.5), ({"nu1": -1.0}, "nu1", -1.0),
    ({"force": -5.0}, "force", -5.0), ({"force": None}, "(force, approach)", (None, None)),
    ({"approach": 0.01}, "(force, approach)", (P, 0.01)), ({"layer": "linear"}, "layer", "linear"),
    ({"penalty": 0.0}, "penalty", 0.0), ({"rtol": -1e-9}, "rtol", -1e-9), ({"rtol": 10.0}, "rtol", 10.0),
    ({"maxiter": 0}, "maxiter", 0),
    ({"maxiter": 2.0}, "maxiter", 2.0), ({"a_est": -1.0}, "a_est", -1.0), ({"n_contact_elements": 1}, "n_contact_elements", 1),
    ({"n_contact_elements": 4.5}, "n_contact_elements", 4.5), ({"domain_factor": -1.0}, "domain_factor", -1.0),
    ({"fine_radius": 0.0}, "fine_radius", 0.0), ({"growth": float("nan")}, "growth", float("nan")),
    ({"truncation_correction": "yes"}, "truncation_correction", "yes"), ({"remesh": 1}, "remesh", 1),
    ({"mesh": "coarse"}, "mesh", "coarse"),
]


@pytest.mark.parametrize("kwargs, name, value", BAD, ids=[f"{b[1]}={b[2]!r}" for b in BAD])
def test_bad_input_names_the_argument(gap, kwargs, name, value):
    """The form of bem.checks: "name = value is not allowed: rule"."""
    args = dict(E1=E, nu1=NU, E2=E, nu2=NU, force=P)
    args.update(kwargs)
    with pytest.raises(InputError, match="^" + re.escape(f"{name} = {value!r} is not allowed: it must be ")):
        fr.solve(gap, **args)


def test_bad_gap():
    with pytest.raises(InputError, match=r"^gap = 'sphere' is not allowed: it must be callable\.$"):
        fr.solve("sphere", E1=E, nu1=NU, E2=E, nu2=NU, force=P)
    kw = dict(E1=E, nu1=NU, E2=E, nu2=NU, force=P, a_est=0.2, n_contact_elements=3, domain_factor=20.0)
    with pytest.raises(InputError, match=r"^gap\(x, y\) = nan at \(x, y\) = \(0, 0\) is not allowed: the gap "
                                         r"must be finite on the interface\.$"):
        fr.solve(lambda x, y: np.full_like(x, np.nan), **kw)
    with pytest.raises(InputError, match=r"^gap returned shape \(\) which is not allowed: it must return the "
                                         r"shape of x \(\(\d+,\)\)\.$"):
        fr.solve(lambda x, y: 0.0, **kw)


def test_vtu_is_compressed_with_ordinary_permissions(result, tmp_path):
    """The one writer (bem.files.write_vtu): zlib-compressed VTK XML, read here by an independent
    decoder of the format; the file gets the permissions of any new file (umask), not 0600."""
    import os
    import stat

    from bem.files import file_mode

    from ..vtu_reader import read_vtu

    path = write_vtu(tmp_path / "f.vtu", **result.field())
    assert stat.S_IMODE(os.stat(path).st_mode) == file_mode()
    points, (conn, offsets, types), point_data, cell_data, attrs = read_vtu(path)
    assert attrs["compressor"] == "vtkZLibDataCompressor"
    assert set(types) == {22} and types.size == result.n_elements  # VTK_QUADRATIC_TRIANGLE
    np.testing.assert_array_equal(offsets, 6 * np.arange(1, result.n_elements + 1))
    assert points.shape == (result.n_dofs // 2, 3)
    assert point_data["displacement"].shape == (points.shape[0], 3)
    np.testing.assert_array_equal(np.unique(cell_data["body"]), [0, 1])
    centre = np.nonzero((np.abs(points[:, 0]) < 1e-12) & (np.abs(points[:, 1]) < 1e-12))[0]
    np.testing.assert_allclose(point_data["contact_pressure"][centre], result.p[0])


def test_vtk_reader_opens_the_file(result, tmp_path):
    """What ParaView's reader sees, decoded by the VTK XML format's rules (tests/vtu_reader.py):
    quadratic triangles (VTK cell type 22) and the fields, one value per point."""
    from ..vtu_reader import read_vtu

    path = write_vtu(tmp_path / "paraview.vtu", **result.field())
    points, (_, offsets, types), point_data, _, attrs = read_vtu(path)
    assert attrs["type"] == "UnstructuredGrid" and attrs["compressor"] == "vtkZLibDataCompressor"
    n_points, n_cells = points.shape[0], types.size
    assert n_cells == result.n_elements
    assert set(np.unique(types)) == {22}  # VTK_QUADRATIC_TRIANGLE
    assert np.array_equal(offsets, 6 * np.arange(1, n_cells + 1))
    for name in ("von_mises", "sigma_tt"):
        assert point_data[name].size == n_points
    assert point_data["displacement"].shape == (n_points, 3)