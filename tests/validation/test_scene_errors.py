"""Bad scene files are refused before any work, with a message that names the dotted key.

Each case is a complete TOML file written as a string; the loader must raise SceneError
(a ValueError) naming the key, and ``contactlab check`` must exit with code 2 and print it.
"""

import pytest

import bem
from validation.scene import SceneError, load_scene

from .conftest import cli

BODIES = """
[bodies]
E1 = 210e9
nu1 = 0.3
E2 = 210e9
nu2 = 0.3
"""
BASE = """
[scene]
name = "t"
""" + BODIES + """
[gap]
type = "paraboloid"
R = 0.01

[load]
force = 100.0

[bem]
nodes_across = 16
"""
LAYER_BASE = BASE + """
[layer]
"""
PAPER_ER = BASE + """
[layer]
law = "elastic_rigid"
lam_over_cnn = 10.0
cnn_step = 1e-5
alpha_a = 0.5
"""
ELLIPTIC = BASE.replace('type = "paraboloid"\nR = 0.01', 'type = "elliptic_paraboloid"\nRx = 0.02\nRy = 0.005')
TABLE_GAP = """
[scene]
name = "t"
""" + BODIES + """
[gap]
type = "table"
x = [-1e-3, 0.0, 1e-3]
y = [-1e-3, 0.0, 1e-3]
h = [[1e-4, 5e-5, 1e-4], [5e-5, 0.0, 5e-5], [1e-4, 5e-5, 1e-4]]
method = "linear"

[load]
force = 1.0
"""

