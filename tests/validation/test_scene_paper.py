"""The paper's layer parameterisation (section 6): C_nn, alpha_a, alpha_b, alpha_c."""

import math
import tomllib
from types import SimpleNamespace

import numpy as np
import pytest

import bem
from bem.layers import Bilinear, ElasticRigid, Linear, Root
from bem.reference import hertz_sphere
from validation.run import execute_scene, run_scene
from validation.scene import builtin_path, load_scene
from validation.run.calibrate import CalibrationError, resolve_layer
from validation.scene.paper import c_nn, check_layer

from .conftest import STEEL_E, STEEL_NU, e_star

W_T00 = 1.5 * math.sqrt(3.0) * math.log(3.0)  # template at the origin, (3 sqrt3 / 2) ln 3 (docs/method.md)
P_LAMBDA = 7.0e8  # a stand-in peak pressure of the linear reference


class StubSolve:
    """Records the layers it is asked to solve; returns a fixed peak pressure."""

    def __init__(self, p_max=P_LAMBDA):
        self.p_max, self.layers = p_max, []

    def __call__(self, layer):
        self.layers.append(layer)
        return SimpleNamespace(p_max=self.p_max)


def test_c_nn_is_the_diagonal_influence_coefficient():
    assert c_nn(2e-5, 1e11) == pytest.approx(2e-5 / (math.pi * 1e11) * W_T00, rel=1e-13)


def test_lam_over_cnn_is_taken_at_its_reference_step_whatever_the_lattice():
    spec = check_layer({"law": "linear", "lam_over_cnn": 10.0, "cnn_step": 1e-5})
    for step in (2e-5, 1e-5, 2.5e-6):
        solve = StubSolve()
        layer, info = resolve_layer(spec, step=step, E_star=1e11, solve=solve)
        assert isinstance(layer, Linear) and layer.lam == pytest.approx(10 * 1e-5 / (math.pi * 1e11) * W_T00)
        assert solve.layers == []
        assert info["lam_ref"] == layer.lam
        assert info["c_nn"] == pytest.approx(step / (math.pi * 1e11) * W_T00)  # C_nn of the lattice in use
        assert info["lam_over_cnn"] == pytest.approx(10 * 1e-5 / step)


def test_lam_over_cnn_without_its_reference_step_is_refused():
    from validation.scene import SceneError

    with pytest.raises(SceneError, match=r"layer\.lam_over_cnn = 10\.0 is not allowed without layer\.cnn_step"):
        check_layer({"law": "linear", "lam_over_cnn": 10.0})
    with pytest.raises(SceneError, match=r"layer\.cnn_step = 1e-05 is not allowed without layer\.lam_over_cnn"):
        check_layer({"law": "elastic_rigid", "lam": 1e-15, "cnn_step": 1e-5, "alpha_a": 0.5})


def test_elastic_rigid_threshold_from_alpha_a():
    solve = StubSolve()
    layer, info = resolve_layer(check_layer({"law": "elastic_rigid", "lam_over_cnn": 10.0, "cnn_step": 1e-5,
                                             "alpha_a": 0.3}), step=2e-5, E_star=1e11, solve=solve)
    lam = 10 * c_nn(1e-5, 1e11)
    assert len(solve.layers) == 1 and isinstance(solve.layers[0], Linear) and solve.layers[0].lam == lam
    assert isinstance(layer, ElasticRigid)
    assert layer.lam == lam and layer.p_cr == pytest.approx(0.3 * P_LAMBDA)
    assert info["p_max_lambda"] == P_LAMBDA


def test_alpha_a_zero_is_the_smooth_contact():
    layer, _ = resolve_layer(check_layer({"law": "elastic_rigid", "lam": 1e-15, "alpha_a": 0.0}),
                             step=1e-5, E_star=1e11, solve=StubSolve())
    assert layer is None
    layer, _ = resolve_layer(check_layer({"law": "bilinear", "lam1": 1e-15, "alpha_c": 0.5, "alpha_a": 0.0}),
                             step=1e-5, E_star=1e11, solve=StubSolve())
    assert isinstance(layer, Linear) and layer.lam == pytest.approx(1e-15 * math.tan(0.5))


def test_bilinear_from_alpha_c():
    layer, info = resolve_layer(check_layer({"law": "bilinear", "lam1": 2e-15, "alpha_c": 0.4, "alpha_a": 0.5}),
                                step=1e-5, E_star=1e11, solve=StubSolve())
    assert isinstance(layer, Bilinear)
    assert layer.lam1 == 2e-15 and layer.lam2 == pytest.approx(2e-15 * math.tan(0.4), rel=1e-14)
    assert layer.p_star == pytest.approx(0.5 * P_LAMBDA)
    assert info["alpha_c"] == pytest.approx(0.4, rel=1e-14)


@pytest.mark.parametrize("reference", [{"lam_ref": 2e-15}, {"lam_over_cnn": 10.0, "cnn_step": 2e-5 * W_T00 ** -1}])
def test_root_law_meets_the_linear_layer_at_p_max_lambda(reference):
    solve = StubSolve()
    layer, info = resolve_layer(check_layer({"law": "root", **reference}), step=1e-5, E_star=1e11, solve=solve)
    lam = 2e-15 if "lam_ref" in reference else 10 * c_nn(reference["cnn_step"], 1e11)
    assert solve.layers[0].lam == lam and info["lam_ref"] == lam
    assert isinstance(layer, Root)
    assert float(layer.w(P_LAMBDA)) == pytest.approx(lam * P_LAMBDA, rel=1e-13)
    assert float(layer.w(0.25 * P_LAMBDA)) == pytest.approx(2 * lam * 0.25 * P_LAMBDA, rel=1e-13)  # softer below


