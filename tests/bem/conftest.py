"""The paper's test problem (two paraboloids, Fig. 4a) in units where R = E* = P = 1."""

import math

import pytest

import bem
from bem import layers

R = E_STAR = FORCE = 1.0
A_HERTZ = (3 * FORCE * R / (4 * E_STAR)) ** (1 / 3)
P0_HERTZ = 3 * FORCE / (2 * math.pi * A_HERTZ**2)
STEP = 2 * A_HERTZ / 30
EXTENT = 2.2 * A_HERTZ
C_NN = bem.diagonal_coefficient(STEP, E_STAR)


def paper_laws(factor):
    """The laws of Fig. 4 with compliance ``factor * C_nn`` at the Hertz peak pressure."""
    lam = factor * C_NN
    return {
        "linear": layers.Linear(lam),
        "root": layers.Root(lam * math.sqrt(P0_HERTZ)),
        "power_2": layers.Power(lam / P0_HERTZ, 2.0),
        "elastic_rigid": layers.ElasticRigid(lam, 0.5 * P0_HERTZ),
        "bilinear": layers.Bilinear(lam, lam * math.tan(0.2), 0.5 * P0_HERTZ),
    }


@pytest.fixture(scope="session")
def paper():
    """Solve the paper problem: ``paper(layer, method, **kw)``."""

    def run(layer, method="newton", **kw):
        kw = {"force": FORCE, **kw}
        return bem.solve(bem.gaps.Paraboloid(R), E_star=E_STAR, step=STEP, extent=EXTENT,
                         layer=layer, method=method, **kw)

    return run


@pytest.fixture
def two_threads():
    """The FFT threads (and the compiled passes' parts) set to two for the test, restored after it."""
    from bem import fft

    previous = fft.set_threads(2)
    yield
    fft.set_threads(previous)
