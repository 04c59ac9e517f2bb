"""The quadratic form ``v.C v`` of the half-space operator without its product, and its use by the QP."""

import numpy as np
import pytest

import bem
from bem.block_symbol import block_quadratic
from bem import layers
from bem.lattice import Lattice
from bem.operator import InfluenceOperator


@pytest.mark.parametrize("n_cols", [12, 15])  # a Nyquist column in the half spectrum, and none
def test_block_quadratic_is_the_sum_over_the_whole_spectrum(n_cols):
    """Against the circular convolution itself: ``sum_a x_a . (sum_b k_ab * x_b)`` for real kernels with
    ``k_00``, ``k_11`` even and ``k_10(x) = k_01(-x)`` (a Hermitian symbol), from the half spectra."""
    rng = np.random.default_rng(5)
    shape = (10, n_cols)

    def even(k):
        return 0.5 * (k + np.roll(k[::-1, ::-1], 1, axis=(0, 1)))

    k00, k11, k01 = even(rng.standard_normal(shape)), even(rng.standard_normal(shape)), rng.standard_normal(shape)
    k10 = np.roll(k01[::-1, ::-1], 1, axis=(0, 1))
    x = rng.standard_normal((2, *shape))

    def conv(k, v):
        return np.fft.ifft2(np.fft.fft2(k) * np.fft.fft2(v)).real

    ref = float(np.sum(x[0] * (conv(k00, x[0]) + conv(k01, x[1]))) + np.sum(x[1] * (conv(k10, x[0]) + conv(k11, x[1]))))
    size = shape[0] * shape[1]
    S = ((np.fft.rfft2(k00).real / size, np.fft.rfft2(k01) / size), (None, np.fft.rfft2(k11).real / size))
    V = np.fft.rfft2(x)
    assert block_quadratic(S, V, n_cols) == pytest.approx(ref, rel=1e-12)
    with pytest.raises(ValueError, match="Hermitian symbol"):
        block_quadratic((S[0], (S[0][1].conj(), S[1][1])), V, n_cols)


@pytest.mark.parametrize("extent, coated", [((1.0, 0.8), False), ((0.55, 1.0), False), ((0.73, 0.81), False),
                                            ((0.6, 0.5), True)])
