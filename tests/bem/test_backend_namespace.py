"""The solvers run unchanged on a strict array API namespace and give the NumPy answer.

``array_api_strict`` implements the standard and nothing else; its arrays are refused by NumPy
here (``__array__`` raises), so a solve that converted an array to NumPy behind the back of the
backend would fail instead of falling back silently. The callbacks see every iterate in the
strict namespace.
"""


import numpy as np
import pytest

import bem
import bem.backend
from bem import layers
from bem.gaps import Paraboloid
from bem.periodic import PeriodicCell, solve_periodic

from .fourier_qp_cases import CASES, COATING, compare, rough

xs = pytest.importorskip("array_api_strict")

KW = dict(E_star=1.0, force=1.0, step=0.05, extent=1.2)


@pytest.fixture
def strict(monkeypatch):
    """``array_api_strict``, with any conversion of its arrays to NumPy arrays an error."""
    from array_api_strict._array_object import Array

    def refuse(self, *args, **kwargs):
        raise AssertionError("an array_api_strict array was converted to NumPy")

    monkeypatch.setattr(Array, "__array__", refuse)
    return xs


def _iterates(device):
    seen = []
    return seen, lambda k, p: seen.append(type(p).__module__.split(".")[0])


def _same(a, b, tol=1e-12):
    assert a.converged and b.converged
    assert a.method == b.method
    assert isinstance(b.p, np.ndarray) and isinstance(b.displacement, np.ndarray)
    assert np.abs(b.p - a.p).max() <= tol * a.p.max()
    assert abs(b.approach - a.approach) <= tol * abs(a.approach)
    assert b.kkt_residual <= 1e-10


@pytest.mark.parametrize("layer, method", [(None, "kalker"), (layers.Root(0.05), "newton")],
                         ids=["hertz_kalker_qp", "root_layer_newton"])
def test_strict_namespace_solve_equals_the_numpy_solve(strict, layer, method):
    ref = bem.solve(Paraboloid(1.0), layer=layer, method=method, **KW)
    seen, callback = _iterates(strict)
    res = bem.solve(Paraboloid(1.0), layer=layer, method=method, device=strict, callback=callback, **KW)
    _same(ref, res)
    assert seen and set(seen) == {"array_api_strict"}
    assert (res.n_matvec, res.n_transforms) == (ref.n_matvec, ref.n_transforms)  # the device's transforms counted


def _laws():
    return {"linear": layers.Linear(0.02), "power": layers.Power(0.1, 2.0), "bilinear": layers.Bilinear(0.02, 0.01, 0.3),
            "tabulated": layers.Tabulated(np.linspace(0, 4, 41), 0.05 * np.sqrt(np.linspace(0, 4, 41)))}


@pytest.mark.parametrize("method, law", [("newton", "tabulated"), ("newton", "bilinear"),
                                         ("augmented_gap", "linear"), ("variable_compliance", "power"),
                                         ("variable_compliance", "tabulated")])
def test_every_solver_and_a_host_only_law_run_on_the_strict_namespace(strict, method, law):
    layer = _laws()[law]
    kw = dict(KW, step=0.1, nested=False)
    ref = bem.solve(Paraboloid(1.0), layer=layer, method=method, **kw)
    seen, callback = _iterates(strict)
    res = bem.solve(Paraboloid(1.0), layer=layer, method=method, device=strict, callback=callback, **kw)
    _same(ref, res, tol=1e-10)
    assert set(seen) == {"array_api_strict"}


@pytest.mark.parametrize("layer, method", [(None, "kalker"), (layers.Root(0.2), "newton")],
                         ids=["periodic_kalker_qp", "periodic_root_newton"])
