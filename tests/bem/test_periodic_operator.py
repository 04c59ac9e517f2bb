"""The periodic influence operator: exact image sum of the pyramid template, zero mean, FFT = dense."""

import math

import numpy as np
import pytest

import bem
from bem.periodic import PeriodicCell, PeriodicOperator, periodic_template
from bem.periodic.kernel import periodic_spectra

SQRT3 = math.sqrt(3.0)


def _offsets(n_rows, n_cols):
    r, q = np.meshgrid(np.arange(n_rows), np.arange(n_cols), indexing="ij")
    return q + (r % 2) / 2, r * SQRT3 / 2


def test_periodic_template_does_not_depend_on_the_ewald_split():
    # the split parameter only moves work between the Fourier and the real-space sums; on the 16 x 80 cell the terms
    # of alpha = 0.25 fall each on a mode of its own (no binning), those of 0.4 and 0.6 are binned: both ways agree
    for shape in ((6, 5), (8, 12), (20, 7), (16, 80)):
        ref = periodic_template(*shape, alpha=0.4)
        for alpha in (0.25, 0.6):
            other = periodic_template(*shape, alpha=alpha)
            assert np.abs(other - ref).max() <= 1e-13 * np.abs(ref).max()  # measured <= 4e-16


@pytest.mark.parametrize("shape", [(6, 5), (12, 9), (16, 80), (130, 77)])
def test_periodic_spectra_are_the_ffts_of_the_templates_rows(shape):
    # made from the Fourier sum's terms without the template at the nodes: the real FFTs of its even rows and of its
    # odd rows shifted by a row and a column, the kernels of a parity on itself and of the even rows on the odd ones
    w = periodic_template(*shape)
    even, odd = w[0::2], np.roll(w[1::2], (1, 1), axis=(0, 1))
    expected = np.stack([np.fft.rfft2(even), np.fft.rfft2(odd)])
    got = periodic_spectra(*shape)
    assert got.shape == expected.shape
    assert np.abs(got - expected).max() <= 1e-14 * np.abs(expected).max()  # measured <= 4e-16


def test_periodic_template_is_the_limit_of_the_image_sum_of_the_template():
    """Brute force: sum over the images L in a disc of radius R of w_t(x + L) - w_t(L).

    The disc leaves out the quadrupole tail (sqrt3/2) pi |x|^2 / (2 A R) (the angular mean of
    the second-order term of 1/|x + L|), which is added; the rest converges like R^-2.5.
    """
    n_rows, n_cols = 6, 5
    w = periodic_template(n_rows, n_cols)
    x, y = (v.ravel() for v in _offsets(n_rows, n_cols))
    lx, ly = n_cols, n_rows * SQRT3 / 2
    expected = w.ravel() - w[0, 0]
    errors = []
    for radius in (100.0, 200.0, 400.0):
        m, n = int(radius / lx) + 1, int(radius / ly) + 1
        a, b = np.meshgrid(np.arange(-m, m + 1) * lx, np.arange(-n, n + 1) * ly)
        keep = np.hypot(a, b) <= radius
        a, b = a[keep], b[keep]
        base = bem.template(a, b).sum()
        brute = np.array([bem.template(xi + a, yi + b).sum() - base for xi, yi in zip(x, y)])
        brute += SQRT3 / 2 * math.pi * (x * x + y * y) / (2 * lx * ly * radius)
        errors.append(np.abs(brute - expected).max() / np.abs(w).max())
    orders = [math.log2(errors[k] / errors[k + 1]) for k in range(2)]
    assert min(orders) > 2.2  # measured 2.58, 2.61
    assert errors[-1] < 3e-6  # measured 1.1e-6


