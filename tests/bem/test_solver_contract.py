"""The solver contract: every option checked, one meaning per name, a result meets rtol or says so."""

import ast
import logging
import math
import pathlib

import numpy as np
import pytest

import bem
from bem import layers
from bem.gaps import Paraboloid
from bem.reference import rigid_layer_paraboloid

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _hertz(**kw):
    return bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=0.05, extent=1.2, **kw)


def _dense_kkt(res, layer, gap=Paraboloid(1.0)):
    """KKT residual of eq. 14 recomputed with the dense C (independent of the FFT path)."""
    C = bem.InfluenceOperator(res.lattice, res.E_star).dense()
    w = np.zeros_like(res.p) if layer is None else layer.w(res.p)
    total = C @ res.p + w
    g = total + gap(res.x, res.y) - res.approach
    return bem.kkt.kkt_residual(res.p, g, displacement_scale=float(np.abs(total).max()), force=res.force,
                                node_area=res.lattice.node_area)


# --- options are checked, result.method names the solver that ran ---------------------------------

def test_an_unknown_option_is_refused_by_name():
    with pytest.raises(bem.InputError, match="frobnicate = 1 is not allowed"):
        _hertz(frobnicate=1)


def test_an_option_of_another_solver_is_refused():
    with pytest.raises(bem.InputError, match=r"relaxation = 0.5 .*Kalker's QP"):
        _hertz(method="augmented_gap", relaxation=0.5)
    with pytest.raises(bem.InputError, match="eps_p = 1e-08 is not allowed: method = 'newton' does not take it"):
        _hertz(layer=layers.Root(0.1), eps_p=1e-8)


@pytest.mark.parametrize("kw, name", [({"relaxation": 1.5}, "relaxation"), ({"relaxation": 0.0}, "relaxation"),
                                      ({"eps_h": -1.0}, "eps_h"), ({"record": "yes"}, "record")])
def test_option_values_are_checked(kw, name):
    with pytest.raises(bem.InputError, match=f"^{name} = "):
        _hertz(layer=layers.Root(0.1), method="augmented_gap", **kw)


@pytest.mark.parametrize("kw, name", [({"maxiter": 0}, "maxiter"), ({"maxiter": 2.5}, "maxiter"),
                                      ({"precondition": "no"}, "precondition"), ({"nested": 1}, "nested"),
                                      ({"callback": 3}, "callback")])
def test_common_option_values_are_checked(kw, name):
    with pytest.raises(bem.InputError, match=f"^{name} = "):
        _hertz(**kw)


@pytest.mark.parametrize("method", bem.METHODS)
def test_result_method_is_the_solver_that_ran(method):
    res = _hertz(method=method)  # no layer: Kalker's QP for every method
    assert res.method == "kalker" and res.converged
    assert res.iterations == len(res.history["residual"])  # CG iterations, counted as such
    layered = _hertz(layer=layers.Root(0.05), method=method) if method != "kalker" else None
    if layered is not None:
        assert layered.method == method


@pytest.mark.parametrize("method", ["augmented_gap", "variable_compliance"])
def test_a_paper_method_run_as_the_qp_says_so(caplog, method):
    with caplog.at_level(logging.INFO, logger="bem"):
        res = _hertz(method=method)
    assert res.method == "kalker" and res.converged
    said = [r.getMessage() for r in caplog.records if r.levelno == logging.INFO]
    assert [m for m in said if f"method = {method!r} runs as Kalker's QP" in m and "there is no layer" in m]


def test_the_default_method_on_a_quadratic_problem_logs_nothing_above_debug(caplog):
    with caplog.at_level(logging.INFO, logger="bem"):
        assert _hertz().method == "kalker"
    assert not caplog.records