def test_strict_namespace_periodic_solve_equals_the_numpy_solve(strict, layer, method):
    cell = PeriodicCell(1.0 / 32, 32, 32)
    h = rough(cell)
    # the QP in the Fourier basis (bem.periodic.qp) on both, solved far enough (KKT 1e-13) for the answers
    # to agree to 1e-12 (the iteration counts may differ by one at the round-off of single-precision transforms)
    kw = dict(step=cell.step, E_star=1.0, mean_pressure=2.0, layer=layer, method=method, rtol=1e-13)
    ref = solve_periodic(h, **kw)
    seen, callback = _iterates(strict)
    res = solve_periodic(h, device=strict, callback=callback, **kw)
    assert 0.05 < ref.contact_fraction < 0.95
    _same(ref, res)
    assert set(seen) == {"array_api_strict"}
    # the device's transforms counted as NumPy's, where the two made the same products
    assert res.n_transforms == ref.n_transforms or res.n_matvec != ref.n_matvec


@pytest.mark.parametrize("case", ["hardness", "coating"])
def test_hardness_and_coatings_run_on_the_strict_namespace(strict, case):
    """The hardness cap (bounded step) and a coated body (coated influence coefficients, coated
    cell kernel) on the strict namespace: the NumPy answer, on the half-space and on the cell."""
    extra = (dict(E_star=1.0, hardness=0.5) if case == "hardness"
             else dict(COATING, coating1=bem.Coating(0.2, 3.0, 0.3)))
    kw = {k: v for k, v in KW.items() if k != "E_star"} | extra
    if case == "coating":
        # the single-precision products of NumPy and of the namespace differ by 1e-7 from the first step on, and
        # the directions kept when nodes enter the contact carry that on: solved to KKT 1e-14, the answers agree
        # to 1e-12 as answers, not as one path (at the default 1e-10 they differ by 1.4e-12 of p_max)
        kw["rtol"] = 1e-14
    ref = bem.solve(Paraboloid(1.0), **kw)
    seen, callback = _iterates(strict)
    _same(ref, bem.solve(Paraboloid(1.0), device=strict, callback=callback, **kw))
    assert set(seen) == {"array_api_strict"}
    if case == "hardness":
        assert 0 < ref.plastic_area
    cell = PeriodicCell(1.0 / 32, 32, 32)
    kw = dict(step=cell.step, mean_pressure=2.0, rtol=1e-13) | (dict(E_star=1.0, hardness=4.0) if case == "hardness"
                                                                else extra)
    ref = solve_periodic(rough(cell), **kw)
    seen, callback = _iterates(strict)
    _same(ref, solve_periodic(rough(cell), device=strict, callback=callback, **kw))
    assert set(seen) == {"array_api_strict"}
    if case == "hardness":
        assert 0 < ref.plastic_fraction < ref.contact_fraction


def test_an_unknown_device_is_refused():
    with pytest.raises(bem.InputError, match="device = 'tpu' is not allowed: .*'cpu', 'cuda' or an array API"):
        bem.solve(Paraboloid(1.0), device="tpu", **KW)


def test_cuda_without_cupy_or_a_device_is_refused():
    try:
        bem.backend.get_backend("cuda")
    except bem.InputError:
        pass
    else:
        pytest.skip("CuPy and a CUDA device are present")
    with pytest.raises(bem.InputError, match="device = 'cuda' is not allowed: CuPy (is not installed|sees no CUDA device)"):
        bem.solve(Paraboloid(1.0), device="cuda", **KW)


def test_strict_namespace_subsurface_stress_equals_the_numpy_stress(strict):
    res = bem.solve(Paraboloid(1.0), **KW)
    z = np.linspace(0.0, 0.3, 5)  # depths below one step (near-field correction) and beyond
    ref = bem.subsurface_stress(res, z, nu=0.3)
    out = bem.subsurface_stress(res, z, nu=0.3, device=strict)
    assert isinstance(out.sigma, np.ndarray)
    assert np.abs(out.sigma - ref.sigma).max() <= 1e-12 * np.abs(ref.sigma).max()
    assert out.max_von_mises == pytest.approx(ref.max_von_mises, rel=1e-12)