@pytest.mark.parametrize("shape", [(6, 5), (8, 12)])
def test_periodic_operator_is_the_dense_symmetric_matrix_with_zero_mean(shape):
    cell = PeriodicCell(0.3, shape[1], shape[0])
    op = PeriodicOperator(cell, 2.0)
    dense = op.dense()
    asymmetry = np.abs(dense - dense.T).max()  # the kernel's own, from its sums: measured 7.5e-15, 8.2e-15 relative
    assert asymmetry <= 1e-13 * np.abs(dense).max()
    # the operator's matrix, column by column: exactly symmetric (its symbol is Hermitian by construction, S_10 the
    # conjugate of S_01) and the kernel's matrix to within that asymmetry
    matrix = np.stack([op.matvec(e.reshape(cell.shape)).ravel() for e in np.eye(cell.n_nodes)], axis=1)
    assert np.abs(matrix - matrix.T).max() <= 1e-15 * np.abs(matrix).max()
    assert np.abs(matrix - dense).max() <= asymmetry + 1e-15 * np.abs(dense).max()
    p = np.random.default_rng(1).random(cell.shape)
    u = op.matvec(p)
    assert np.abs(u.ravel() - dense @ p.ravel()).max() <= 1e-14 * np.abs(u).max() + asymmetry * np.abs(p).sum()
    assert abs(u.mean()) <= 1e-15 * np.abs(u).max()
    eig = np.linalg.eigvalsh(dense)
    assert abs(eig[0]) <= 1e-14 * eig[-1] and eig[1] > 0.01 * eig[-1]  # one zero mode: the constant


def test_periodic_preconditioner_inverts_c_plus_lam_on_zero_mean_vectors():
    cell = PeriodicCell(0.3, 5, 6)
    op = PeriodicOperator(cell, 2.0)
    dense = op.dense()
    r = np.random.default_rng(2).random(cell.shape)
    r -= r.mean()
    for lam in (0.0, 0.1):
        z = op.preconditioner(lam)(r)
        assert np.abs((dense + lam * np.eye(cell.n_nodes)) @ z.ravel() - r.ravel()).max() <= 1e-13


def test_single_precision_preconditioner_symbol_applies_the_preconditioner_to_single_precision():
    op = PeriodicOperator(PeriodicCell(0.1, 12, 8), 2.0)
    r = np.random.default_rng(7).standard_normal(op.lattice.shape)
    for lam in (0.0, 0.4):
        single = op.symbol(lam, inverse=True, single=True)
        assert [a.dtype for a in single.rows()] == [np.float32, np.complex64]
        x = op.spectrum(r.astype(np.float32))
        z = op.brick(op.mix(x, single, out=x))
        exact = op.preconditioner(lam)(r)
        assert np.abs(z - exact).max() <= 1e-5 * np.abs(exact).max()


def test_periodic_template_matches_the_free_template_where_images_are_far():
    # a large cell: near the source the images add a smooth, almost uniform field, so the
    # second difference of W equals that of w_t to the curvature of the image field
    n = 256
    w = periodic_template(n, n)
    free = bem.template(np.array([0.0, 1.0, 2.0]), np.zeros(3))
    second = w[0, 0] - 2 * w[0, 1] + w[0, 2]
    assert second == pytest.approx(free[0] - 2 * free[1] + free[2], rel=1e-5)


def test_periodic_cell_prolong_is_exact_for_linear_fields_and_restrict_takes_every_other_node():
    fine = PeriodicCell(0.1, 64, 32)
    coarse = fine.coarsen()
    assert (coarse.n_cols, coarse.n_rows, coarse.step) == (32, 16, 0.2)

    def field(x, y):
        return 1 + 0.3 * x - 0.7 * y

    values = fine.prolong(field(coarse.x, coarse.y))
    inner = (slice(0, 24), slice(16, 40))  # away from the periodic wrap of the linear field
    assert np.abs(values - field(fine.x, fine.y))[inner].max() < 1e-14
    assert np.array_equal(fine.restrict(field(fine.x, fine.y)), field(coarse.x, coarse.y))


@pytest.mark.parametrize("kwargs, name", [(dict(step=0.1, n_cols=8, n_rows=5), "n_rows"),
                                          (dict(step=0.1, n_cols=2, n_rows=4), "n_cols"),
                                          (dict(step=-1.0, n_cols=8, n_rows=4), "step")])