CASES = {
    "unknown_section": (BASE + "\n[solver]\nmethod = 'x'\n", "solver"),
    "unknown_bodies_key": (BASE.replace("E1 = 210e9", "E1 = 210e9\nYoung = 1e9"), "bodies.Young"),
    "negative_modulus": (BASE.replace("E1 = 210e9", "E1 = -210e9"), "bodies.E1"),
    "nu_above_half": (BASE.replace("nu1 = 0.3", "nu1 = 0.6"), "bodies.nu1"),
    "nu_minus_one": (BASE.replace("nu2 = 0.3", "nu2 = -1.0"), "bodies.nu2"),
    "modulus_is_text": (BASE.replace("E1 = 210e9", 'E1 = "steel"'), "bodies.E1"),
    "missing_nu2": (BASE.replace("nu2 = 0.3\n", ""), "bodies.nu2"),
    "E_star_and_E1": (BASE.replace("E1 = 210e9", "E1 = 210e9\nE_star = 1e11"), "bodies.E_star"),
    "missing_load": (BASE.replace("[load]\nforce = 100.0\n", ""), "[load]"),
    "negative_force": (BASE.replace("force = 100.0", "force = -5.0"), "load.force"),
    "zero_force": (BASE.replace("force = 100.0", "force = 0.0"), "load.force"),
    "force_and_approach": (BASE.replace("force = 100.0", "force = 100.0\napproach = 1e-6"), "load.force"),
    "approach_is_text": (BASE.replace("force = 100.0", 'approach = "big"'), "load.approach"),
    "missing_gap_type": (BASE.replace('type = "paraboloid"\n', ""), "gap.type"),
    "unknown_gap_type": (BASE.replace('"paraboloid"', '"sphere"'), "gap.type"),
    "negative_radius": (BASE.replace("R = 0.01", "R = -0.01"), "gap.R"),
    "unknown_gap_key": (BASE.replace("R = 0.01", "R = 0.01\nradius = 0.01"), "gap.radius"),
    "nan_in_gap_table": (TABLE_GAP.replace("[5e-5, 0.0, 5e-5]", "[5e-5, nan, 5e-5]")
                         + "\n[bem]\nstep = 1e-4\nextent = 5e-4\n", "gap.h"),
    "non_monotone_layer_table": (LAYER_BASE + 'law = "tabulated"\np = [0.0, 1e8, 2e8, 3e8]\n'
                                 "w = [0.0, 2e-7, 1e-7, 3e-7]\n", "layer.w[2]"),
    "unknown_law": (LAYER_BASE + 'law = "magic"\n', "layer.law"),
    "negative_layer_compliance": (LAYER_BASE + 'law = "linear"\nlam = -1e-15\n', "layer.lam"),
    "missing_layer_compliance": (LAYER_BASE + 'law = "linear"\n', "layer.lam"),
    "lam_and_lam_over_cnn": (LAYER_BASE + 'law = "linear"\nlam = 1e-15\nlam_over_cnn = 10.0\n', "layer.lam"),
    "alpha_a_above_one": (PAPER_ER.replace("alpha_a = 0.5", "alpha_a = 1.5"), "layer.alpha_a"),
    "lam_over_cnn_without_its_step": (PAPER_ER.replace("cnn_step = 1e-5\n", ""), "layer.lam_over_cnn"),
    "alpha_c_right_angle": (LAYER_BASE + 'law = "bilinear"\nlam_over_cnn = 10.0\ncnn_step = 1e-5\nalpha_a = 0.5\n'
                            "alpha_c = 1.6\n", "layer.alpha_c"),
    "unknown_layer_key": (LAYER_BASE + 'law = "power"\nlam = 1e-12\ns = 0.5\nt = 2.0\n', "layer.t"),
    "none_law_with_parameters": (LAYER_BASE + 'law = "none"\nlam = 1e-15\n', "layer.lam"),
    "alpha_b_without_lam_over_cnn": (LAYER_BASE + 'law = "root"\nlam = 1e-12\nalpha_b = 0.9\n', "layer.alpha_b"),
    "series_nested_bad_key": (LAYER_BASE + 'law = "series"\n[layer.a]\nlaw = "linear"\nlam = 1e-15\nmu = 1\n'
                              '[layer.b]\nlaw = "root"\nlam = 1e-11\n', "layer.a.mu"),
    "unknown_method": (BASE.replace("nodes_across = 16", 'nodes_across = 16\nmethod = "magic"'), "bem.method"),
    "too_few_nodes_across": (BASE.replace("nodes_across = 16", "nodes_across = 2"), "bem.nodes_across"),
    "fractional_nodes_across": (BASE.replace("nodes_across = 16", "nodes_across = 20.5"), "bem.nodes_across"),
    "step_and_nodes_across": (BASE.replace("nodes_across = 16", "nodes_across = 16\nstep = 1e-5"), "bem.step"),
    "extent_cannot_hold_load": (BASE.replace("nodes_across = 16", "step = 1e-5\nextent = 5e-5"), "bem.extent"),
    "unknown_bem_key": (BASE.replace("nodes_across = 16", "nodes_across = 16\ntolerance = 1e-6"),
                        "bem.tolerance"),
    "negative_rtol": (BASE.replace("nodes_across = 16", "nodes_across = 16\nrtol = -1e-8"), "bem.rtol"),
    "rtol_above_a_percent": (BASE.replace("nodes_across = 16", "nodes_across = 16\nrtol = 10.0"), "bem.rtol = 10.0"),
    "radius_overflowing": (BASE.replace("R = 0.01", "R = 1e308"), "gap.R = 1e+308"),
    "force_overflowing": (BASE.replace("force = 100.0", "force = 1e308"), "load.force = 1e+308"),
    "modulus_overflowing": (BASE.replace("E1 = 210e9", "E1 = 1e308"), "bodies.E1 = 1e+308"),
    "depth_overflowing": (BASE + "\n[stress]\ndepths = [0.0, 1e308]\n",
                          "stress.depths[1] = 1e+308"),
    "extent_of_three": (BASE.replace("nodes_across = 16", "step = 1e-5\nextent = [5e-4, 5e-4, 5e-4]"),
                        "bem.extent"),
    "precondition_is_text": (BASE.replace("nodes_across = 16", 'nodes_across = 16\nprecondition = "yes"'),
                             "bem.precondition"),
    "kalker_with_nonlinear_layer": (BASE.replace("nodes_across = 16", 'nodes_across = 16\nmethod = "kalker"')
                                    + '\n[layer]\nlaw = "root"\nlam = 1e-11\n', "bem.method"),
    "relaxation_with_newton": (BASE.replace("nodes_across = 16", "nodes_across = 16\nrelaxation = 0.5"),
                               "bem.relaxation"),
    "extent_factor_below_one": (BASE.replace("nodes_across = 16", "nodes_across = 16\nextent_factor = 0.5"),
                                "bem.extent_factor"),
    "lattice_too_large": (BASE.replace("nodes_across = 16", "step = 1e-8\nextent = 5e-4"), "bem.step"),
    "table_gap_without_lattice": (TABLE_GAP, "bem.step"),
    "fem_for_elliptic_gap": (ELLIPTIC + "\n[fem]\nn_contact_elements = 8\n", "fem"),
    "fem_with_E_star": (BASE.replace(BODIES, "\n[bodies]\nE_star = 1e11\n") + "\n[fem]\n", "fem"),
    "fem_too_few_elements": (BASE + "\n[fem]\nn_contact_elements = 1\n", "fem.n_contact_elements"),
    "unknown_fem_key": (BASE + "\n[fem]\nmesh_size = 1e-5\n", "fem.mesh_size"),
    "fem_domain_inside_its_fine_zone": (BASE + "\n[fem]\ndomain_factor = 5.0\nfine_radius = 1.5\n",
                                        "fem.domain_factor"),
    "unknown_analytic_kind": (BASE + '\n[analytic]\nkind = "exact"\n', "analytic.kind"),
    "hertz_with_layer": (PAPER_ER + '\n[analytic]\nkind = "hertz"\n', "analytic.kind"),
    "hertz_on_flat_punch": (BASE.replace('type = "paraboloid"\nR = 0.01', 'type = "flat_punch"\na = 1e-4\n'
                                         'edge_radius = 1e-3') + '\n[analytic]\nkind = "hertz"\n', "analytic.kind"),
    "rigid_layer_with_elastic_rigid_law": (PAPER_ER + '\n[analytic]\nkind = "rigid_layer"\n', "analytic.kind"),
    "sweep_unknown_parameter": (BASE + '\n[sweep]\nparameter = "foo"\nvalues = [1.0]\n', "sweep.parameter"),
    "sweep_no_values": (BASE + '\n[sweep]\nparameter = "load.force"\nvalues = []\n', "sweep.values"),
    "sweep_value_out_of_range": (PAPER_ER + '\n[sweep]\nparameter = "alpha_a"\nvalues = [0.5, 2.0]\n',
                                 "layer.alpha_a"),
    "report_unknown_section": (BASE + '\n[report]\nsections = ["nonsense"]\n', "report.sections[0]"),
    "missing_scene_name": (BASE.replace('name = "t"\n', 'title = "x"\n'), "scene.name"),
    "scene_name_with_slash": (BASE.replace('name = "t"', 'name = "a/b"'), "scene.name"),
    "roller_region_beyond_length": ("""
[scene]
name = "r"
""" + BODIES + """
[gap]
type = "crowned_roller"
length = 0.01
R = 0.004
crown = "none"

[load]
force = 1000.0

[bem]
step = 2e-5
extent = [0.006, 0.0005]
""", "bem.extent"),
}