def test_n_matvec_counts_the_products_with_c(monkeypatch):
    calls = []
    real = bem.InfluenceOperator.matvec

    def counting(self, p, **kw):
        calls.append(self.lattice.n_nodes)
        return real(self, p, **kw)

    monkeypatch.setattr(bem.InfluenceOperator, "matvec", counting)
    for kw in ({}, {"layer": layers.Root(0.05)}):
        calls.clear()
        res = _hertz(nested=False, **kw)
        assert res.n_matvec == len(calls) > res.iterations


@pytest.mark.parametrize("domain", ["region", "cell"])
@pytest.mark.parametrize("layer", [None, layers.Root(0.05)])
def test_n_transforms_counts_the_ffts_of_the_lattices_arrays(monkeypatch, domain, layer):
    """Counted where the transforms are made, a level below the operators that count them: on a region the
    forward transform of a box (both parities in one call) and the inverse of each parity; on a cell the real
    transform along the rows, forward and inverse, once a transform; each called from the operator's module (the
    kernel's spectra are made through other callers). One level (nested=False): every transform counted is the
    finest lattice's."""
    import sys

    from bem import fft as bem_fft
    from bem import pruned_fft

    counts = {"forward": 0, "inverse": 0}

    def spy(module, name, key, weight):
        real = getattr(module, name)

        def counting(*args, **kw):
            if sys._getframe(1).f_code.co_filename.endswith(("operator.py", "influence.py")):
                counts[key] += weight
            return real(*args, **kw)

        monkeypatch.setattr(module, name, counting)

    if domain == "region":
        spy(pruned_fft, "forward_parts", "forward", 1)
        spy(pruned_fft, "inverse_into", "inverse", 0.5)  # one call a parity
        res = _hertz(nested=False, layer=layer)
    else:
        from bem.periodic import influence

        spy(influence.fft, "rfft_into", "forward", 1)
        spy(influence.fft, "irfft_into", "inverse", 1)
        cell = bem.PeriodicCell(1.0 / 64, 64, 64)
        h = 0.01 * (2 - np.cos(2 * np.pi * cell.x / cell.size[0]) - np.cos(2 * np.pi * cell.y / cell.size[1]))
        res = bem.solve(h, domain=cell, E_star=1.0, mean_pressure=0.003, layer=layer, nested=False)
        assert bem_fft is influence.fft
    assert res.converged
    assert res.n_transforms == counts["forward"] + counts["inverse"]
    assert counts["forward"] >= res.iterations and counts["inverse"] >= res.iterations > 0


# --- one name, one meaning ------------------------------------------------------------------------

def test_rtol_is_the_kkt_tolerance_of_every_method():
    layer = layers.Root(0.02)
    for method, kw in (("newton", {}), ("variable_compliance", {}), ("augmented_gap", {"relaxation": 0.5})):
        res = _hertz(layer=layer, method=method, rtol=1e-9, **kw)
        assert res.converged or method == "augmented_gap", method  # Newton and variable compliance must
        if res.converged:
            assert res.kkt_residual <= 1e-9, method
            assert _dense_kkt(res, layer) <= 1.01e-9, method
        else:
            assert res.kkt_residual > 1e-9, method


def test_fem_reference_domain_factor_is_relative_to_the_contact_and_extent_is_refused():
    """``extent`` is an absolute half-width in bem.solve; the FEM's domain size is relative to the
    expected contact radius and has its own name."""
    import fem_reference

    kw = dict(E1=2.0, nu1=0.3, E2=2.0, nu2=0.3, force=1.0, n_contact_elements=3)
    radius = {}
    for factor in (10.0, 20.0):
        res = fem_reference.solve(Paraboloid(1.0), domain_factor=factor, **kw)
        radius[factor] = res.field()["points"][:, 0].max()
    a_est = radius[10.0] / 10.0
    assert radius[20.0] == pytest.approx(20.0 * a_est, rel=1e-9)
    a_hertz = (3.0 * 0.91 / 4.0) ** (1 / 3)  # (3 P R / (4 E*))^(1/3), 1/E* = 2 (1 - 0.09) / 2
    assert a_est == pytest.approx(a_hertz, rel=0.02)  # in units of the expected contact radius
    with pytest.raises((TypeError, ValueError), match="extent"):
        fem_reference.solve(Paraboloid(1.0), extent=20.0, **kw)