def test_direct_parameters_need_no_reference():
    solve = StubSolve()
    layer, _ = resolve_layer(check_layer({"law": "elastic_rigid", "lam": 1e-15, "p_cr": 1e8}), step=1e-5,
                             E_star=1e11, solve=solve)
    assert solve.layers == [] and layer.p_cr == 1e8


def test_check_layer_does_not_modify_its_input():
    d = {"law": "bilinear", "lam_over_cnn": 10.0, "cnn_step": 1e-5, "alpha_c": 0.1, "alpha_a": 0.5}
    before = dict(d)
    spec = check_layer(d)
    resolve_layer(spec, step=1e-5, E_star=1e11, solve=StubSolve())
    assert d == before


SMALL = ["bem.nodes_across=20"]


def _bem_only(name):
    """The raw built-in scene without its FEM, sweep, report and closed-form sections."""
    with open(builtin_path(name), "rb") as fh:
        return {k: v for k, v in tomllib.load(fh).items() if k not in ("fem", "sweep", "report", "analytic")}


def test_paper_layer_is_ten_c_nn_at_the_reference_step_in_physical_units():
    """The scenes' compliance is the paper's 10 C_nn at c = a_H/20, as its lam_over_cnn form gives it."""
    smooth = load_scene("paper_smooth")
    a_h = hertz_sphere(smooth.gap.R, smooth.E_star, **smooth.load).contact_radius
    lam = 10 * a_h / 20 / (math.pi * smooth.E_star) * W_T00
    assert load_scene("paper_linear").layer.lam == pytest.approx(lam, rel=1e-4)  # 4 digits in the scene
    r = run_scene(_bem_only("paper_linear"), overrides=SMALL + ["layer.lam_over_cnn=10.0",
                                                                 f"layer.cnn_step={a_h / 20!r}"])
    assert r.layer["parameters"]["lam"] == pytest.approx(lam, rel=1e-12)


@pytest.mark.parametrize("name", ["paper_linear", "paper_root"])
def test_paper_layered_scene_converges_under_refinement(name):
    """nodes_across 20, 40, 80, 160 solve one problem: the same compliance, and p_max and the approach
    converge at about second order (measured, linear layer: p_max differences 6.0e-4, 1.3e-4, 3.0e-5 of
    p_H, order 2.2 then 2.1; approach 4.5e-4, 1.3e-4, 4e-5 of delta_H, order 1.8 then 1.7; root layer:
    p_max 7.4e-4, 1.9e-4, 5e-5, order 1.9 then 1.9). The contact radius, read off the lattice,
    converges too but not monotonically (its differences stay within 2 steps)."""
    outs = [execute_scene(_bem_only(name), overrides={"bem.nodes_across": n}) for n in (20, 40, 80, 160)]
    assert all(o.bem.converged for o in outs)
    lams = [o.result.layer["lam_ref" if name == "paper_root" else "parameters"] for o in outs]
    lams = [x if isinstance(x, float) else x["lam"] for x in lams]
    assert lams == [lams[0]] * 4
    sc = outs[0].scene
    hz = hertz_sphere(sc.gap.R, sc.E_star, **sc.load)
    for key, scale in (("p_max", hz.p_max), ("approach", hz.approach)):
        values = np.array([getattr(o.result, key) for o in outs]) / scale
        diffs = np.abs(np.diff(values))
        orders = np.log2(diffs[:-1] / diffs[1:])
        assert np.all(orders > 1.5), (key, values, orders)
    radii = np.array([o.result.contact_radius for o in outs])
    steps = np.array([o.result.bem.step for o in outs])
    assert np.all(np.abs(np.diff(radii)) <= 2 * steps[:-1])
    assert abs(radii[-1] - radii[-2]) < 0.01 * radii[-1]


def test_alpha_b_target_is_reached():
    """lam_r found for alpha_b = 0.9; checked by an independent solve of that root law."""
    r = run_scene("paper_root", overrides=SMALL + ["alpha_b=0.9"])
    assert r.alpha_b == pytest.approx(0.9, rel=1e-3)
    lam_r = r.layer["parameters"]["lam"]
    Es = e_star(STEEL_E, STEEL_NU, STEEL_E, STEEL_NU)
    gap = bem.gaps.Paraboloid(0.01)
    kw = dict(E_star=Es, force=100.0, step=r.bem.step, extent=r.bem.extent)
    p_lambda = bem.solve(gap, layer=Linear(r.layer["lam_ref"]), **kw).p_max
    p_root = bem.solve(gap, layer=Root(lam_r), **kw).p_max
    assert p_root / p_lambda == pytest.approx(0.9, rel=1e-3)
    assert r.layer["p_max_lambda"] == pytest.approx(p_lambda, rel=1e-8)


def test_alpha_b_out_of_reach_is_refused():
    with pytest.raises(CalibrationError, match="layer.alpha_b"):
        run_scene("paper_root", overrides=SMALL + ["alpha_b=5.0"])