def _write(tmp_path, text):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_scene_is_refused_naming_the_key(tmp_path, case, monkeypatch):
    text, key = CASES[case]

    def no_work(*a, **k):  # validation must refuse the scene before any solve
        raise AssertionError("a solver ran before the scene was validated")

    monkeypatch.setattr(bem, "solve", no_work)
    with pytest.raises(SceneError) as info:
        load_scene(_write(tmp_path, text))
    assert key in str(info.value)
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize("case", sorted(CASES))
def test_cli_check_exits_2_naming_the_key(tmp_path, case):
    text, key = CASES[case]
    code, out, err = cli("check", _write(tmp_path, text))
    assert code == 2
    assert key in err
    assert out == ""


def test_there_are_at_least_30_cases():
    assert len(CASES) >= 30


def test_message_shows_value_and_rule(tmp_path):
    with pytest.raises(SceneError) as info:
        load_scene(_write(tmp_path, CASES["nu_above_half"][0]))
    msg = str(info.value)
    assert "bodies.nu1 = 0.6" in msg and "(-1.0, 0.5]" in msg


def test_unknown_key_lists_known_keys(tmp_path):
    with pytest.raises(SceneError) as info:
        load_scene(_write(tmp_path, CASES["unknown_bem_key"][0]))
    assert "nodes_across" in str(info.value) and "extent_factor" in str(info.value)