def test_quadratic_equals_the_dense_quadratic_form(extent, coated):
    """``op.quadratic(v)`` is ``v.C v`` of the dense matrix of eq. 6 to single precision, on supports from one node
    to the whole region, and leaves ``v`` alone."""
    bodies = bem.Bodies(210e9, 0.3, 210e9, 0.3, coating1=bem.Coating(0.05, 3.0, 0.3)) if coated else None
    lat = Lattice.from_extent(0.05, extent)
    op = InfluenceOperator(lat, 1.0 if bodies is None else bodies.E_star, bodies=bodies)
    C = op.dense()
    rng = np.random.default_rng(11)
    assert op.quadratic(np.zeros(lat.shape)) == 0.0
    for k in range(8):
        v = np.zeros(lat.shape)
        if k == 0:
            v[3, 4] = 1.0
        elif k == 1:
            v = rng.standard_normal(lat.shape) * lat.mask
        else:
            r0, c0 = rng.integers(0, lat.shape[0] - 2), rng.integers(0, lat.shape[1] - 2)
            v[r0 : r0 + rng.integers(1, lat.shape[0] // 2), c0 : c0 + rng.integers(1, lat.shape[1] // 2)] = 1.0
            v *= rng.random(lat.shape) * lat.mask
        given = v.copy()
        ref = float(v[lat.mask] @ C @ v[lat.mask])
        assert op.quadratic(v) == pytest.approx(ref, rel=1e-6)
        assert np.array_equal(v, given)
    assert op.n_matvec == 0  # not a product


def _rough_sphere(x, y):
    """A sphere (``R = 1``) carrying a smooth roughness of a few lattice steps: nodes enter at most steps."""
    return 0.5 * (x**2 + y**2) + 2e-4 * (np.sin(2 * np.pi * x / 0.037) * np.cos(2 * np.pi * y / 0.029)
                                         + np.sin(2 * np.pi * (x + y) / 0.023))


@pytest.mark.parametrize("layer, method", [(None, "kalker"), (layers.Linear(2e-3), "kalker"),
                                           (layers.Root(5e-4), "newton")], ids=["no_layer", "linear", "root_newton"])
def test_the_qp_takes_the_curvature_of_entering_steps_from_the_quadratic_form(monkeypatch, layer, method):
    """Where nodes enter the contact the QP takes ``t.C t`` from the quadratic form (uniform, per-node and no
    compliance: a linear layer, Newton's model of a root layer): fewer products than the QP that forms every
    ``C t``, and its answer (both converged, KKT residual on an exact product)."""
    kw = dict(E_star=1.0, force=0.003, step=0.005, extent=0.5, layer=layer, method=method)
    quadratic = InfluenceOperator.quadratic
    calls = []
    monkeypatch.setattr(InfluenceOperator, "quadratic", lambda self, v: calls.append(1) or quadratic(self, v))
    res = bem.solve(_rough_sphere, **kw)
    monkeypatch.setattr(InfluenceOperator, "quadratic", None)
    ref = bem.solve(_rough_sphere, **kw)
    assert res.converged and ref.converged and res.kkt_residual <= 1e-10
    assert len(calls) >= 3 and res.n_matvec <= ref.n_matvec - len(calls) // 2
    assert np.abs(res.p - ref.p).max() <= 1e-8 * ref.p.max()


def test_quadratic_of_large_and_non_finite_values():
    """Scaled before its single-precision transform: no overflow at ``|v| = 1e30`` (where ``v.C v`` is far above the
    single-precision range), the form of ``1e30 v`` is ``1e60`` times that of ``v``; a non-finite ``v`` gives NaN."""
    lat = Lattice.from_extent(0.1, 1.0)
    op = InfluenceOperator(lat, 1.0)
    v = np.random.default_rng(2).random(lat.shape) * lat.mask
    assert op.quadratic(1e30 * v) == pytest.approx(1e60 * op.quadratic(v), rel=1e-6)
    v[2, 3] = np.inf
    assert np.isnan(op.quadratic(v))


def test_quadratic_on_an_array_api_namespace_equals_the_numpy_one():
    """Off NumPy (``array_api_strict``: the gathered batch, the whole-spectrum sum in the namespace) the form is
    NumPy's to single precision, on a box and on the whole region."""
    xs = pytest.importorskip("array_api_strict")
    lat = Lattice.from_extent(0.05, (0.73, 0.81))
    host, device = InfluenceOperator(lat, 1.0), InfluenceOperator(lat, 1.0, device=xs)
    rng = np.random.default_rng(8)
    for v in (np.where(rng.random(lat.shape) < 0.3, rng.standard_normal(lat.shape), 0.0) * lat.mask,
              np.pad(rng.random((7, 9)), ((4, lat.shape[0] - 11), (5, lat.shape[1] - 14)))):
        assert device.quadratic(xs.asarray(v)) == pytest.approx(host.quadratic(v), rel=1e-6)


def test_the_preconditioner_and_the_quadratic_of_a_box_make_its_spectra_once(monkeypatch):
    """The support preconditioner keeps the box's kernel spectra, rounded, for the quadratic form on that box: one
    ``_kernel_spectra`` for both, the quadratic's value that of an operator that made them for itself; on another
    box the quadratic makes its own."""
    lat = Lattice.from_extent(0.05, 1.0)
    rng = np.random.default_rng(11)
    v = np.zeros(lat.shape)
    v[8:20, 9:24] = rng.standard_normal((12, 15))
    v *= lat.mask
    fresh = InfluenceOperator(lat, 1.0).quadratic(v)
    op = InfluenceOperator(lat, 1.0)
    calls = []
    made = op._kernel_spectra
    monkeypatch.setattr(op, "_kernel_spectra", lambda *a, **k: calls.append(a[0]) or made(*a, **k))
    op.preconditioner(lam=0.0, single=True)(v)
    assert len(calls) == 1
    assert op.quadratic(v) == fresh and len(calls) == 1
    w = np.zeros(lat.shape)
    w[2:6, 3:7] = 1.0
    w *= lat.mask
    assert op.quadratic(w) == InfluenceOperator(lat, 1.0).quadratic(w) and len(calls) == 2
