"""The paper's layer parameterisation (section 6): C_nn, alpha_a, alpha_b, alpha_c."""

import math
from types import SimpleNamespace

import pytest

import bem
from bem.layers import Bilinear, ElasticRigid, Linear, Root
from validation.scene.paper import c_nn, check_layer, resolve_layer
from validation.run import run_scene

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


def test_linear_layer_from_lam_over_cnn_needs_no_reference_solve():
    solve = StubSolve()
    layer, info = resolve_layer(check_layer({"law": "linear", "lam_over_cnn": 10.0}), step=1e-5, E_star=1e11,
                                solve=solve)
    assert isinstance(layer, Linear) and layer.lam == pytest.approx(10 * 1e-5 / (math.pi * 1e11) * W_T00)
    assert solve.layers == []
    assert info["lam_ref"] == layer.lam


def test_elastic_rigid_threshold_from_alpha_a():
    solve = StubSolve()
    layer, info = resolve_layer(check_layer({"law": "elastic_rigid", "lam_over_cnn": 10.0, "alpha_a": 0.3}),
                                step=1e-5, E_star=1e11, solve=solve)
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


def test_root_law_meets_the_linear_layer_at_p_max_lambda():
    layer, info = resolve_layer(check_layer({"law": "root", "lam_over_cnn": 10.0}), step=1e-5, E_star=1e11,
                                solve=StubSolve())
    lam = 10 * c_nn(1e-5, 1e11)
    assert isinstance(layer, Root)
    assert float(layer.w(P_LAMBDA)) == pytest.approx(lam * P_LAMBDA, rel=1e-13)
    assert float(layer.w(0.25 * P_LAMBDA)) == pytest.approx(2 * lam * 0.25 * P_LAMBDA, rel=1e-13)  # softer below


def test_direct_parameters_need_no_reference():
    solve = StubSolve()
    layer, _ = resolve_layer(check_layer({"law": "elastic_rigid", "lam": 1e-15, "p_cr": 1e8}), step=1e-5,
                             E_star=1e11, solve=solve)
    assert solve.layers == [] and layer.p_cr == 1e8


def test_check_layer_does_not_modify_its_input():
    d = {"law": "bilinear", "lam_over_cnn": 10.0, "alpha_c": 0.1, "alpha_a": 0.5}
    before = dict(d)
    spec = check_layer(d)
    resolve_layer(spec, step=1e-5, E_star=1e11, solve=StubSolve())
    assert d == before


SMALL = ["bem.nodes_across=20"]


def test_scene_lambda_is_ten_c_nn_of_its_own_step():
    r = run_scene("paper_linear", overrides=SMALL + ["fem.n_contact=8"])
    Es = e_star(STEEL_E, STEEL_NU, STEEL_E, STEEL_NU)
    step = r["bem"]["step"]
    assert r["layer"]["parameters"]["lam"] == pytest.approx(10 * step / (math.pi * Es) * W_T00, rel=1e-12)


def test_alpha_b_target_is_reached():
    """lam_r found for alpha_b = 0.9; checked by an independent solve of that root law."""
    r = run_scene("paper_root", overrides=SMALL + ["alpha_b=0.9"])
    assert r["alpha_b"] == pytest.approx(0.9, rel=1e-3)
    lam_r = r["layer"]["parameters"]["lam"]
    Es = e_star(STEEL_E, STEEL_NU, STEEL_E, STEEL_NU)
    gap = bem.gaps.Paraboloid(0.01)
    kw = dict(E_star=Es, force=100.0, step=r["bem"]["step"], extent=r["bem"]["extent"])
    p_lambda = bem.solve(gap, layer=Linear(r["layer"]["lam_ref"]), **kw).p_max
    p_root = bem.solve(gap, layer=Root(lam_r), **kw).p_max
    assert p_root / p_lambda == pytest.approx(0.9, rel=1e-3)
    assert r["layer"]["p_max_lambda"] == pytest.approx(p_lambda, rel=1e-8)


def test_alpha_b_out_of_reach_is_refused():
    from validation.scene import SceneError

    with pytest.raises(SceneError, match="layer.alpha_b"):
        run_scene("paper_root", overrides=SMALL + ["alpha_b=5.0"])