def test_toml_syntax_error_is_a_scene_error(tmp_path):
    with pytest.raises(SceneError, match="not valid TOML"):
        load_scene(_write(tmp_path, BASE + "\nforce = = 3\n"))


def test_unknown_scene_name_lists_builtins():
    with pytest.raises(SceneError) as info:
        load_scene("no_such_scene")
    assert "hertz" in str(info.value) and "paper_root" in str(info.value)


def test_missing_file():
    with pytest.raises(SceneError, match="no such file"):
        load_scene("/nonexistent/dir/scene.toml")


@pytest.mark.parametrize("override, key", [
    ("load.force=-1", "load.force"),
    ("bem.nodes_across=3", "bem.nodes_across"),
    ("layer.alpha_a=1.5", "layer.alpha_a"),
    ("bem.nodes_across", "--set"),
    ("force=3", "--set"),
    ("gap.R.x=1", "gap.R"),
])
def test_bad_override_is_refused(override, key):
    code, _out, err = cli("check", "paper_elastic_rigid", "--set", override)
    assert code == 2
    assert key in err


def test_check_lists_every_error_at_once(tmp_path):
    """Three independent errors in three sections: all reported, each naming its key, exit 2."""
    text = (BASE.replace("nu1 = 0.3", "nu1 = 0.7").replace("force = 100.0", "force = -5.0")
            + '\n[layer]\nlaw = "magic"\n')
    path = _write(tmp_path, text)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    errors = info.value.errors
    assert len(errors) == 3
    for key, error in zip(("bodies.nu1 = 0.7", "load.force = -5.0", "layer.law = 'magic'"), errors):
        assert error.startswith(key)
    assert str(info.value).startswith("3 errors in the scene:")
    code, out, err = cli("check", path)
    lines = err.strip().splitlines()
    assert code == 2 and out == "" and len(lines) == 3
    assert all(line.startswith("contactlab: error: ") for line in lines)
    assert [line.split()[2] for line in lines] == ["bodies.nu1", "load.force", "layer.law"]


def test_errors_of_dependent_sections_are_not_repeated(tmp_path):
    """A bad [bodies] leaves [gap] and [bem], which need E*, unchecked rather than reported twice;
    independent sections are still checked."""
    text = BASE.replace("E1 = 210e9", "E1 = -1.0") + '\n[report]\nformat = "word"\n\n[solver]\nx = 1\n'
    with pytest.raises(SceneError) as info:
        load_scene(_write(tmp_path, text))
    keys = sorted(e.split()[0] for e in info.value.errors)
    assert keys == ["bodies.E1", "report.format", "solver"]


def test_check_lists_misspelled_keys_with_the_other_errors_and_suggests_the_key(tmp_path):
    """Misspelled keys of sections that wait for a failed one ([bem], [fem], [stress] need
    [bodies]) are listed in the same pass, each with the closest known key."""
    text = (BASE.replace("nu1 = 0.3", "nu1 = 0.7").replace("force = 100.0", "force = -5.0")
            .replace("nodes_across = 16", "nodes_acros = 16\nextent_factr = 2.0")
            + "\n[fem]\nn_contct = 8\n\n[stress]\ndepht = [0.0]\n\n[reprot]\nformat = 'html'\n")
    path = _write(tmp_path, text)
    code, out, err = cli("check", path)
    lines = err.strip().splitlines()
    assert code == 2 and out == ""
    expected = {"bodies.nu1": "", "load.force": "", "bem.nodes_acros": "Did you mean 'nodes_across'?",
                "bem.extent_factr": "Did you mean 'extent_factor'?",
                "fem.n_contct": "Did you mean 'n_contact_elements'?",
                "stress.depht": "Did you mean 'depths'?", "reprot": "Did you mean 'report'?"}
    assert sorted(line.split()[2] for line in lines) == sorted(expected)
    for line in lines:
        assert line.endswith(expected[line.split()[2]])


