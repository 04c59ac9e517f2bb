"""The problems the studies run, as scene dicts (docs/scenes.md): paraboloid on paraboloid (paper Fig. 4 a).

A study runs a problem with :func:`validation.run.execute_scene` and varies it with dotted-key
overrides (``{"bem.method": "kalker"}``); it names a problem by its ``[scene] title``. Units:
lengths in units of the effective radius ``R``, pressures in units of ``E*``, force ``P = 1``
(``R = E* = P = 1``), so Hertz's contact radius is ``a_H = (3/4)^(1/3) = 0.9086`` and his peak
``p0 = 3 P / (2 pi a_H^2) = 0.5784``. A layer's stiffness is the ratio ``k`` of its secant
compliance at the Hertz peak, ``w(p0) / p0``, to the elastic compliance over the contact
``C_el = delta_H / p0`` (Hertz approach over peak): ``w = k C_el p0^(1 - s) p^s``.
"""

from __future__ import annotations

import copy
import math
import re

from bem.checks import check_choice
from bem.reference import hertz_sphere

__all__ = ["paraboloids", "power_layer", "methods", "get_problem", "stability_cases", "robustness_scene",
           "ERROR_TIME_PROBLEMS", "LIMIT_TOL"]

NU = 0.3
#: relative L2 difference allowed against a closed-form limit: Hertz (smooth bodies, or a layer with
#: k <= 1e-2; measured at 25 steps across 1.4 %, mostly the square-root edge on the lattice) and the
#: rigid-body layer (k >= 1e2; measured 0.02 .. 1 % for s <= 1, 0.6 % for s = 1.5, 4.4 % for s = 3,
#: where the layer is stiff at the low pressures of that contact and the bodies' compliance counts)
LIMIT_TOL = {"hertz": 0.03, "rigid_layer": 0.06}


def _hertz_scales():
    """Hertz's peak ``p0`` [pressure] and ``C_el`` [length/pressure] for ``R = E* = P = 1``."""
    H = hertz_sphere(1.0, 1.0, force=1.0)
    return H.p_max, H.approach / H.p_max


def power_layer(k, s):
    """``[layer]`` table of ``w = lam p^s`` whose secant at the Hertz peak is ``k C_el`` (``s = 1``: ``linear``,
    ``s = 1/2``: ``root``, else ``power``)."""
    p0, c_el = _hertz_scales()
    lam = k * c_el * p0 ** (1.0 - s)
    law = {1.0: "linear", 0.5: "root"}.get(s)
    return {"law": law, "lam": lam} if law else {"law": "power", "lam": lam, "s": s}


def paraboloids(name, description, *, layer=None, E=None, nu=(NU, NU), E_star=None, analytic=None, fem=False,
                nodes_across=25, extent_factor=1.25, **bem):
    """Scene dict of paraboloids ``R1 = R2 = 2`` (``R = 1``) pressed by ``P = 1``.

    ``name`` is the ``[scene] title`` (the scene's name is it with ``_`` for other characters);
    ``layer`` a ``[layer]`` table (``None``: smooth bodies); ``E`` the Young's moduli [pressure]
    (default ``E* = 1`` from ``nu``), or ``E_star`` alone; ``analytic`` the ``[analytic] kind``;
    ``fem``: run the FEM at 16 elements across the contact radius; ``nodes_across``,
    ``extent_factor`` and ``bem``: the ``[bem]`` table (steps across the expected contact
    diameter, region half-width over its radius, other keys).
    """
    E = tuple(2.0 * (1.0 - n * n) for n in nu) if E is None else E  # two like bodies: E* = 1
    bodies = {"E_star": E_star} if E_star is not None else {"E1": E[0], "nu1": nu[0], "E2": E[1], "nu2": nu[1]}
    scene = {"scene": {"name": re.sub(r"[^A-Za-z0-9_.-]+", "_", name), "title": name, "description": description,
                       "units": "normalised: R = E* = P = 1" if E_star is None else "normalised: R = P = 1"},
             "bodies": bodies,
             "gap": {"type": "paraboloid", "R": 1.0}, "load": {"force": 1.0},
             "bem": {"nodes_across": nodes_across, "extent_factor": extent_factor, **bem}}
    if layer is not None:
        scene["layer"] = layer
    if analytic is not None:
        scene["analytic"] = {"kind": analytic}
    if fem:
        scene["fem"] = {"n_contact_elements": 16}
    return scene


def methods(scene):
    """BEM methods that apply to a scene dict: Kalker's QP only without a layer or with a linear one."""
    law = scene.get("layer", {}).get("law", "none")
    return ("newton", "augmented_gap", "variable_compliance") + (("kalker",) if law in ("none", "linear") else ())


ERROR_TIME_PROBLEMS = {
    "hertz": paraboloids("hertz", "Hertz: smooth paraboloids R1 = R2 = 2 (R = 1), E* = 1, P = 1", analytic="hertz"),
    "paper-root": paraboloids("paper-root", "paper problem: paraboloids R1 = R2 = 2 with a root layer "
                                            "w = lam sqrt(p), k = 1", layer=power_layer(1.0, 0.5)),
}


