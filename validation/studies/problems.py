"""The problems the studies run: paraboloid on paraboloid (paper section 6, Fig. 4a).

Units: lengths in units of the effective radius ``R`` and pressures in units of ``E*``
with the force ``P = 1`` (``R = E* = P = 1`` unless a problem says otherwise), so the Hertz
contact radius is ``a_H = (3/4)^(1/3) = 0.9086`` and the Hertz peak
``p0 = 3 P / (2 pi a_H^2) = 0.5784``.

Layer stiffness is stated as the ratio ``k`` of the layer's secant compliance at the Hertz
peak, ``w(p0) / p0``, to the elastic compliance over the contact, ``C_el = delta_H / p0``
(Hertz approach over peak pressure): ``w = k C_el p0^(1 - s) p^s``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

import bem
import fem_reference
from bem import layers
from bem.checks import check_choice
from bem.gaps import Paraboloid
from bem.materials import effective_modulus

from bem.reference import estimate_contact_radius, hertz_sphere, rigid_layer_paraboloid

__all__ = ["Problem", "ERROR_TIME_PROBLEMS", "get_problem", "power_layer", "stability_cases", "body_modulus"]

NU = 0.3


def body_modulus(nu, E_star=1.0):
    """Young's modulus of each of two identical bodies whose ``E*`` is ``E_star`` [pressure]."""
    return 2.0 * (1.0 - nu * nu) * E_star


@dataclass(frozen=True)
class Problem:
    """Two elastic paraboloids (radii ``R1``, ``R2``) pressed by a force, with an optional layer.

    Attributes
    ----------
    name, title : str
        Identifier and one-line description.
    R1, R2 : float
        Radii of the two bodies [length]; the gap is ``r^2 / (2 R)``, ``1/R = 1/R1 + 1/R2``.
    E1, nu1, E2, nu2 : float
        Moduli [pressure] and Poisson's ratios of the bodies.
    force : float
        Total force ``P`` [force].
    layer : bem.layers.Layer, optional
        Interface law (``None``: smooth bodies).
    analytic : {None, "hertz", "rigid_layer"}
        Closed form that describes the problem: exactly (``"hertz"`` without a layer) or in
        a limit (``"hertz"`` for a very stiff layer, ``"rigid_layer"`` for a very soft one).
    analytic_tol : float
        Relative L2 difference allowed against that closed form (discretisation plus the
        distance from the limit).
    n_across : int
        Default BEM resolution: lattice steps across the contact diameter.
    margin : float
        Half-width of the candidate region over the contact radius.
    fem : bool
        Whether the FEM reference is relevant (stability study).
    n_contact : int
        Default FEM elements across the contact radius.
    options : dict
        Extra ``bem.solve`` options per method, e.g. ``{"variable_compliance": {"maxiter": 30}}``.
    """

    name: str
    title: str
    R1: float = 2.0
    R2: float = 2.0
    E1: float = field(default_factory=lambda: body_modulus(NU))
    nu1: float = NU
    E2: float = field(default_factory=lambda: body_modulus(NU))
    nu2: float = NU
    force: float = 1.0
    layer: object = None
    analytic: str | None = None
    analytic_tol: float = 0.0
    n_across: int = 25
    margin: float = 1.25
    fem: bool = False
    n_contact: int = 16
    options: dict = field(default_factory=dict)

    @property
    def R(self):
        """Effective radius ``R1 R2 / (R1 + R2)`` [length]."""
        return self.R1 * self.R2 / (self.R1 + self.R2)

    @property
    def E_star(self):
        """Johnson's effective modulus [pressure]."""
        return effective_modulus(self.E1, self.nu1, self.E2, self.nu2)

    @property
    def gap(self):
        """The initial gap ``h = r^2 / (2 R)``."""
        return Paraboloid(self.R)

    @property
    def hertz(self):
        """The Hertz solution of the smooth problem."""
        return hertz_sphere(self.R, self.E_star, force=self.force)

    @property
    def methods(self):
        """BEM methods that apply: Kalker's QP only without a layer or with a linear one."""
        if self.layer is None or self.layer.is_linear:
            return ("newton", "augmented_gap", "variable_compliance", "kalker")
        return ("newton", "augmented_gap", "variable_compliance")

    def reference_solution(self):
        """The closed form named by ``analytic`` (or ``None``)."""
        if self.analytic == "hertz":
            return self.hertz
        if self.analytic == "rigid_layer":
            return rigid_layer_paraboloid(self.layer, self.R, force=self.force)
        return None

    @cached_property
    def contact_radius(self):
        """Contact radius [length]: Hertz's without a layer; with one, the largest loaded node
        radius of a Newton solve at step ``a1 / 20`` in ``|x|, |y| <= 1.5 a1``, where ``a1`` is
        that radius, plus one step, on a coarse pass (step ``a_est / 8``, region ``3 a_est``,
        ``a_est`` from :func:`bem.reference.estimate_contact_radius`)."""
        if self.layer is None:
            return self.hertz.contact_radius
        a = estimate_contact_radius(self.gap, E_star=self.E_star, force=self.force, layer=self.layer)
        a1 = self._loaded_radius(step=a / 8, extent=3 * a) + a / 8
        return self._loaded_radius(step=a1 / 20, extent=1.5 * a1)

    def _loaded_radius(self, *, step, extent):
        res = bem.solve(self.gap, E_star=self.E_star, force=self.force, step=step, extent=extent, layer=self.layer)
        return float(np.hypot(res.x, res.y)[res.p > 0].max())

    def step(self, n_across):
        """Lattice step for ``n_across`` steps across the contact diameter [length]."""
        return 2.0 * self.contact_radius / n_across

    def run_bem(self, method="newton", *, n_across=None, **options):
        """``bem.solve`` of the problem at ``n_across`` steps across the contact (default the problem's)."""
        n = self.n_across if n_across is None else n_across
        options = {**self.options.get(method, {}), **options}
        return bem.solve(self.gap, E_star=self.E_star, force=self.force, step=self.step(n),
                         extent=self.margin * self.contact_radius, layer=self.layer, method=method, **options)

    def run_fem(self, *, n_contact=None, **options):
        """``fem_reference.solve`` of the problem at ``n_contact`` elements across the contact radius."""
        n = self.n_contact if n_contact is None else n_contact
        return fem_reference.solve(self.gap, E1=self.E1, nu1=self.nu1, E2=self.E2, nu2=self.nu2,
                                   force=self.force, layer=self.layer, n_contact=n, **options)