@pytest.mark.parametrize("key, value, known", [("extent_factor", "30.0", "domain_factor"),
                                              ("n_contact", "8", "n_contact_elements")])
def test_fem_keys_named_like_bem_quantities_are_refused_with_their_fem_names(tmp_path, key, value, known):
    """``[fem]`` sizes its domain by ``domain_factor`` and its mesh by ``n_contact_elements``:
    ``extent_factor`` (the BEM's candidate region) and ``n_contact`` (nodes in contact) are unknown
    there, and the message points to the FEM's key."""
    with pytest.raises(SceneError) as info:
        load_scene(_write(tmp_path, BASE + f"\n[fem]\n{key} = {value}\n"))
    message = str(info.value)
    assert message.startswith(f"fem.{key} = {value} is not allowed: [fem] has no key {key!r}")
    assert message.endswith(f"Did you mean {known!r}?")


@pytest.mark.parametrize("content, rule", [
    ("[scene]\nname = 'caf\u00e9'\n".encode("latin-1"), "must be UTF-8 text"),
    ("[scene]\nname = 't'\n".encode("utf-16"), "is UTF-16 text"),
    (b"[scene]\nname = 't'\nx = " + b"[" * 5000 + b"]" * 5000 + b"\n", "more than 32 levels deep"),
    (b"[scene]\nname = 't'\nx = " + b"[" * 40 + b"]" * 40 + b"\n", "more than 32 levels deep"),
], ids=["latin-1", "utf-16", "nested-5000", "nested-40"])
def test_files_that_are_not_utf8_toml_or_nest_too_deep_are_refused(tmp_path, content, rule):
    path = tmp_path / "bad.toml"
    path.write_bytes(content)
    code, out, err = cli("check", path)
    assert code == 2 and out == "" and err.startswith(f"contactlab: error: scene file {str(path)!r} is not")
    assert rule in err and "Traceback" not in err


@pytest.mark.parametrize("text, key", [
    (LAYER_BASE + 'law = "power"\nlam = 1e-12\ns = 1e308\n', "layer.s = 1e+308"),
    (BASE + "\n[stress]\ndepths = [0.0, 1e308]\n", "stress.depths[1] = 1e+308"),
    (BASE.replace("nodes_across = 16", "step = 1e-300\nextent = 1e-299"), "bem.step = 1e-300"),
    (BASE + "\n[fem]\nrtol = 10.0\n", "fem.rtol = 10.0"),
    (BASE.replace("nodes_across = 16", "step = 1e-5\nextent = 1e300"), "bem.extent = 1e+300"),
], ids=["power-exponent", "stress-depth", "step", "fem-rtol", "extent"])
def test_values_beyond_their_range_are_refused_at_load(tmp_path, text, key):
    code, out, err = cli("run", _write(tmp_path, text), "--out", tmp_path / "out")
    assert code == 2 and err.startswith(f"contactlab: error: {key} is not allowed") and out == ""
    assert not (tmp_path / "out").exists()


NUL_RULE = "is not allowed: it must be a file name without a NUL byte"


@pytest.mark.parametrize("text, key", [
    (BASE.replace('type = "paraboloid"\nR = 0.01', 'type = "measured"\nfile = "h\\u0000.npy"\nspacing = 1e-6'),
     "gap.file = 'h\\x00.npy'"),
    (LAYER_BASE + 'law = "tabulated"\nfile = "la\\u0000w.toml"\n', "layer.file = 'la\\x00w.toml'"),
], ids=["gap-file", "layer-file"])
def test_a_file_name_with_a_nul_byte_is_refused_naming_the_key(tmp_path, text, key):
    code, out, err = cli("check", _write(tmp_path, text))
    assert code == 2 and out == "" and err == f"contactlab: error: {key} {NUL_RULE} (no file system accepts one).\n"


def test_a_scene_name_with_a_nul_byte_is_refused():
    with pytest.raises(SceneError, match="^scene = 'a\\\\x00b.toml' " + NUL_RULE):
        load_scene("a\x00b.toml")