def get_problem(name):
    """A copy of the scene dict of an error-time problem: ``"hertz"`` or ``"paper-root"`` (or ``"paper_root"``)."""
    name = check_choice("scene", str(name).replace("_", "-"), tuple(ERROR_TIME_PROBLEMS))
    return copy.deepcopy(ERROR_TIME_PROBLEMS[name])


def _layered(name, description, k, s, **kw):
    """A case with a layer ``k`` times as compliant as the bodies, and its limit: Hertz for ``k <= 1e-2``
    (the runner compares no layered scene with Hertz: no ``[analytic]``), the rigid-body layer for
    ``k >= 1e2`` (``[analytic] kind = "rigid_layer"``), else none."""
    limit = "hertz" if k <= 1e-2 else "rigid_layer" if k >= 1e2 else None
    analytic = "rigid_layer" if limit == "rigid_layer" else None
    return paraboloids(name, description, layer=power_layer(k, s), analytic=analytic, **kw), limit


def stability_cases(quick=False):
    """The stiff and extreme cases of the stability study (``quick``: a representative subset).

    Returns
    -------
    list of (dict, str or None)
        Scene dict and the closed form its answer must match (a key of :data:`LIMIT_TOL`) or ``None``.
    """
    ks = (1e-3, 1.0, 1e3) if quick else (1e-3, 1e-2, 1e-1, 1.0, 10.0, 1e2, 1e3)
    grid = ((0.2, 1e3), (3.0, 1e3)) if quick else [(s, k) for s in (0.2, 0.5, 1.5, 3.0) for k in (1e-3, 1.0, 1e3)]
    cases = [_layered(f"linear k={k:g}", f"linear layer, compliance {k:g} x elastic", k, 1.0, fem=k == 1.0)
             for k in ks]
    cases += [_layered(f"power s={s:g} k={k:g}", f"power layer s = {s:g}, compliance {k:g} x elastic", k, s,
                       fem=k == 1.0 and s in (0.5, 3.0)) for s, k in grid]
    p0, c_el = _hertz_scales()
    rubber = (1.0 - NU**2) / 1e3 + (1.0 - 0.49**2)  # E2 with E1 = 1e3 E2, nu1 = 0.3, nu2 = 0.49 and E* = 1
    cases += [(scene, None) for scene in (
        paraboloids("elastic-rigid p_cr=1e-6 p0", "elastic-rigid layer, p_cr = 1e-6 p0 (nearly rigid at once)",
                    layer={"law": "elastic_rigid", "lam": c_el, "p_cr": 1e-6 * p0}, extent_factor=1.5),
        paraboloids("root, few nodes", "root layer k = 1, 5 steps across the contact", layer=power_layer(1.0, 0.5),
                    nodes_across=5, extent_factor=2.0),
        paraboloids("linear, near full region", "linear layer k = 1 in a region 1.12 x the contact radius",
                    layer=power_layer(1.0, 1.0), extent_factor=1.12),
        paraboloids("dissimilar E1/E2=1e3", "steel-on-rubber-like E1/E2 = 1e3, nu2 = 0.49, root layer k = 1",
                    E=(1e3 * rubber, rubber), nu=(NU, 0.49), layer=power_layer(1.0, 0.5), fem=True))]
    if not quick:  # maxiter = 30 for every method: variable compliance (99 iterations to converge here) must say
        # it hit the limit; Newton needs 7, augmented gap stalls after 16 (measured)
        cases.append((paraboloids("power s=0.2 k=1, 100 steps", "power layer s = 0.2, k = 1 on a fine lattice",
                                  layer=power_layer(1.0, 0.2), nodes_across=100, maxiter=30), None))
    for nu in (0.499,) if quick else (0.49, 0.499):
        cases.append((paraboloids(f"smooth nu={nu:g}", f"smooth bodies, nu1 = nu2 = {nu:g} (FEM near incompressible)",
                                  nu=(nu, nu), analytic="hertz", fem=True), "hertz"))
    return cases


def robustness_scene(s, k, E_star, **bem):
    """Scene dict of a point of the robustness grid: a paraboloid ``R = 1`` on a flat under ``P = 1`` with
    ``w = lam p^s``, whose secant at the Hertz mean pressure ``p_m`` is ``k`` times the elastic compliance
    of the contact ``a_H^2 / (R p0)`` (``E*`` [pressure] relative to ``P / R^2``); ``bem``: the ``[bem]`` table."""
    a = (3 / (4 * E_star)) ** (1 / 3)  # Hertz, R = P = 1
    p0 = 3 / (2 * math.pi * a * a)
    layer = {"law": "power", "lam": k * (a * a / p0) * (2 * p0 / 3) ** (1 - s), "s": s}
    return paraboloids(f"s={s:g} k={k:g} E*={E_star:g}", "robustness grid point", E_star=E_star, layer=layer, **bem)
