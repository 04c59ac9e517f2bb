"""Nested levels solved on the window of the nodes whose gap can close (bem.lattice.LatticeWindow)."""

import importlib

import numpy as np
import pytest

import bem
from bem import layers
from bem.gaps import Paraboloid
from bem.lattice import Lattice
from bem.operator import InfluenceOperator

solve_module = importlib.import_module("bem.solve")
windows_module = importlib.import_module("bem.windows")


@pytest.mark.parametrize("rows, cols", [((3, 20), (5, 30)), ((4, 21), (6, 41)), ((0, 35), (0, 41)), ((1, 3), (0, 3)),
                                        ((5, 35), (1, 41))])
def test_window_operator_is_the_parent_operator_on_the_window(rows, cols):
    lat = Lattice.from_extent(0.1, (2.0, 1.7))
    win = lat.window(rows, cols)
    op, op_w = InfluenceOperator(lat, 2.0), InfluenceOperator(win, 2.0)
    p = np.random.default_rng(3).random(win.shape) * win.mask
    ref = op.matvec(win.embed(p))[win.index]
    got = op_w.matvec(p)
    assert np.abs(got - ref).max() <= 1e-14 * np.abs(ref).max()
    assert np.abs(op_w.dense() @ p[win.mask] - got[win.mask]).max() <= 1e-13 * np.abs(ref).max()
    assert not got[~win.mask].any()


def test_window_refuses_a_block_outside_the_lattice():
    lat = Lattice.from_extent(0.1, 1.0)
    with pytest.raises(bem.InputError, match="rows = "):
        lat.window((0, 1), (0, 5))
    with pytest.raises(bem.InputError, match="rows = "):
        lat.window((0, 5), (0, lat.shape[1] + 1))


def _root(**kw):
    return bem.solve(Paraboloid(1.0), E_star=1.0, force=1e-3, step=0.003, extent=0.3, layer=layers.Root(0.04),
                     **kw)


@pytest.mark.parametrize("control", ["force", "approach"])
@pytest.mark.parametrize("layer", [None, layers.Root(0.04)])
def test_window_gives_the_full_lattice_solution(monkeypatch, control, layer):
    load = {"force": 1e-3} if control == "force" else {"approach": 0.012}
    kw = dict(E_star=1.0, step=0.003, extent=0.3, layer=layer, **load)
    windowed = bem.solve(Paraboloid(1.0), **kw)
    monkeypatch.setattr(windows_module, "_WINDOW_UP_TO", 0.0)  # no window
    full = bem.solve(Paraboloid(1.0), **kw)
    assert windowed.converged and full.converged
    assert windowed.kkt_residual <= 1e-10 and windowed.p.shape == full.p.shape
    assert np.abs(windowed.p - full.p).max() <= 1e-8 * full.p.max()
    assert windowed.approach == pytest.approx(full.approach, rel=1e-9)


def test_window_is_used_and_its_solution_checked_outside(monkeypatch):
    used, calls = [], []
    run = solve_module._run

    def spy(solver, op, *args):
        used.append(op.lattice)
        return run(solver, op, *args)

    monkeypatch.setattr(solve_module, "_run", spy)
    res = _root(callback=lambda k, p: calls.append(p.shape))
    assert res.converged
    assert type(used[-1]).__name__ == "LatticeWindow" and used[-1].n_nodes < 0.5 * res.p.size
    assert set(calls) == {res.lattice.shape}  # the callback sees the full lattice
    # a window that misses nodes of the contact is detected, and the level solved on the full lattice
    used.clear()
    monkeypatch.setattr(windows_module, "_WINDOW_MARGIN", -0.6)
    small = _root()
    assert small.converged and small.kkt_residual <= 1e-10
    assert type(used[-1]).__name__ == "Lattice" and type(used[-2]).__name__ == "LatticeWindow"
    assert np.abs(small.p - res.p).max() <= 1e-8 * res.p.max()


def test_recorded_iterates_are_on_the_full_lattice():
    res = _root(record=True)
    assert len(res.history["p"]) == res.iterations + 1  # Newton records its start and every step
    assert all(p.shape == res.p.shape for p in res.history["p"])
    np.testing.assert_allclose(res.history["p"][-1], res.p)


