"""Every result says its outcome in ``status``, one of ``bem.STATUSES``, beside ``message``."""

import numpy as np
import pytest

import bem
from bem import layers
from bem.gaps import Paraboloid
from bem.reference import rigid_layer_paraboloid


def _hertz(**kw):
    return bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=0.05, extent=1.2, **kw)


def _check(res, status):
    assert res.status == status, res.message
    assert res.converged == (status == "converged")
    assert res.summary()["status"] == status


# a layer each method converges on (the augmented gap needs a layer much softer than the bodies)
LAYER = {"kalker": None, "newton": layers.Root(0.05), "augmented_gap": layers.Linear(1e-3),
         "variable_compliance": layers.Root(0.05)}


@pytest.mark.parametrize("method", bem.METHODS)
def test_a_converged_run_says_converged(method):
    _check(_hertz(layer=LAYER[method], method=method), "converged")


@pytest.mark.parametrize("method", bem.METHODS)
def test_a_run_out_of_iterations_says_maxiter(method):
    _check(_hertz(layer=LAYER[method], method=method, maxiter=1), "maxiter")


def test_growing_increments_of_the_augmented_gap_say_diverged():
    _check(_hertz(layer=layers.Root(0.05), method="augmented_gap"), "diverged")


def test_an_augmented_gap_that_makes_no_progress_says_stalled():
    _check(_hertz(layer=layers.Root(1.0), method="augmented_gap", maxiter=40), "stalled")


def test_a_secant_map_that_makes_no_progress_says_stalled():
    """s >= 2 with a dominating layer: the secant map has derivative -(s - 1) <= -1."""
    layer = layers.Power(1.0, 3.0)
    a = rigid_layer_paraboloid(layer, 1.0, force=1.0).contact_radius
    res = bem.solve(Paraboloid(1.0), E_star=1e4, force=1.0, step=2 * a / 30, extent=1.3 * a, layer=layer,
                    method="variable_compliance", maxiter=60)
    _check(res, "stalled")


def test_a_periodic_result_says_its_status():
    cell = bem.PeriodicCell(1.0 / 16, 16, 16)
    h = 0.05 * (2 - np.cos(2 * np.pi * cell.x) - np.cos(2 * np.pi * cell.y / cell.size[1]))
    kw = dict(step=cell.step, E_star=1.0, mean_pressure=0.02)
    _check(bem.solve_periodic(h, **kw), "converged")
    _check(bem.solve_periodic(h, maxiter=1, **kw), "maxiter")


def test_statuses_are_the_documented_set():
    assert set(bem.STATUSES) == {"converged", "maxiter", "stalled", "diverged", "nonfinite"}