def _hertz_scales():
    H = hertz_sphere(1.0, 1.0, force=1.0)
    return H.p_max, H.approach / H.p_max


def power_layer(k, s):
    """Layer ``w = lam p^s`` whose secant at the Hertz peak is ``k C_el`` (module docstring).

    ``s = 1``: :class:`bem.layers.Linear`; ``s = 1/2``: :class:`bem.layers.Root`.
    """
    p0, c_el = _hertz_scales()
    lam = k * c_el * p0 ** (1.0 - s)
    if s == 1.0:
        return layers.Linear(lam)
    if s == 0.5:
        return layers.Root(lam)
    return layers.Power(lam, s)


ERROR_TIME_PROBLEMS = {
    "hertz": Problem("hertz", "Hertz: smooth paraboloids R1 = R2 = 2 (R = 1), E* = 1, P = 1", analytic="hertz"),
    "paper-root": Problem(
        "paper-root", "paper problem: paraboloids R1 = R2 = 2 with a root layer w = lam sqrt(p), k = 1",
        layer=power_layer(1.0, 0.5)),
}


def get_problem(name):
    """A built-in error-time problem by name (``"hertz"``, ``"paper-root"``)."""
    name = str(name).replace("_", "-")  # the built-in scene is called paper_root
    check_choice("scene", name, tuple(ERROR_TIME_PROBLEMS))
    return ERROR_TIME_PROBLEMS[name]


