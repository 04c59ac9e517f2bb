"""A coated body in a scene's ``[stress]``: bem.coated_stress in the run, result.json, stress_field.vtu, the report,
the command line and the refusals that remain."""

import math

import numpy as np
import pytest
import tomli_w

import bem
from validation.run import execute_scene, write_outputs
from validation.run.record import RunResult
from validation.scene import SceneError, parse_scene
from validation.scene.load import read_toml
from validation.scene.source import builtin_path

from .conftest import cli

#: a coating twice as stiff as the steel below it, about a sixth of the contact radius thick
COATING = {"thickness": 4e-5, "E": 4.5e11, "nu": 0.25}


def _raw(coating=COATING, stress=None, nodes=10, **bodies):
    """The built-in Hertz scene (steel on steel, 100 N) without its closed form and FEM, body 1 coated."""
    raw = read_toml(builtin_path("hertz"))
    for section in ("analytic", "fem", "report"):
        raw.pop(section, None)
    raw["bem"]["nodes_across"] = nodes
    raw["bodies"].update(bodies)
    if coating is not None:
        raw["bodies"]["coating1"] = dict(coating)
    raw["stress"] = stress or {"depths": "auto", "n_depths": 8}
    return raw


def _von_mises(s):
    """sqrt(3 J2) of Voigt tensors (xx, yy, zz, yz, xz, xy), written out here."""
    xx, yy, zz, yz, xz, xy = np.moveaxis(np.asarray(s), -1, 0)
    return np.sqrt(0.5 * ((xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2) + 3 * (yz**2 + xz**2 + xy**2))


@pytest.fixture(scope="module")
def coated_run(tmp_path_factory):
    raw = _raw(stress={"depths": "auto", "n_depths": 6})
    raw["report"] = {"sections": ["stress"]}
    outcome = execute_scene(raw)
    out = tmp_path_factory.mktemp("coated_stress") / "run"
    write_outputs(outcome, out)
    return outcome, out, RunResult.read(out / "result.json")


@pytest.fixture(scope="module")
def direct(coated_run):
    """bem.coated_stress called on the run's solution at the depths result.json records: an independent call."""
    outcome, _, result = coated_run
    return bem.coated_stress(outcome.bem, np.asarray(result.stress.depths), body=1)


def test_result_json_holds_what_bem_coated_stress_gives_on_the_same_result(coated_run, direct):
    outcome, _, result = coated_run
    block, t = result.stress, COATING["thickness"]
    depths = np.asarray(block.depths)
    # "auto": the interface, and at least three depths inside the coating and three below it
    assert t in depths and np.count_nonzero((depths > 0) & (depths < t)) >= 3 and np.count_nonzero(depths > t) >= 3
    c = result.stress.bodies["body1"].coated
    assert c.thickness == t
    for name in ("max_von_mises_coating", "max_von_mises_substrate"):
        assert getattr(c, name) == pytest.approx(getattr(direct, name), rel=1e-12), name
    assert c.location_of_max_coating == pytest.approx(list(direct.location_of_max_coating), abs=1e-15)
    assert c.location_of_max_substrate == pytest.approx(list(direct.location_of_max_substrate), abs=1e-15)
    assert c.location_of_max_coating[2] <= t <= c.location_of_max_substrate[2]
    tr = direct.interface_traction("coating")
    for value, where, field in ((c.interface_min_sigma_zz, c.location_of_interface_min_sigma_zz, tr["zz"].min()),
                                (c.interface_max_sigma_zz, c.location_of_interface_max_sigma_zz, tr["zz"].max()),
                                (c.interface_max_shear, c.location_of_interface_max_shear, tr["shear"].max())):
        assert value == pytest.approx(field, rel=1e-12)
        k = direct.nearest(*where)  # the location is the node of that value, in its own field
        assert [direct.x[k], direct.y[k]] == pytest.approx(where, abs=1e-15)
    k_min, k_max, k_shear = (direct.nearest(*w) for w in (c.location_of_interface_min_sigma_zz,
                                                          c.location_of_interface_max_sigma_zz,
                                                          c.location_of_interface_max_shear))
    assert (tr["zz"][k_min], tr["zz"][k_max], tr["shear"][k_shear]) == pytest.approx(
        (c.interface_min_sigma_zz, c.interface_max_sigma_zz, c.interface_max_shear), rel=1e-12)
    assert c.interface_min_sigma_zz < 0 < c.interface_max_shear  # compression and shear across the bond
    # the body's maxima cover both materials; body 2 (uncoated) keeps bem.subsurface_stress
    body1, body2 = result.stress.bodies["body1"], result.stress.bodies["body2"]
    # the body's maximum is the larger material's (here at a sampled depth, so no parabola moves it: measured equal)
    assert body1.max_von_mises == pytest.approx(max(c.max_von_mises_coating, c.max_von_mises_substrate), rel=1e-12)
    assert body1.nu == 0.3 and body2.coated is None
    plain = bem.subsurface_stress(outcome.bem, depths, nu=0.3, body=2)
    assert body2.max_von_mises == pytest.approx(plain.max_von_mises, rel=1e-12)
    assert body2.location_of_max == pytest.approx(list(plain.location_of_max), abs=1e-15)


def test_the_interface_in_result_json_is_the_traction_from_both_sides(coated_run, direct):
    _, _, result = coated_run
    iface = result.stress.bodies["body1"].coated.interface
    k = np.array([direct.nearest(x, iface["y"]) for x in iface["x"]])
    assert len(k) > 10 and np.all(np.diff(iface["x"]) > 0)  # a section along x
    for side in ("coating", "substrate"):
        tr = direct.interface_traction(side)
        scale = np.abs(tr["zz"]).max()
        np.testing.assert_allclose(iface["sigma_zz"], tr["zz"][k], rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(iface["shear"], tr["shear"][k], rtol=0, atol=1e-12 * scale)
    vm_c, vm_s = _von_mises(direct.interface_coating[k]), _von_mises(direct.interface_substrate[k])
    np.testing.assert_allclose(iface["von_mises_coating"], vm_c, rtol=1e-12)
    np.testing.assert_allclose(iface["von_mises_substrate"], vm_s, rtol=1e-12)
    assert np.max(np.abs(vm_c - vm_s)) > 0.05 * np.max(vm_c)  # the in-plane stresses jump at the bond
    # the axis profile holds the interface twice: the coating's side, then the substrate's
    axis = result.stress.bodies["body1"].axis
    at = np.flatnonzero(np.asarray(axis["z"]) == COATING["thickness"])
    n = direct.nearest(0.0, 0.0)
    assert at.size == 2 and np.allclose(np.asarray(axis["von_mises"])[at],
                                        [_von_mises(direct.interface_coating[n]),
                                         _von_mises(direct.interface_substrate[n])], rtol=1e-12)


def test_equal_coating_and_substrate_give_the_homogeneous_scene():
    """A coating of the substrate's own material: the stresses of the uncoated scene, to round-off."""
    stress = {"depths": [0.0, 2e-5, 4e-5, 8e-5, 1.6e-4]}
    same = execute_scene(_raw({"thickness": 2e-5, "E": 210e9, "nu": 0.3}, stress=stress, nodes=8)).result.stress
    bare = execute_scene(_raw(None, stress=stress, nodes=8)).result.stress
    for name in ("body1", "body2"):
        s, b = same.bodies[name], bare.bodies[name]
        for key in ("max_von_mises", "depth_of_max"):
            assert getattr(s, key) == pytest.approx(getattr(b, key), rel=1e-10), (name, key)
        # the maximum shear on the axis, where two principal stresses coincide, comes from an arccos near 1
        # (bem.stress.principal_stresses): a round-off of the tensor moves it by about sqrt(1e-16) (measured 9e-10)
        for key in ("max_tresca", "depth_of_max_tresca"):
            assert getattr(s, key) == pytest.approx(getattr(b, key), rel=1e-7), (name, key)
        assert s.location_of_max == pytest.approx(b.location_of_max, rel=1e-10, abs=1e-15)
        keep = np.r_[True, np.diff(s.section["z"]) != 0]  # the interface's second (substrate) row dropped
        scale = np.max(b.section["von_mises"])
        np.testing.assert_allclose(np.asarray(s.section["von_mises"])[keep], b.section["von_mises"], rtol=0,
                                   atol=1e-10 * scale)
        np.testing.assert_allclose(np.asarray(s.axis["sigma_zz"])[keep], b.axis["sigma_zz"], rtol=0,
                                   atol=1e-10 * scale)
        np.testing.assert_allclose(np.asarray(s.axis["sigma_xx"])[keep], b.axis["sigma_xx"], rtol=0,
                                   atol=1e-10 * scale)
    c = same.bodies["body1"].coated
    z, vm = np.asarray(bare.bodies["body1"].section["z"]), np.asarray(bare.bodies["body1"].section["von_mises"])
    assert c.interface_min_sigma_zz < 0 and c.max_von_mises_coating <= vm[z <= 2e-5].max() * (1 + 1e-10)


def test_stress_field_file_holds_the_coating_and_the_substrate_apart(coated_run):
    import meshio

    from bem.files import volume_grid

    outcome, out, _ = coated_run
    mesh = meshio.read(out / "stress_field.vtu")
    direct = outcome.stress.coated["body1"]
    t = COATING["thickness"]
    layers = direct.layers()[0]
    _, _, nodes = volume_grid(outcome.bem.lattice, layers.size, 2)
    flat = nodes.ravel()
    hexa = mesh.cells_dict["hexahedron"]
    body, coating = mesh.cell_data_dict["body"]["hexahedron"], mesh.cell_data_dict["coating"]["hexahedron"]
    z = mesh.points[hexa][..., 2].astype(float)
    assert set(np.unique(coating[body == 0])) == {0, 1} and not coating[body == 1].any()
    inside = (body == 0) & (coating == 1)
    assert np.all(z[inside] <= t * (1 + 1e-6)) and np.all(z[(body == 0) & (coating == 0)] >= t * (1 - 1e-6))
    # the interface's points twice, each block with its own side's von Mises stress
    at = np.flatnonzero(np.abs(mesh.points[:, 2] - t) <= 1e-6 * t)
    assert at.size == 2 * flat.size
    vm = mesh.point_data["von_mises"][at]
    np.testing.assert_allclose(vm[:flat.size], _von_mises(direct.interface_coating[flat]), rtol=1e-6)
    np.testing.assert_allclose(vm[flat.size:], _von_mises(direct.interface_substrate[flat]), rtol=1e-6)


def test_report_shows_the_coated_stresses(coated_run, tmp_path):
    from validation.report import report_results_dir

    _, out, result = coated_run
    report_results_dir(out, tmp_path / "report")
    md = (tmp_path / "report" / "report.md").read_text()
    section = md[md.index("## Subsurface stresses"):]
    assert "largest von Mises stress in the substrate" in section and "interface: largest shear traction" in section
    for name in ("stress_section.png", "stress_profiles.png", "stress_interface.png"):
        assert name in section and (tmp_path / "report" / "figures" / name).is_file()
    c = result.stress.bodies["body1"].coated
    assert f"| {c.interface_max_shear / 1e6:.4g} |" in section  # MPa, four digits (the report's pressure unit)


def test_the_command_line_runs_a_coated_scene_with_stress(tmp_path):
    path = tmp_path / "coated.toml"
    path.write_text(tomli_w.dumps(_raw(nodes=8)))
    code, out, err = cli("run", path, "--out", tmp_path / "run", "--set", "stress.n_depths=4",
                         "--set", "stress.bodies=[\"body1\"]")
    assert code == 0, err
    result = RunResult.read(tmp_path / "run" / "result.json")
    assert list(result.stress.bodies) == ["body1"] and result.stress.bodies["body1"].coated.thickness == 4e-5
    c = result.stress.bodies["body1"].coated
    assert f"shear up to {c.interface_max_shear:.6g} Pa" in out and "coating max von Mises" in out


def test_a_rigid_substrate_has_stresses_in_its_coating_only(tmp_path):
    raw = _raw(nodes=8, stress={"depths": "auto", "n_depths": 4, "bodies": ["body1"]}, E1=math.inf)
    outcome = execute_scene(raw)
    write_outputs(outcome, tmp_path / "run")
    body = outcome.result.stress.bodies["body1"]
    assert max(body.axis["z"]) == COATING["thickness"] and body.coated.max_von_mises_substrate is None
    assert body.coated.interface["von_mises_substrate"] is None and (tmp_path / "run" / "stress_field.vtu").is_file()
    raw["stress"] = {"depths": [0.0, 1e-5, 1e-4], "bodies": ["body1"]}
    with pytest.raises(SceneError, match=r"stress.depths\[2\] = 0.0001 is not allowed with bodies.E1 = inf and "
                                         r"bodies.coating1: .* at most the coating thickness "
                                         r"bodies.coating1.thickness = 4e-05"):
        parse_scene(raw)


def test_a_periodic_cell_still_refuses_stress_naming_the_key():
    raw = read_toml(builtin_path("rough_flat"))
    raw["gap"].update(grid=32)
    raw["bem"]["cell_nodes"] = 32
    raw["bodies"] = {"E1": 210e9, "nu1": 0.3, "E2": 210e9, "nu2": 0.3, "coating1": dict(COATING)}
    raw["stress"] = {"depths": "auto"}
    with pytest.raises(SceneError, match=r"stress = \{\.\.\.\} is not allowed with bem.periodic = true"):
        parse_scene(raw)
