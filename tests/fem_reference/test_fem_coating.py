"""A coating meshed as its own material, bonded to its substrate: the mesh, an exact state, and the
surface displacement against the Hankel transform of the coated half-space's compliance."""

import numpy as np
import pytest
from scipy.special import j0, jv

from bem.checks import InputError
from bem.coating import Coating, mode_compliance
from bem.gaps import Paraboloid
from fem_reference import build_mesh, solve
from fem_reference.sizes import N_ACROSS_COATING
from fem_reference.model import AxiModel

E, NU = 1.0, 0.3
B = 1.5  # radius of the smooth test load q = (1 - r^2/B^2)^2


def _hankel_displacement(r, bodies, k_max=1500.0, panels=12000, order=16):
    """``u(r) = 16 B^2 int_0^inf (s1 + s2)(k) J3(k B) J0(k r) / (k B)^3 dk`` by Gauss-Legendre panels.

    The 2-D Fourier transform of ``(1 - r^2/B^2)^2`` is ``2 pi B^2 8 J3(k B) / (k B)^3``; a body's
    symbol is ``2 s(k) / k``. The tail beyond ``k_max`` is below 1e-10 of the value.
    """
    x, w = np.polynomial.legendre.leggauss(order)
    edges = np.linspace(0.0, k_max, panels + 1)
    half = 0.5 * np.diff(edges)
    k = (0.5 * (edges[:-1] + edges[1:]))[:, None] + half[:, None] * x
    s = sum(mode_compliance(k, E_b, nu_b, c) for E_b, nu_b, c in bodies)
    kernel = s * jv(3, k * B) / (k * B) ** 3 * w * half[:, None]
    return np.array([16.0 * B * B * np.sum(kernel * j0(k * ri)) for ri in np.atleast_1d(r)])


def _surface_displacement(model):
    """Relative interface displacement ``(C + dc) f`` under the smooth load."""
    q = np.where(model.r < B, (1.0 - (model.r / B) ** 2) ** 2, 0.0)
    dc = model.reference_correction(None, 1.0)
    return (model.interface_compliance() + dc) @ (model.weights * q)


def test_the_hankel_reference_reproduces_the_homogeneous_closed_form():
    # u(0) = (2 / E*) int_0^B q dr = 16 B s / 15 for s1 + s2 = 2 (1 - nu^2) / E
    u0 = _hankel_displacement(0.0, [(E, NU, None), (E, NU, None)])[0]
    assert u0 == pytest.approx(16.0 * B * 2 * (1 - NU**2) / (15.0 * E), rel=1e-9)


@pytest.fixture(scope="module")
def thin_mesh():
    return build_mesh(1.0, n_contact_elements=6, domain_factor=30.0, coating_thickness=(None, 0.2))


def test_coating_elements_fill_the_strip_with_several_elements_across(thin_mesh):
    m, t = thin_mesh, 0.2
    p, tri = m.mesh.p, m.mesh.t
    centroid = p[:, tri].mean(axis=1)
    in_strip = (m.body == 1) & (centroid[1] > -t)
    np.testing.assert_array_equal(m.coated, in_strip)
    assert m.coated.any() and not m.coated[m.body == 0].any()
    corners = p[:, tri[:, m.coated]]
    assert corners[1].min() >= -t * (1 + 1e-12) and corners[1].max() <= 1e-12
    near = m.coated & (centroid[0] < m.fine_radius - t)
    edges = np.linalg.norm(np.roll(p[:, tri[:, near]], 1, axis=1) - p[:, tri[:, near]], axis=0)
    assert edges.max() <= 1.5 * t / N_ACROSS_COATING
    assert m.radius == 30.0


def test_no_coating_keeps_the_plain_mesh():
    plain = build_mesh(1.0, n_contact_elements=4, domain_factor=20.0)
    same = build_mesh(1.0, n_contact_elements=4, domain_factor=20.0, coating_thickness=(None, None))
    np.testing.assert_array_equal(plain.nodes6, same.nodes6)
    np.testing.assert_array_equal(plain.cells6, same.cells6)
    assert not same.coated.any()