def test_the_flat_index_path_of_cupy_emulated_on_numpy_equals_the_numpy_solve():
    """CuPy's code path (flat-index selections, the namespace's own FFTs), run by array_api_compat.numpy."""
    compat = pytest.importorskip("array_api_compat.numpy")
    from bem.backend import Backend

    device = Backend(compat, "compat-numpy", flat_indices=True)
    for layer, method in ((None, "kalker"), (layers.Root(0.05), "newton"), (_laws()["tabulated"], "variable_compliance")):
        ref = bem.solve(Paraboloid(1.0), layer=layer, method=method, **KW)
        _same(ref, bem.solve(Paraboloid(1.0), layer=layer, method=method, device=device, **KW), tol=1e-10)
    cell = PeriodicCell(1.0 / 32, 32, 32)
    kw = dict(step=cell.step, E_star=1.0, mean_pressure=2.0, layer=layers.Root(0.2), rtol=1e-13)  # as above
    _same(solve_periodic(rough(cell), **kw), solve_periodic(rough(cell), device=device, **kw))


@pytest.mark.parametrize("domain", ["region", "cell"])
@pytest.mark.parametrize("layer, method", [(None, "kalker"), (layers.Root(0.05), "newton")])
def test_the_iterations_move_no_array_to_the_host(strict, monkeypatch, layer, method, domain):
    """Device arrays reach the host only through bem.backend.to_host (DLPack): the solution, its
    displacement and the result's product, whatever the number of iterations (on the cell: of the
    QP in the Fourier basis)."""
    copies = []
    from_dlpack = np.from_dlpack

    def counted(x, *args, **kwargs):
        copies.append(x.shape)
        return from_dlpack(x, *args, **kwargs)

    monkeypatch.setattr(np, "from_dlpack", counted)
    if domain == "region":
        res = bem.solve(Paraboloid(1.0), layer=layer, method=method, device=strict, nested=False, **KW)
    else:
        cell = PeriodicCell(1.0 / 32, 32, 32)
        res = solve_periodic(rough(cell), step=cell.step, E_star=1.0, mean_pressure=2.0, layer=layer, method=method,
                             device=strict, nested=False)
    assert res.converged and res.iterations > 3
    assert len(copies) == 3



@pytest.mark.parametrize("case", CASES)
def test_the_fourier_qp_takes_the_numpy_path_on_the_strict_namespace(strict, monkeypatch, case):
    """The periodic cell's QP in the Fourier basis (bem.periodic.qp) on the strict namespace: the iteration
    of NumPy, step by step, to the same count, and its answer (tests/bem/fourier_qp_cases.py)."""
    compare(case, strict, xs.asarray, monkeypatch)


@pytest.mark.parametrize("case", CASES)
def test_the_fourier_qp_takes_the_numpy_path_on_the_flat_index_path_of_cupy(monkeypatch, case):
    """The same on CuPy's code path (flat-index selections, the namespace's own FFTs) run by array_api_compat.numpy."""
    compat = pytest.importorskip("array_api_compat.numpy")
    from bem.backend import Backend

    compare(case, Backend(compat, "compat-numpy", flat_indices=True), compat.asarray, monkeypatch)


@pytest.mark.parametrize("n", [1, 2, 7, 10])
def test_the_median_with_and_without_leave_to_overwrite(strict, n):
    """``Backend.median``: NumPy's median of the values, with ``overwrite`` too (the values then in any order), and
    the values untouched without it; on NumPy and on the strict namespace."""
    values = np.random.default_rng(n).standard_normal(n).astype(np.float32)
    expected, kept = float(np.median(values)), values.copy()
    bk = bem.backend.backend_of(values)
    assert bk.median(values) == expected and np.array_equal(values, kept)
    assert bk.median(values.copy(), overwrite=True) == expected
    device = strict.asarray(values)
    bk = bem.backend.backend_of(device)
    assert bk.median(device) == expected and bk.median(device, overwrite=True) == expected