def test_qp_uses_the_preconditioner_callable_it_is_given_and_solve_preconditions_by_default():
    from bem.kalker import solve_qp

    res = _hertz(nested=False)
    op = bem.InfluenceOperator(res.lattice, res.E_star)
    h = Paraboloid(1.0)(res.lattice.x, res.lattice.y)
    applied = []

    def identity(r):
        applied.append(1)
        return r

    sub = solve_qp(op, h, force=1.0, preconditioner=identity)
    assert sub.converged and len(applied) >= sub.iterations - 1  # once per CG iteration
    np.testing.assert_allclose(sub.p[res.lattice.mask], res.p, rtol=0, atol=1e-6 * res.p.max())
    fft = solve_qp(op, h, force=1.0, preconditioner=op.preconditioner())
    assert fft.converged and fft.iterations < sub.iterations  # the callable given is the one applied
    with pytest.raises(TypeError, match="precondition"):
        solve_qp(op, h, force=1.0, precondition=True)
    default, on, off = (_hertz(nested=False, **kw) for kw in ({}, {"precondition": True}, {"precondition": False}))
    assert default.iterations == on.iterations < off.iterations
    assert default.n_matvec == on.n_matvec


# --- public errors --------------------------------------------------------------------------------

def test_errors_are_public_value_errors():
    assert issubclass(bem.InputError, ValueError)
    assert issubclass(bem.RegionTooSmallError, bem.InputError)
    assert bem.checks.InputError is bem.InputError