@pytest.mark.parametrize("layer", [None, layers.Power(0.02, 0.3)])
def test_window_off_centre_with_an_offset_gap(monkeypatch, layer):
    """A sphere off the centre of an elongated region, the gap offset by a constant."""

    def gap(x, y):
        return 0.01 + ((x - 0.17) ** 2 + (y + 0.05) ** 2) / 2.0

    kw = dict(E_star=1.0, force=1e-3, step=0.003, extent=(0.45, 0.25), layer=layer)
    windowed = bem.solve(gap, **kw)
    monkeypatch.setattr(windows_module, "_WINDOW_UP_TO", 0.0)
    full = bem.solve(gap, **kw)
    assert windowed.converged and windowed.kkt_residual <= 1e-10
    assert np.abs(windowed.p - full.p).max() <= 1e-8 * full.p.max()


def test_qp_window_fallback(monkeypatch):
    monkeypatch.setattr(windows_module, "_WINDOW_MARGIN", -0.6)
    small = bem.solve(Paraboloid(1.0), E_star=1.0, force=1e-3, step=0.003, extent=0.3)
    monkeypatch.setattr(windows_module, "_WINDOW_UP_TO", 0.0)
    full = bem.solve(Paraboloid(1.0), E_star=1.0, force=1e-3, step=0.003, extent=0.3)
    assert small.converged and small.kkt_residual <= 1e-10
    assert np.abs(small.p - full.p).max() <= 1e-8 * full.p.max()


def test_start_window_is_the_padded_box_of_the_starts_contact(monkeypatch):
    lat = Lattice.from_extent(0.1, 1.0)
    x0 = np.zeros(lat.shape)
    assert windows_module.start_window(lat, None) is None and windows_module.start_window(lat, x0) is None
    x0[6:9, 4:7] = 1.0
    before = x0.copy()
    win = windows_module.start_window(lat, x0)
    pad = windows_module._START_PAD
    assert (win.rows, win.cols) == ((6 - pad, 9 + pad), (4 - pad, 7 + pad))
    np.testing.assert_array_equal(x0, before)  # the start is not modified
    # with the coarser product's estimate of the gap, also around the nodes it closes (here one, below the box)
    h, u = np.full(lat.shape, 1.0), np.zeros(lat.shape)
    h[14, 5] = 0.2
    grown = windows_module.start_window(lat, x0, h, u, 0.5)
    assert (grown.rows, grown.cols) == ((6 - pad, 15 + pad), (4 - pad, 7 + pad))
    assert windows_module.start_window(lat, x0, h, u, 0.1) is not None and (
        windows_module.start_window(lat, x0, h, u, 0.1).rows == win.rows)
    x0[0, 0] = x0[-1, -1] = 1.0  # a box of the whole lattice is not worth a window
    assert windows_module.start_window(lat, x0) is None


def _wavy(x, y):
    """A sphere of radius 1 with a lattice of bumps 0.004 high: the gap dips below the approach over most of the
    region, and the window of the start's contact is the smaller one."""
    return (x * x + y * y) / 2.0 - 0.002 * (1 + np.cos(2 * np.pi * x / 0.03) * np.cos(2 * np.pi * y / 0.03))


def _spied(monkeypatch):
    used, products = [], []
    run, matvec = solve_module._run, InfluenceOperator.matvec

    def spy(solver, op, *args):
        used.append(op.lattice)
        return run(solver, op, *args)

    def counted(self, p, **kw):
        products.append(self.lattice)
        return matvec(self, p, **kw)

    monkeypatch.setattr(solve_module, "_run", spy)
    monkeypatch.setattr(InfluenceOperator, "matvec", counted)
    return used, products


@pytest.mark.parametrize("layer", [None, layers.Root(0.005)])
def test_start_window_gives_the_full_lattice_solution(monkeypatch, layer):
    kw = dict(E_star=1.0, force=1e-3, step=0.002, extent=0.2, layer=layer)
    used, products = _spied(monkeypatch)
    calls = []
    windowed = bem.solve(_wavy, callback=lambda k, p: calls.append(p.shape), **kw)
    finest = windowed.lattice
    h = bem.HalfSpaceRegion(0.002, 0.2).nodal_gap(_wavy, finest)
    assert windows_module.candidate_window(finest, h, windowed.approach) is None  # h < approach too widely
    assert type(used[-1]).__name__ == "LatticeWindow" and used[-1].n_nodes < 0.5 * windowed.p.size
    assert set(calls) == {finest.shape}  # the callback sees the full lattice
    # the full lattice's one product after the window's solve checks it and is the result's
    assert sum(lat is finest for lat in products) == 1
    monkeypatch.setattr(windows_module, "_WINDOW_UP_TO", 0.0)  # no window
    full = bem.solve(_wavy, **kw)
    assert windowed.converged and full.converged and windowed.kkt_residual <= 1e-10
    assert np.abs(windowed.p - full.p).max() <= 1e-8 * full.p.max()
    assert windowed.approach == pytest.approx(full.approach, rel=1e-9)
    np.testing.assert_allclose(windowed.displacement, full.displacement, rtol=0, atol=1e-9 * full.displacement.max())


