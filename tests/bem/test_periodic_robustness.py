"""The periodic QP converges from every feasible start: a rough cell that once stalled, and a seeded
study over loads and lattice cells, each answer checked by bem.kkt on an independently computed C p."""

from __future__ import annotations

import math

import numpy as np
import pytest

import bem
from bem.kkt import kkt_residual
from bem.rough import to_lattice


def _surface(n=512, seed=1, hurst=0.8, rolloff=4, cutoff=128, slope=0.1):
    """Self-affine heights on an n x n grid of the unit cell: PSD q^(-2(1+H)), flat below the roll-off
    wave number 2 pi rolloff, zero above 2 pi cutoff, random phases, scaled to the rms slope."""
    rng = np.random.default_rng(seed)
    k = np.fft.fftfreq(n, 1.0 / n)
    kx, ky = np.meshgrid(k, k, indexing="ij")
    q = 2 * math.pi * np.hypot(kx, ky)
    q_r, q_s = 2 * math.pi * rolloff, 2 * math.pi * cutoff
    psd = np.where(q < q_r, q_r, np.where(q > 0, q, 1.0)) ** (-2 * (1 + hurst))
    psd[(q > q_s) | (q == 0)] = 0.0
    spectrum = np.sqrt(psd) * np.exp(2j * math.pi * rng.random(q.shape))
    z = np.fft.ifft2(spectrum).real
    gx = np.fft.ifft2(2j * math.pi * kx * np.fft.fft2(z)).real
    gy = np.fft.ifft2(2j * math.pi * ky * np.fft.fft2(z)).real
    return z * (slope / math.sqrt(np.mean(gx**2 + gy**2)))


def _check(res, h, rtol):
    """The result converged to rtol by the result's own report AND by bem.kkt on C p recomputed here."""
    assert res.status == "converged", res.message
    op = bem.PeriodicOperator(res.lattice, res.E_star)
    p = res.p.reshape(h.shape)
    u = op.matvec(p)
    g = u + h - res.approach
    kkt = kkt_residual(p.ravel(), g.ravel(), displacement_scale=float(np.abs(u).max()), force=res.force,
                       node_area=res.lattice.node_area)
    assert kkt <= 10 * rtol
    assert res.kkt_residual <= rtol


@pytest.mark.slow
@pytest.mark.parametrize("pbar", [0.03, 0.04])
def test_the_rough_cell_whose_nested_start_stalled_converges(pbar):
    """672 x 776 cell of the unit square, default options (nested iteration): the QP from the coarse
    cell's answer cycled at a KKT residual of about 5e-2 (contact fraction 0.548 at 0.03 E*)."""
    lh = to_lattice(_surface(), (1.0, 1.0), 672)
    h = lh.gap()
    res = bem.solve_periodic(h, step=lh.step, E_star=1.0, mean_pressure=pbar, rtol=1e-10, maxiter=300)
    _check(res, h, 1e-10)


def robustness_study(loads, n_cols_list, *, rtol=1e-10, seed=1):
    """Solve the seeded surface at every load [E*] on every lattice cell (``n_cols`` columns of the
    unit cell): a list of ``(n_cols, load, result, gap)``."""
    z = _surface(n=128, seed=seed, cutoff=32)
    out = []
    for n_cols in n_cols_list:
        lh = to_lattice(z, (1.0, 0.83), n_cols)
        h = lh.gap()
        for load in loads:
            out.append((n_cols, load, bem.solve_periodic(h, step=lh.step, E_star=1.0, mean_pressure=load,
                                                         rtol=rtol), h))
    return out


def test_robustness_over_loads_and_lattice_cells():
    """Odd and even, non-square cells (with and without nested levels), loads 0.005-0.2 E*."""
    for n_cols, load, res, h in robustness_study([0.005, 0.03, 0.2], [48, 61, 96]):
        _check(res, h, 1e-10)
