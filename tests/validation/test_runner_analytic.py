"""Closed-form comparisons a scene can ask for: rigid_layer and hertz_elliptic on a paraboloid."""

import math

import pytest

from validation.run import run_scene

RIGID_LAYER = {
    "scene": {"name": "rigid_layer"},
    "bodies": {"E1": 1e20, "nu1": 0.3, "E2": 1e20, "nu2": 0.3},  # practically rigid bodies
    "gap": {"type": "paraboloid", "R": 0.01},
    "layer": {"law": "linear", "lam": 1e-12},
    "load": {"force": 100.0},
    "bem": {"nodes_across": 40},
    "analytic": {"kind": "rigid_layer"},
}


def test_rigid_bodies_on_a_winkler_layer():
    """p = (delta - r^2/2R) / lam, P = pi R delta^2 / lam (written out here)."""
    r = run_scene(RIGID_LAYER)
    lam, R, P = 1e-12, 0.01, 100.0
    delta = math.sqrt(P * lam / (math.pi * R))
    assert r.analytic.p_max == pytest.approx(delta / lam, rel=1e-12)
    assert r.p_max == pytest.approx(delta / lam, rel=0.01)
    assert r.approach == pytest.approx(delta, rel=0.01)
    assert r.contact_radius == pytest.approx(math.sqrt(2 * R * delta), rel=0.03)


def test_hertz_elliptic_on_a_paraboloid_is_the_circle():
    scene = dict(RIGID_LAYER, bodies={"E1": 210e9, "nu1": 0.3, "E2": 210e9, "nu2": 0.3},
                 analytic={"kind": "hertz_elliptic"})
    scene.pop("layer")
    r = run_scene(scene, overrides=["bem.nodes_across=24"])
    ref = r.analytic
    assert ref.a == pytest.approx(ref.b, rel=1e-9)
    assert r.p_max == pytest.approx(ref.p_max, rel=0.01)


def test_hertz_on_a_round_elliptic_paraboloid():
    scene = dict(RIGID_LAYER, bodies={"E1": 210e9, "nu1": 0.3, "E2": 210e9, "nu2": 0.3},
                 gap={"type": "elliptic_paraboloid", "Rx": 0.01, "Ry": 0.01}, analytic={"kind": "hertz"})
    scene.pop("layer")
    r = run_scene(scene, overrides=["bem.nodes_across=24"])
    a = (3 * 100.0 * 0.01 / (4 * 210e9 / (2 * (1 - 0.09)))) ** (1 / 3)
    assert r.analytic.contact_radius == pytest.approx(a, rel=1e-12)
    assert r.contact_radius == pytest.approx(a, rel=0.03)