@pytest.mark.parametrize("case", ["grown", "full", "unchecked"])
def test_start_window_that_misses_the_contact_is_solved_again(monkeypatch, case):
    kw = dict(E_star=1.0, force=1e-3, step=0.002, extent=0.2)
    reference = bem.solve(_wavy, **kw)
    used, _ = _spied(monkeypatch)
    box, box_window = windows_module._box, windows_module._box_window
    # every start window cut 6 nodes inside the box of the start's contact
    monkeypatch.setattr(windows_module, "start_window", lambda lat, x0, *estimate: None if x0 is None else box_window(
        lat, box(lat, lambda lo, hi: x0[lo:hi] > 0), -6))
    if case == "full":  # one window tried, then the full lattice
        monkeypatch.setattr(windows_module, "_START_TRIES", 1)
    if case == "unchecked":  # planted fault: the window's solution taken unchecked
        monkeypatch.setattr(windows_module, "_closing_outside", lambda *args: None)
    res = bem.solve(_wavy, **kw)
    kinds = [type(lat).__name__ for lat in used]
    if case == "unchecked":  # the full lattice's KKT residual shows the nodes the window left out
        assert kinds[-1] == "LatticeWindow" and res.kkt_residual > 1e-4
        return
    assert res.converged and res.kkt_residual <= 1e-10
    assert np.abs(res.p - reference.p).max() <= 1e-8 * reference.p.max()
    if case == "full":
        assert kinds[-2:] == ["LatticeWindow", "Lattice"]
    else:  # the finest level's window grown over the nodes it missed: a larger window, not the full lattice
        assert kinds[-2:] == ["LatticeWindow", "LatticeWindow"] and used[-1].n_nodes > used[-2].n_nodes
        assert used[-1].n_nodes < 0.6 * res.p.size


@pytest.mark.parametrize("estimate", [True, False])
def test_start_window_takes_in_what_the_coarser_product_closes(monkeypatch, estimate):
    """A bump one node wide just outside the contact, between the nodes of the coarser lattices (which do not see it):
    with the coarser level's product prolonged, the finest level's first window takes it in; without that estimate
    (planted) the window misses it and is grown over it."""
    kw = dict(E_star=1.0, force=1e-3, step=0.001, extent=0.2)  # three levels: the middle one hands its product over
    fine = bem.solve(Paraboloid(1.0), **kw).lattice
    coarse = fine.coarsen()
    x, y = fine.x[fine.mask], fine.y[fine.mask]
    cx, cy = coarse.x[coarse.mask], coarse.y[coarse.mask]
    near = np.flatnonzero((np.abs(np.hypot(x, y) - 0.128) < 0.002) & (np.abs(y) < 0.003))
    xb, yb = next((x[i], y[i]) for i in near if np.min(np.hypot(cx - x[i], cy - y[i])) > 0.9 * kw["step"])

    def bumpy(x, y):
        return (x * x + y * y) / 2.0 - 0.004 * np.exp(-((x - xb) ** 2 + (y - yb) ** 2) / (2 * (0.25 * kw["step"]) ** 2))

    found, closing = [], windows_module._closing_outside

    def recorded(lat, *args):  # the nodes each check found closing outside its window (None: none)
        found.append(closing(lat, *args))
        return found[-1]

    monkeypatch.setattr(windows_module, "_closing_outside", recorded)
    if not estimate:
        start = windows_module.start_window
        monkeypatch.setattr(windows_module, "start_window", lambda lat, x0, *args: start(lat, x0))
    res = bem.solve(bumpy, **kw)
    assert res.converged and res.kkt_residual <= 1e-10
    assert res.p[np.argmin(np.hypot(res.x - xb, res.y - yb))] > 0  # the bump is in contact
    if estimate:  # every first window held the contact
        assert found and all(f is None for f in found)
    else:  # the finest level's first window missed the bump, the grown one held it
        assert found[-2] is not None and found[-1] is None