def test_periodic_cell_refuses_bad_shapes(kwargs, name):
    with pytest.raises(bem.InputError, match=f"^{name} = .* is not allowed"):
        PeriodicCell(**kwargs)


def test_periodic_cell_interpolates_the_pyramid_field_periodically():
    cell = PeriodicCell(0.1, 12, 8)
    values = np.random.default_rng(4).random(cell.shape)
    lx, ly = cell.size
    assert np.allclose(cell.interpolate(values, cell.x, cell.y), values, rtol=0, atol=1e-14)
    assert np.allclose(cell.interpolate(values, cell.x + 2 * lx, cell.y - ly), values, rtol=0, atol=1e-13)
    # midpoint of the edge (along e2) from node (3, 1) to node (4, 2): the mean of its ends
    mid = cell.interpolate(values, 0.5 * (cell.x[1, 3] + cell.x[2, 4]), 0.5 * (cell.y[1, 3] + cell.y[2, 4]))
    assert mid == pytest.approx(0.5 * (values[1, 3] + values[2, 4]), abs=1e-14)
    # and the pyramid field agrees with the prolongation, which takes the same edge midpoints
    fine = PeriodicCell(0.05, 24, 16)
    assert np.allclose(cell.interpolate(values, fine.x, fine.y), fine.prolong(values), rtol=0, atol=1e-14)


def test_periodic_cell_from_size_takes_the_nearest_cell_with_an_even_number_of_rows():
    cell = PeriodicCell.from_size(0.1, (1.0, 0.9))
    assert (cell.n_cols, cell.n_rows) == (10, 10)  # 0.9 / (0.1 sqrt3/2) = 10.4 rows
    assert cell.size == pytest.approx((1.0, 10 * 0.1 * SQRT3 / 2))
    assert cell.area == pytest.approx(cell.n_nodes * cell.node_area)


def test_the_operators_keep_the_last_symbols_and_a_large_cell_lets_the_coarser_ones_go(monkeypatch):
    """The packed symbols of the last cells are kept (the same arrays for a second operator of a cell, the oldest let
    go beyond the limit); nested iteration onto a cell whose product is above ``bem.heap.RELEASE_ABOVE`` lets the
    coarser cells' symbols go before the finer level (here at every size), with the same solution bit for bit."""
    import bem.periodic.influence as influence

    monkeypatch.setattr(influence, "_SYMBOLS", {})
    monkeypatch.setattr(influence, "_SYMBOLS_KEPT", 3)
    cells = [PeriodicCell(1.0 / n, n, n) for n in (8, 16, 32, 64)]
    ops = [PeriodicOperator(cell, 1.0) for cell in cells[:3]]
    assert all(a is b for a, b in zip(PeriodicOperator(cells[0], 1.0)._symbol, ops[0]._symbol))
    PeriodicOperator(cells[3], 1.0)  # the fourth: the least recently used (16 x 16) goes
    assert {key[0] for key in influence._SYMBOLS} == {8, 32, 64}
    influence.forget_symbols(below=32 * 32)
    assert {key[0] for key in influence._SYMBOLS} == {32, 64}

    cell = PeriodicCell(1.0 / 256, 256, 256)
    h = 0.01 * (1 - np.cos(2 * np.pi * cell.x) * np.cos(2 * np.pi * cell.y))
    influence._SYMBOLS.clear()
    monkeypatch.setattr(influence, "_SYMBOLS_KEPT", 8)
    kept = bem.solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=0.005)
    all_levels = {key[0] for key in influence._SYMBOLS}
    influence._SYMBOLS.clear()
    monkeypatch.setattr("bem.heap.RELEASE_ABOVE", 0)
    forgot = bem.solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=0.005)
    assert len(all_levels) >= 3 and {key[0] for key in influence._SYMBOLS} == {256}
    assert kept.converged and forgot.converged and np.array_equal(kept.p, forgot.p)
