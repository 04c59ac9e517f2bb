"""bem.kernel_convolution.SymmetricKernelConvolution against the dense double sum (any parity, any input box)."""

import math

import numpy as np
import pytest

from bem.lattice import Lattice
from bem.kernel_convolution import SymmetricKernelConvolution


def kernel(x, y, odd_x, odd_y):
    """A smooth kernel of the given parity (not radially symmetric)."""
    f = np.exp(-(x * x + 0.7 * y * y) / 40) * (1 + 0.1 * np.cos(x * y))
    return f * (np.sin(x) if odd_x else 1.0) * (y if odd_y else 1.0)


def dense(lattice, rows, cols, v, odd_x, odd_y):
    J, I = lattice.half_rows, lattice.half_cols
    r = np.arange(rows[0], rows[1] + 1)[:, None]
    q = np.arange(cols[0], cols[1] + 1)[None, :]
    x_in = (q - I + ((r - J) % 2) / 2) + 0 * r
    y_in = (r - J) * math.sqrt(3) / 2 + 0 * q
    xo, yo = lattice.x / lattice.step, lattice.y / lattice.step
    k = kernel(xo[:, :, None, None] - x_in, yo[:, :, None, None] - y_in, odd_x, odd_y)
    return np.einsum("ij,abij->ab", v, k)


@pytest.mark.parametrize("half", [(5, 4), (6, 7), (9, 5)])
@pytest.mark.parametrize("odd_x, odd_y", [(False, False), (False, True), (True, False), (True, True)])
def test_matches_dense_sum_for_every_input_box(half, odd_x, odd_y):
    lat = Lattice(1.0, *half)
    n_rows, n_cols = lat.shape
    rng = np.random.default_rng(7)
    boxes = [((0, n_rows - 1), (0, n_cols - 1)), ((-4, n_rows + 3), (-4, n_cols + 3)),
             ((3, n_rows - 5), (2, n_cols - 4)), ((-3, 5), (6, n_cols + 2)), ((n_rows - 3, n_rows + 2), (-3, 2))]
    for rows, cols in boxes:
        conv = SymmetricKernelConvolution(lat, rows, cols)
        (x0, y0), (x1, y1) = conv.offsets()
        spectrum = conv.spectrum(kernel(x0, y0, odd_x, odd_y), kernel(x1, y1, odd_x, odd_y), odd_x=odd_x, odd_y=odd_y)
        v = rng.standard_normal((rows[1] - rows[0] + 1, cols[1] - cols[0] + 1))
        out = conv.apply([(spectrum, conv.transform(v))])
        ref = dense(lat, rows, cols, v, odd_x, odd_y)
        assert np.max(np.abs(out - ref)) <= 1e-12 * np.max(np.abs(ref))


def test_sum_of_terms_and_batches():
    lat = Lattice(1.0, 6, 5)
    rows, cols = (-2, 9), (1, 11)
    conv = SymmetricKernelConvolution(lat, rows, cols, workers=1)
    (x0, y0), (x1, y1) = conv.offsets()
    rng = np.random.default_rng(3)
    v, w = (rng.standard_normal((rows[1] - rows[0] + 1, cols[1] - cols[0] + 1)) for _ in range(2))
    k0 = np.stack([kernel(x0, y0, False, False), 2 * kernel(x0, y0, False, False)])
    k1 = np.stack([kernel(x1, y1, False, False), 2 * kernel(x1, y1, False, False)])
    spec = conv.spectrum(k0, k1, odd_x=False, odd_y=False)
    out = conv.apply([(spec, conv.transform(v)), (spec, conv.transform(w))])
    ref = dense(lat, rows, cols, v + w, False, False)
    assert np.allclose(out[0], ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    assert np.allclose(out[1], 2 * ref, rtol=0, atol=1e-12 * np.abs(ref).max())
