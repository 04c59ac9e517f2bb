"""Fixtures of the FEM reference tests (coarse meshes: fast)."""

import pytest
from .fem_cases import E, NU, P, R, e_star, hertz

from bem.gaps import Paraboloid


@pytest.fixture(scope="session")
def gap():
    return Paraboloid(R)


@pytest.fixture(scope="session")
def hertz_same():
    return hertz(P, R, e_star(E, NU, E, NU))


@pytest.fixture(scope="session")
def coarse_mesh(hertz_same):
    """A coarse mesh sized for the same-material Hertz problem (8 elements across a)."""
    from fem_reference import build_mesh

    return build_mesh(hertz_same[0], n_contact_elements=8, domain_factor=30.0)
