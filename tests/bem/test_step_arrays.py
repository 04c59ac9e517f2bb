"""The arrays the periodic cell's constrained CG reuses from step to step (:class:`bem.periodic.qp_parts.StepArrays`)
and the transforms of :class:`bem.periodic.PeriodicOperator` into given arrays (``out``): the numbers of the
transforms into new arrays, bit for bit, and a solve that makes its products in one array of the cell rather than
in a new array at every product.
"""

import numpy as np
import pytest

import bem.periodic.influence as influence
from bem.backend import get_backend
from bem.errors import InputError
from bem.periodic import PeriodicCell, PeriodicOperator
from bem.periodic.qp import solve_periodic_qp
from bem.periodic.qp_parts import StepArrays

from .test_periodic_qp import _self_affine


@pytest.mark.parametrize("n_rows, n_cols", [(16, 12), (16, 13), (2, 5)])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_transforms_into_given_arrays_are_the_transforms_into_new_ones(n_rows, n_cols, dtype):
    op = PeriodicOperator(PeriodicCell(0.1, n_cols, n_rows), 2.0)
    v = np.random.default_rng(3).standard_normal((n_rows, n_cols)).astype(dtype)
    keep = v.copy()
    new = op.spectrum(v)
    buf = np.empty_like(new)
    got = op.spectrum(v, out=buf)
    assert got is buf
    np.testing.assert_array_equal(got, new)
    np.testing.assert_array_equal(v, keep)  # the input is not modified
    back = op.brick(new)
    out = np.empty((n_rows, n_cols), dtype=dtype)
    into = op.brick(new.copy(), overwrite=True, out=out)
    assert np.shares_memory(into, out) and into.shape == (n_rows, n_cols)
    np.testing.assert_array_equal(into, back)
    np.testing.assert_allclose(back, v, rtol=0, atol=1e-5 if dtype == np.float32 else 1e-12)


@pytest.mark.parametrize("bad", [
    np.empty((8, 2, 7), dtype=np.complex64),  # the wrong precision for a float64 input
    np.empty((8, 2, 6), dtype=np.complex128),  # the wrong shape
    np.empty((8, 2, 14), dtype=np.complex128)[:, :, ::2],  # not contiguous
    [0.0],
])
def test_a_transform_into_an_unfit_array_is_refused_naming_out(bad):
    op = PeriodicOperator(PeriodicCell(0.1, 12, 16), 2.0)
    rule = r"it must be a C-contiguous NumPy array of shape \(8, 2, 7\) and dtype complex128\.$"
    with pytest.raises(InputError, match=r"^out = '(ndarray|list) of shape .*' is not allowed: " + rule):
        op.spectrum(np.zeros((16, 12)), out=bad)
    with pytest.raises(InputError, match=r"^out = .*float32' is not allowed: .* shape \(16, 12\) and dtype float64\.$"):
        op.brick(op.spectrum(np.zeros((16, 12))), out=np.empty((16, 12), dtype=np.float32))


@pytest.mark.parametrize("shape", [(16, 12), (16, 13), (2, 1), (64, 33)])
def test_step_arrays_hold_a_double_spectrum_or_a_single_spectrum_beside_a_single_brick(shape):
    work = StepArrays(get_backend("cpu"), shape)
    spec_shape = (shape[0] // 2, 2, shape[1] // 2 + 1)
    s64, s128, b32 = work.spectrum(np.complex64), work.spectrum(np.complex128), work.brick32()
    assert s64.shape == s128.shape == spec_shape and b32.shape == shape and b32.dtype == np.float32
    assert s64.flags.c_contiguous and s128.flags.c_contiguous and b32.flags.c_contiguous
    assert not np.shares_memory(s64, b32)  # used at once: the preconditioner's spectrum and its brick,
    first_b32, second_s64 = work.brick32(second=False), work.spectrum(np.complex64, second=True)
    assert not np.shares_memory(s64, second_s64) and not np.shares_memory(first_b32, second_s64)  # a product, its brick
    assert np.shares_memory(s64, first_b32) and np.shares_memory(b32, second_s64)
    assert second_s64.shape == spec_shape and second_s64.flags.c_contiguous and first_b32.shape == shape
    assert np.shares_memory(s128, s64) and np.shares_memory(s128, b32)  # one array of the cell in all
    assert work.bytes.nbytes == s128.nbytes
    v = np.random.default_rng(1).standard_normal(shape)
    one = work.single(v)
    assert one is not v and np.shares_memory(one, b32)
    np.testing.assert_array_equal(one, v.astype(np.float32))


def test_step_arrays_off_numpy_give_new_arrays():
    xp = pytest.importorskip("array_api_strict")
    bk = get_backend(xp)
    work = StepArrays(bk, (4, 6))
    assert work.spectrum(np.complex64) is None and work.brick32() is None and work.spectrum(np.complex128) is None
    v = xp.ones((4, 6), dtype=xp.float64)
    assert work.single(v).dtype == xp.float32


@pytest.mark.parametrize("per_node", [False, True])
def test_a_periodic_qp_makes_its_products_in_its_step_arrays(per_node, monkeypatch):
    """Every transform of a step writes into an array the solve holds: the new arrays of the cell's size are the
    first product, the displacement made again at the switch to double precision, and ``M 1`` of a compliance per
    node, however many iterations the solve takes."""
    cell = PeriodicCell(1.0 / 128, 128, 128)
    op = PeriodicOperator(cell, 1.0)
    lam = op.diagonal * np.random.default_rng(2).uniform(0.2, 2.0, cell.shape) if per_node else 0.0
    new = []
    checked = influence._checked_out

    def spy(out, shape, dtype):
        new.append(out is None)
        return checked(out, shape, dtype)

    monkeypatch.setattr(influence, "_checked_out", spy)
    res = solve_periodic_qp(op, _self_affine(cell), force=0.03 * cell.area, lam=lam, rtol=1e-10)
    assert res.converged and res.iterations >= 20
    assert len(new) > 4 * res.iterations  # spectra and bricks of every step
    # the first product (spectrum and brick), the brick of the switch to double precision, M 1's brick per node
    assert sum(new) <= (4 if per_node else 3)


@pytest.mark.parametrize("shape", [(16, 12), (16, 13), (2, 5)])
def test_a_float64_brick_fits_in_the_bytes_of_a_complex128_spectrum(shape):
    """``D p`` and the final ``C p`` of the QP go into the step's bytes where no spectrum is held: a float64 brick
    array of the cell's shape over them (the bytes of a complex128 spectrum hold at least the cell's nodes)."""
    work = StepArrays(get_backend("cpu"), shape)
    brick = work.brick64()
    assert brick.shape == shape and brick.dtype == np.float64 and brick.flags.c_contiguous
    assert np.shares_memory(brick, work.bytes) and brick.nbytes <= work.bytes.nbytes
    brick[...] = np.arange(np.prod(shape)).reshape(shape)
    np.testing.assert_array_equal(work.bytes[: brick.nbytes].view(np.float64), np.arange(np.prod(shape)))
    assert StepArrays(get_backend(pytest.importorskip("array_api_strict")), shape).brick64() is None