def test_nothing_outside_bem_imports_its_private_modules():
    offenders = []
    for path in list(ROOT.glob("fem_reference/**/*.py")) + list(ROOT.glob("validation/**/*.py")) + \
            list(ROOT.glob("tests/**/*.py")) + list(ROOT.glob("benchmarks/*.py")) + list(ROOT.glob("docs/**/*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = []
            if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("bem"):
                names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            if any(part.startswith("_") for n in names if n.startswith("bem") for part in n.split(".")):
                offenders.append(str(path.relative_to(ROOT)))
    assert not offenders


# --- Newton reaches rtol; near the rigid limit with a small exponent ------------------------------

@pytest.mark.parametrize("n_across", [20, 60, 100, 160, 200])
def test_newton_near_the_rigid_limit_with_a_small_exponent(n_across):
    """Power(1, 0.3), E* = 1e9, force control: Newton converges at every resolution."""
    layer = layers.Power(1.0, 0.3)
    a = rigid_layer_paraboloid(layer, 1.0, force=1.0).contact_radius
    res = bem.solve(Paraboloid(1.0), E_star=1e9, force=1.0, step=2 * a / n_across, extent=1.25 * a, layer=layer)
    assert res.converged, res.message
    assert res.kkt_residual <= 1e-10
    assert res.history["inner_worst"] < 1e-2  # no inner solve diverged
    if n_across <= 20:
        assert _dense_kkt(res, layer) <= 1.01e-10


@pytest.mark.parametrize("k", [1e3, 1e6])
def test_newton_force_control_with_an_extreme_concave_layer(k):
    """s = 0.05 with a layer 1e3-1e6 times softer than the bodies: pressures span tens of decades.

    Newton under force control stalls there; the force is then found as the root of P(delta)
    over approach-controlled solves (which converge)."""
    a_H = 0.75 ** (1 / 3)  # Hertz, R = E* = P = 1; the layer's secant at his mean pressure is k a_H^2 / p0
    p0 = 3 / (2 * math.pi * a_H * a_H)
    layer = layers.Power(k * (a_H * a_H / p0) * (2 * p0 / 3) ** (1 - 0.05), 0.05)
    a = max(a_H, rigid_layer_paraboloid(layer, 1.0, force=1.0).contact_radius)
    res = bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=2 * a / 16, extent=1.5 * a, layer=layer)
    assert res.converged, res.message
    assert _dense_kkt(res, layer) <= 1.01e-10
    assert res.force == pytest.approx(1.0, rel=1e-10)


# --- variable compliance under force control where the layer dominates ----------------------------

@pytest.mark.parametrize("layer, E_star", [(layers.Linear(1.0), 1e4), (layers.Root(1.0), 1e2),
                                           (layers.Root(1.0), 1e4)])
def test_variable_compliance_where_the_layer_dominates(layer, E_star):
    """The layer-free first step collapses to about one node; the QP must let the contact grow."""
    a = rigid_layer_paraboloid(layer, 1.0, force=1.0).contact_radius
    kw = dict(E_star=E_star, force=1.0, step=2 * a / 40, extent=1.3 * a, layer=layer)
    vc = bem.solve(Paraboloid(1.0), method="variable_compliance", **kw)
    newton = bem.solve(Paraboloid(1.0), **kw)
    assert vc.converged, vc.message
    assert np.linalg.norm(vc.p - newton.p) / np.linalg.norm(newton.p) <= 1e-6


def test_variable_compliance_reports_failure_where_it_cannot_converge():
    """s >= 2 with a dominating layer: the secant map has derivative -(s - 1) <= -1."""
    layer = layers.Power(1.0, 3.0)
    a = rigid_layer_paraboloid(layer, 1.0, force=1.0).contact_radius
    res = bem.solve(Paraboloid(1.0), E_star=1e4, force=1.0, step=2 * a / 30, extent=1.3 * a, layer=layer,
                    method="variable_compliance", maxiter=60)
    assert not res.converged and res.kkt_residual > 1e-6
    assert res.status in ("stalled", "diverged", "maxiter")


# --- one warning, only when it failed -------------------------------------------------------------

def test_a_converged_run_logs_no_warning(caplog):
    layer = layers.Power(1.0, 0.3)
    a = rigid_layer_paraboloid(layer, 1.0, force=1.0).contact_radius
    with caplog.at_level(logging.DEBUG, logger="bem"):
        res = bem.solve(Paraboloid(1.0), E_star=1e9, force=1.0, step=2 * a / 60, extent=1.25 * a, layer=layer)
    assert res.converged
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING]


def test_a_failed_run_logs_one_warning(caplog):
    with caplog.at_level(logging.WARNING, logger="bem"):
        res = _hertz(layer=layers.Root(1.0), method="augmented_gap", maxiter=40)
    assert not res.converged
    warnings = [r for r in caplog.records if r.levelno >= logging.WARNING]
    assert len(warnings) == 1 and res.message in warnings[0].getMessage()
    assert math.isfinite(res.kkt_residual)


# --- one meaning per name: a solver's displacement is C p, whatever the layer ---------------------

@pytest.mark.parametrize("lam", [0.0, 0.3, "per node"])
def test_the_qp_displacement_is_the_elastic_displacement(lam):
    """QPSolution.displacement = C p, the elastic displacement, whatever the layer (as for Newton)."""
    from bem.kalker import solve_qp

    lattice = bem.Lattice.from_extent(0.1, 1.2)
    op = bem.InfluenceOperator(lattice, 1.0)
    if lam == "per node":
        lam = np.where(lattice.mask, 0.1 + 0.05 * np.hypot(lattice.x, lattice.y), 0.0)
    sol = solve_qp(op, Paraboloid(1.0)(lattice.x, lattice.y), force=1.0, lam=lam, rtol=1e-10)
    assert sol.converged
    np.testing.assert_allclose(sol.displacement, op.matvec(sol.p), rtol=0, atol=1e-12 * np.abs(sol.displacement).max())
