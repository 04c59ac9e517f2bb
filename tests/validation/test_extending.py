"""Extending the toolkit the way CONTRIBUTING.md says: a new gap type is one class and one registry line."""

import math

import pytest

import bem.gaps
from bem.checks import check_positive
from bem.gaps import AxisymmetricGap
from validation.run import run_scene
from validation.scene import SceneError, load_scene
from validation.scene.schema import scene_keys


class Cone(AxisymmetricGap):
    """Rigid cone on a flat: h = slope r (slope = cot of the half-angle)."""

    type_name = "toy_cone"

    def __init__(self, slope):
        self.slope = check_positive("slope", slope)

    def _profile(self, r):
        return self.slope * r

    def _params(self):
        return {"slope": self.slope}


E_STAR, SLOPE, FORCE = 1.0, 0.1, 1e-3
SCENE = {"scene": {"name": "cone", "units": "normalised"}, "bodies": {"E_star": E_STAR},
         "gap": {"type": "toy_cone", "slope": SLOPE}, "load": {"force": FORCE}, "bem": {"nodes_across": 40}}


@pytest.fixture
def registered(monkeypatch):
    monkeypatch.setitem(bem.gaps.GAPS, "toy_cone", Cone)  # the one registry line (bem/gaps/__init__.py)


def test_a_new_gap_type_is_checked_sized_and_solved_by_the_scenes(registered, tmp_path):
    """Nothing in validation names the gap type: the schema, the checks, the sizing, the run and the
    result read it from the class. Against Sneddon's cone (Johnson 1985, sec. 5.2):
    P = pi a^2 E* s / 2 and delta = pi a s / 2."""
    assert scene_keys()["gap"]["toy_cone"] == ("slope",)
    scene = load_scene(SCENE)
    a = math.sqrt(2 * FORCE / (math.pi * E_STAR * SLOPE))
    # sized by the generic axisymmetric estimate, the paraboloid through the contact edge: 8 E* a h(a) = 3 P
    assert scene.bem["expected"][0] == pytest.approx(math.sqrt(3 * FORCE / (8 * E_STAR * SLOPE)), rel=1e-9)
    result = run_scene(scene, tmp_path / "cone")
    assert result.converged and (tmp_path / "cone" / "bem_field.vtu").is_file()
    assert result.contact_radius == pytest.approx(a, abs=2 * scene.bem["step"])
    assert result.approach == pytest.approx(math.pi * a * SLOPE / 2, rel=1e-3)  # measured 3.9e-5
    # the report's problem statement describes the shape by its docstring, with its parameter
    from validation.report import report_results_dir

    html = report_results_dir(tmp_path / "cone", tmp_path / "report").html.read_text(encoding="utf-8")
    assert "Rigid cone on a flat: h = slope r" in html and "slope" in html


def test_a_new_gap_type_s_bad_input_names_its_key(registered):
    with pytest.raises(SceneError, match=r"gap\.slope is missing"):
        load_scene({**SCENE, "gap": {"type": "toy_cone"}})
    with pytest.raises(SceneError, match=r"gap\.slope = -1\.0 is not allowed"):
        load_scene({**SCENE, "gap": {"type": "toy_cone", "slope": -1.0}})
    with pytest.raises(SceneError, match=r"gap\.angle = 3 is not allowed"):
        load_scene({**SCENE, "gap": {"type": "toy_cone", "slope": 0.1, "angle": 3}})


def test_without_its_registry_line_the_gap_type_is_unknown():
    with pytest.raises(SceneError, match="toy_cone"):
        load_scene(SCENE)


def test_register_refuses_what_is_not_a_new_gap_type():
    with pytest.raises(ValueError, match="subclass of bem.gaps.Gap"):
        bem.gaps.register(dict)
    with pytest.raises(ValueError, match="type_name"):
        bem.gaps.register(type("Again", (bem.gaps.Paraboloid,), {}))  # type_name "paraboloid" is taken