def test_uniform_pressure_on_a_coated_body_gives_the_exact_uniaxial_state():
    # nu_c / E_c = nu_s / E_s: both layers contract alike sideways under sigma_zz = -q, so the
    # uniaxial state is exact and bonded; u = q (H / E1 + t / E_c + (H - t) / E_s)
    t, c = 0.5, Coating(0.5, 2.0 * E, 0.4)
    assert c.nu / c.E == pytest.approx(0.2 / E)
    m = build_mesh(1.0, n_contact_elements=4, domain_factor=12.0, coating_thickness=(None, t))
    model = AxiModel(m, E1=E, nu1=NU, E2=E, nu2=0.2, coating2=c)
    q, H = 2.0, m.depth
    d = model.interface_compliance() @ (model.weights * q)
    np.testing.assert_allclose(d, q * (H / E + t / c.E + (H - t) / E), rtol=1e-8)


@pytest.mark.parametrize("t, Ec, nuc", [(1.0, 10.0, 0.45), (0.3, 0.1, 0.3)])
def test_surface_displacement_of_a_coated_body_equals_the_hankel_transform(t, Ec, nuc):
    c = Coating(t, Ec, nuc)
    m = build_mesh(1.0, n_contact_elements=8, domain_factor=40.0, coating_thickness=(None, t))
    model = AxiModel(m, E1=E, nu1=NU, E2=E, nu2=NU, coating2=c)
    u = _surface_displacement(model)
    at = [0, int(np.searchsorted(model.r, 0.7))]
    ref = _hankel_displacement(model.r[at], [(E, NU, None), (E, NU, c)])
    # measured: 2e-4 to 5e-4 with 8 elements across a (1e-5 to 2e-4 with 16)
    np.testing.assert_allclose(u[at], ref, rtol=1e-3)
    uncoated = _hankel_displacement(model.r[at], [(E, NU, None), (E, NU, None)])
    assert np.all(np.abs(ref / uncoated - 1.0) > 0.05)  # the coating's effect is far above the tolerance


def test_sphere_on_a_coated_flat_converges_and_a_like_coating_changes_nothing():
    gap, P = Paraboloid(1.0), 4.0 * 0.1**3 * (E / (1 - NU**2) / 2) / 3.0  # Hertz a = 0.1
    plain = solve(gap, E1=E, nu1=NU, E2=E, nu2=NU, force=P, n_contact_elements=8, remesh=False)
    like = solve(gap, E1=E, nu1=NU, E2=E, nu2=NU, coating2=Coating(0.05, E, NU), force=P,
                 n_contact_elements=8, remesh=False)
    soft = solve(gap, E1=E, nu1=NU, E2=E, nu2=NU, coating2=Coating(0.05, 0.1 * E, NU), force=P,
                 n_contact_elements=8, remesh=False)
    assert plain.converged and like.converged and soft.converged
    assert like.p_max == pytest.approx(plain.p_max, rel=5e-3)
    assert like.approach == pytest.approx(plain.approach, rel=5e-3)
    assert soft.p_max < 0.8 * plain.p_max and soft.edge_radius > plain.edge_radius


def test_bad_coatings_are_refused():
    gap = Paraboloid(1.0)
    with pytest.raises(InputError, match=r"^coating2\.nu = 0\.5 "):
        solve(gap, E1=E, nu1=NU, E2=E, nu2=NU, coating2=Coating(0.1, E, 0.5), force=1e-3)
    with pytest.raises(InputError, match=r"^coating1 = 3 "):
        solve(gap, E1=E, nu1=NU, E2=E, nu2=NU, coating1=3, force=1e-3)
    mesh = build_mesh(0.1, n_contact_elements=4, domain_factor=20.0)
    with pytest.raises(InputError, match=r"^coating2 = .*thickness must be the mesh's"):
        solve(gap, E1=E, nu1=NU, E2=E, nu2=NU, coating2=Coating(0.1, E, 0.3), force=1e-3, mesh=mesh)
    with pytest.raises(InputError, match=r"^coating_thickness\[1\] = -1\.0 "):
        build_mesh(0.1, coating_thickness=(None, -1.0))


def test_more_elements_across_the_coating_when_asked():
    """``n_across_coating = 8``: the coating's elements in the fine zone at most 1.5 t / 8 (the default four:
    not)."""
    t = 0.2
    for across in (N_ACROSS_COATING, 8):
        m = build_mesh(1.0, n_contact_elements=6, domain_factor=30.0, coating_thickness=(None, t),
                       n_across_coating=across)
        p, tri = m.mesh.p, m.mesh.t
        near = m.coated & (p[:, tri].mean(axis=1)[0] < m.fine_radius - t)
        longest = np.linalg.norm(np.roll(p[:, tri[:, near]], 1, axis=1) - p[:, tri[:, near]], axis=0).max()
        assert m.n_across_coating == across
        assert (longest <= 1.5 * t / 8) == (across == 8), (across, longest / (t / 8))