def _limit(k):
    """Closed-form limit of a layer ``k`` times as compliant as the bodies, and its tolerance.

    ``k <= 1e-2``: Hertz, relative L2 3 % (measured at 25 steps across: 1.4 %, mostly the
    square-root edge on the lattice; 0.3 % at 100 steps). ``k >= 1e2``: the rigid-body layer
    limit, 6 % (measured: 0.02 .. 1 % for ``s <= 1``, 0.6 % for ``s = 1.5``, and for
    ``s = 3`` 4.4 % at 25 steps, 3.8 % at 100: the layer is stiff at the low pressures of
    that contact, so the bodies' compliance is not negligible). Else none.
    """
    if k <= 1e-2:
        return "hertz", 0.03
    if k >= 1e2:
        return "rigid_layer", 0.06
    return None, 0.0


def _stiffness_cases(quick):
    ks = (1e-3, 1.0, 1e3) if quick else (1e-3, 1e-2, 1e-1, 1.0, 10.0, 1e2, 1e3)
    cases = []
    for k in ks:
        analytic, tol = _limit(k)
        cases.append(Problem(f"linear k={k:g}", f"linear layer, compliance {k:g} x elastic",
                             layer=power_layer(k, 1.0), analytic=analytic, analytic_tol=tol,
                             fem=k == 1.0))
    return cases


def _exponent_cases(quick):
    grid = ((0.2, 1e3), (3.0, 1e3)) if quick else tuple(
        (s, k) for s in (0.2, 0.5, 1.5, 3.0) for k in (1e-3, 1.0, 1e3))
    cases = []
    for s, k in grid:
        analytic, tol = _limit(k)
        cases.append(Problem(f"power s={s:g} k={k:g}", f"power layer s = {s:g}, compliance {k:g} x elastic",
                             layer=power_layer(k, s), analytic=analytic, analytic_tol=tol,
                             fem=(k == 1.0 and s in (0.5, 3.0))))
    return cases


def stability_cases(quick=False):
    """The stiff and extreme cases of the stability study (``quick``: a representative subset).

    Returns
    -------
    list of Problem
    """
    p0, c_el = _hertz_scales()
    cases = _stiffness_cases(quick) + _exponent_cases(quick)
    cases += [
        Problem("elastic-rigid p_cr=1e-6 p0", "elastic-rigid layer, p_cr = 1e-6 p0 (nearly rigid at once)",
                layer=layers.ElasticRigid(c_el, 1e-6 * p0), margin=1.5),
        Problem("root, few nodes", "root layer k = 1, 5 steps across the contact", layer=power_layer(1.0, 0.5),
                n_across=5, margin=2.0),
        Problem("linear, near full region", "linear layer k = 1 in a region 1.12 x the contact radius",
                layer=power_layer(1.0, 1.0), margin=1.12),
        Problem("dissimilar E1/E2=1e3", "steel-on-rubber-like E1/E2 = 1e3, nu2 = 0.49, root layer k = 1",
                E1=1e3 * _rubber_modulus(), nu1=NU, E2=_rubber_modulus(), nu2=0.49,
                layer=power_layer(1.0, 0.5), fem=True),
    ]
    if not quick:  # measured: every method fails here (Newton's line search stalls); ~2 min
        cases.append(Problem("power s=0.2 k=1, 100 steps", "power layer s = 0.2, k = 1 on a fine lattice",
                             layer=power_layer(1.0, 0.2), n_across=100,
                             options={"variable_compliance": {"maxiter": 30}}))
    for nu in (0.49, 0.499):
        if quick and nu == 0.49:
            continue
        cases.append(Problem(f"smooth nu={nu:g}", f"smooth bodies, nu1 = nu2 = {nu:g} (FEM near incompressible)",
                             E1=body_modulus(nu), nu1=nu, E2=body_modulus(nu), nu2=nu, analytic="hertz",
                             analytic_tol=0.03, fem=True))
    return cases


def _rubber_modulus():
    """``E2`` with ``E1 = 1e3 E2``, ``nu1 = 0.3``, ``nu2 = 0.49`` and ``E* = 1``."""
    return (1.0 - NU**2) / 1e3 + (1.0 - 0.49**2)
