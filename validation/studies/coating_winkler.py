"""When does a linear Winkler layer stand for a coating? A sphere on a coated flat against the same sphere on
the bare substrate carrying the layer ``w = lam p``.

The problem: an elastic sphere (radius ``R``, the substrate's material ``E_s, nu_s``) pressed by the
force ``P`` on a flat of the same material coated with a bonded layer of thickness ``t``, modulus
``E_c`` and Poisson's ratio ``nu_c`` (frictionless surface). ``a_H`` is the Hertz radius of the
uncoated pair, ``p_H`` its peak pressure, ``d_H = a_H^2 / R`` its approach. Cases: ``a_H / t``,
``E_c / E_s`` and ``nu_c`` over the grid of the settings (``P`` and ``R`` fixed, ``t`` varies).

The coated truth is a function of the case (:data:`TRUTHS`, the ``truth`` argument of
:func:`run_coating_winkler`): ``"rings"`` (default) the axisymmetric ring solution with the coated
half-space's mode compliance (:mod:`validation.studies.coating_rings`), ``"fem"`` the FEM
reference with the coating meshed (:func:`fem_reference.solve`, ``coating2``). Both give a
:class:`Profile`; another source (a BEM solve with a coated body) is one more function of
``(case, settings) -> Profile``.

Two Winkler models on the bare substrate (the sphere on the half-space ``E_s, nu_s``), solved on rings:

- the oedometric layer, ``lam = t (1 + nu_c)(1 - 2 nu_c) / ((1 - nu_c) E_c)``
  (:func:`bem.coating.oedometric_compliance`);
- the best layer: ``lam >= 0`` minimising the RMS pressure error (below); ``lam = 0`` (no layer) is
  a candidate, so a coating stiffer than its substrate gets the bare substrate at best.

Errors against the truth, relative to its values: ``p_max``, contact radius (edge of the loaded
zone), approach (of points far from the contact) and the RMS of ``p(r)`` over the plane,
``sqrt(integral (p - p_true)^2 r dr / integral p_true^2 r dr)``; ``worst`` is the largest magnitude
of the four.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..progress import each
from . import no_scene, save

__all__ = ["SETTINGS", "QUICK", "Profile", "problem", "rings_truth", "fem_truth", "TRUTHS", "WinklerRings",
           "errors", "run_case", "run_coating_winkler", "rule", "summary_lines", "OUTPUT_NAMES", "main", "STEM",
           "METRICS"]

STEM = __name__.rpartition(".")[2]
OUTPUT_NAMES = ("coating_winkler.json", "coating_winkler.md", "coating_winkler_map.png")
#: the errors of a model, in the JSON rows as ``<model>_<metric>``
METRICS = ("p_max", "radius", "approach", "rms", "worst")

#: the full study (SI units); ``rings``: rings across ``1.5`` contact radii
SETTINGS = dict(R=0.01, E_s=200e9, nu_s=0.3, a_H=1e-4,
                a_over_t=(0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0),
                modulus_ratios=(0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0),
                nu_c=(0.2, 0.35, 0.49), rings=300, refine=(150, 300, 600), refine_case=(1.0, 0.1, 0.35),
                fem_cases=((1.0, 0.1, 0.35), (0.2, 10.0, 0.2), (1.0, 0.01, 0.49)), fem_elements=(8, 16))
#: the small run (``contactlab study coating-winkler --quick``)
QUICK = dict(SETTINGS, a_over_t=(0.2, 5.0, 20.0), modulus_ratios=(0.01, 10.0), nu_c=(0.3, 0.49), rings=150,
             refine=(75, 150, 300), fem_cases=((1.0, 0.1, 0.35),), fem_elements=(8,))


@dataclass
class Profile:
    """An axisymmetric contact's answer: ``r`` [m] and ``p`` [Pa] along a radius (``p = 0`` beyond the
    last point), ``p_max`` [Pa], ``radius`` [m], ``approach`` [m], ``converged``, ``message``."""

    r: np.ndarray
    p: np.ndarray
    p_max: float
    radius: float
    approach: float
    converged: bool = True
    message: str = "converged"


def problem(s):
    """``(E_star, P, p_H, d_H)`` of the uncoated pair of settings ``s`` [Pa, N, Pa, m]."""
    E_star = s["E_s"] / (2.0 * (1.0 - s["nu_s"] ** 2))
    P = 4.0 * E_star * s["a_H"] ** 3 / (3.0 * s["R"])
    return E_star, P, 3.0 * P / (2.0 * math.pi * s["a_H"] ** 2), s["a_H"] ** 2 / s["R"]


def _coating(case, s):
    from bem.coating import Coating

    a_over_t, ratio, nu_c = case
    return Coating(s["a_H"] / a_over_t, ratio * s["E_s"], nu_c)


def _on_rings(s, force, *, lam=0.0, coating=None, L=None):
    """A ring solution, on rings over ``L`` (default: from a coarse pass), grown until the contact fits."""
    from .coating_rings import ring_compliance, solve_rings

    def once(L, n):
        r, edges, C = ring_compliance(L, n, E1=s["E_s"], nu1=s["nu_s"], E2=s["E_s"], nu2=s["nu_s"], coating2=coating)
        return solve_rings(r, edges, C, r**2 / (2.0 * s["R"]), force=force, lam=lam)

    if L is None:
        L, coarse = 4.0 * s["a_H"], None
        while coarse is None or not coarse.converged:
            L *= 2.0 if coarse is not None else 1.0
            coarse = once(L, 60)
        L = 1.5 * coarse.radius
    sol = once(L, s["rings"])
    while not sol.converged:
        L *= 1.5
        sol = once(L, s["rings"])
    return sol


def _profile(sol):
    return Profile(sol.r, sol.p, sol.p_max, sol.radius, sol.approach, sol.converged, sol.message)


def rings_truth(case, s):
    """The coated truth on rings (:mod:`validation.studies.coating_rings`) of ``case = (a_H/t, E_c/E_s, nu_c)``."""
    return _profile(_on_rings(s, problem(s)[1], coating=_coating(case, s)))


def fem_truth(case, s, *, n_contact_elements=16):
    """The coated truth by the FEM reference (:func:`fem_reference.solve` with ``coating2``)."""
    from bem.gaps import Paraboloid
    from fem_reference import solve

    res = solve(Paraboloid(s["R"]), E1=s["E_s"], nu1=s["nu_s"], E2=s["E_s"], nu2=s["nu_s"],
                coating2=_coating(case, s), force=problem(s)[1], n_contact_elements=n_contact_elements)
    return Profile(res.r, res.p, float(res.p_max), float(res.edge_radius), float(res.approach), bool(res.converged),
                   res.message)


#: the sources of the coated truth: name -> function ``(case, settings) -> Profile``
TRUTHS = {"rings": rings_truth, "fem": fem_truth}


class WinklerRings:
    """The sphere on the bare substrate with the layer ``w = lam p``, on rings sized for each ``lam``.

    The ring length is ``1.5`` times the larger of the truth's radius and the radius of the layer
    alone (``(4 P lam R^2 / pi)^(1/4)``), rounded up on a ladder of factors ``1.25``.
    """

    def __init__(self, s, truth_radius):
        self.s, self.base = s, 1.5 * truth_radius
        self.force = problem(s)[1]

    def __call__(self, lam):
        s = self.s
        alone = (4.0 * self.force * lam * s["R"] ** 2 / math.pi) ** 0.25
        L = self.base * 1.25 ** max(0, math.ceil(math.log(1.5 * alone / self.base) / math.log(1.25))) \
            if lam > 0 else self.base
        return _profile(_on_rings(s, self.force, lam=lam, L=L))


def _on_grid(profile, r):
    """The profile's pressure at ``r`` (linear between its points, 0 beyond its last loaded point + one)."""
    return np.interp(r, profile.r, profile.p, right=0.0)


def errors(model, truth):
    """Relative errors of the ``model`` :class:`Profile` against ``truth``: ``{metric: value}`` (:data:`METRICS`)."""
    r = np.linspace(0.0, 1.05 * max(model.radius, truth.radius), 2001)
    pm, pt = _on_grid(model, r), _on_grid(truth, r)
    out = dict(p_max=model.p_max / truth.p_max - 1.0, radius=model.radius / truth.radius - 1.0,
               approach=model.approach / truth.approach - 1.0,
               rms=float(math.sqrt(np.trapezoid((pm - pt) ** 2 * r, r) / np.trapezoid(pt**2 * r, r))))
    out["worst"] = max(abs(v) for v in out.values())
    return out


def best_lam(winkler, truth, lam_scale):
    """``(lam, errors)``: ``lam >= 0`` minimising the RMS pressure error (``lam = 0`` included).

    A scan of ``lam_scale 10^k``, ``k`` in ``-4 ... 3`` by halves, then Brent's method on ``log lam``
    in the bracket around the best scanned point.
    """
    from scipy.optimize import minimize_scalar

    rms = {}

    def f(x):
        if x not in rms:
            rms[x] = errors(winkler(lam_scale * 10.0**x), truth)["rms"]
        return rms[x]

    xs = np.arange(-4.0, 3.01, 0.5)
    k = int(np.argmin([f(x) for x in xs]))
    lo, hi = xs[max(k - 1, 0)], xs[min(k + 1, xs.size - 1)]
    x = minimize_scalar(f, bounds=(lo, hi), method="bounded", options=dict(xatol=1e-3)).x
    bare = errors(winkler(0.0), truth)
    if bare["rms"] <= f(x):
        return 0.0, bare
    lam = lam_scale * 10.0**x
    return lam, errors(winkler(lam), truth)


def run_case(case, s, truth=rings_truth):
    """One row of the map: the truth, the oedometric and the best layer at ``case``."""
    from bem.coating import oedometric_compliance

    _, P, p_H, d_H = problem(s)
    coating = _coating(case, s)
    t0 = time.perf_counter()
    true = truth(case, s)
    winkler = WinklerRings(s, true.radius)
    lam_oed = oedometric_compliance(coating)
    oed = errors(winkler(lam_oed), true)
    lam, best = best_lam(winkler, true, d_H / p_H)
    row = dict(a_over_t=case[0], modulus_ratio=case[1], nu_c=case[2], thickness=coating.thickness,
               truth_converged=true.converged, truth_message=true.message, p_max=true.p_max, radius=true.radius,
               approach=true.approach, lam_oed=lam_oed, lam_best=lam, lam_scale=d_H / p_H,
               wall_time_s=time.perf_counter() - t0)
    row.update({f"oed_{k}": v for k, v in oed.items()})
    row.update({f"best_{k}": v for k, v in best.items()})
    return row


def refinement(s):
    """The ring truth of ``s["refine_case"]`` at the ring counts ``s["refine"]``: values and changes."""
    levels = []
    for n in s["refine"]:
        p = rings_truth(s["refine_case"], dict(s, rings=n))
        levels.append(dict(rings=n, p_max=p.p_max, radius=p.radius, approach=p.approach))
    change = {k: [abs(b[k] / a[k] - 1.0) for a, b in zip(levels[:-1], levels[1:])]
              for k in ("p_max", "radius", "approach")}
    return dict(case=list(s["refine_case"]), levels=levels, change=change)


def fem_check(s):
    """The FEM reference against the ring truth on ``s["fem_cases"]`` at ``s["fem_elements"]``."""
    rows = []
    for case in s["fem_cases"]:
        ring = rings_truth(case, s)
        for n in s["fem_elements"]:
            t0 = time.perf_counter()
            fem = fem_truth(case, s, n_contact_elements=n)
            row = dict(a_over_t=case[0], modulus_ratio=case[1], nu_c=case[2], elements=n, converged=fem.converged,
                       wall_time_s=time.perf_counter() - t0, p_max=fem.p_max, radius=fem.radius,
                       approach=fem.approach)
            row.update({f"vs_rings_{k}": v for k, v in errors(fem, ring).items()})
            rows.append(row)
    return rows


def run_coating_winkler(settings=None, *, quick=False, truth="rings", fem=True, progress=None):
    """Run the study; returns a JSON-ready dict: ``rows`` (one per case, :func:`run_case`), ``refinement``
    (:func:`refinement`), ``fem_check`` (:func:`fem_check`, when ``fem``), ``rule`` (:func:`rule`),
    ``settings``. ``truth``: a key of :data:`TRUTHS` or a function ``(case, settings) -> Profile``;
    ``progress(label, done, total)``: one step per case."""
    s = dict(QUICK if quick else SETTINGS, **(settings or {}))
    source = TRUTHS[truth] if isinstance(truth, str) else truth
    cases = [(x, e, n) for n in s["nu_c"] for e in s["modulus_ratios"] for x in s["a_over_t"]]
    t0 = time.perf_counter()
    rows = [run_case(c, s, source) for c in each(cases, progress, lambda c: "a/t = {:g}, Ec/Es = {:g}, nu_c = {:g}"
                                                 .format(*c))]
    out = {"study": STEM, "mode": "quick" if quick else "full",
           "truth": truth if isinstance(truth, str) else getattr(truth, "__name__", "custom"),
           "settings": {k: _listed(v) for k, v in s.items()},
           "rows": rows, "wall_time_s": time.perf_counter() - t0, "refinement": refinement(s)}
    out["fem_check"] = fem_check(s) if fem else []
    out["rule"] = rule(rows)
    return out


#: the error levels of the map
LEVELS = (0.01, 0.05, 0.2)


def rule(rows, model="oed", level=0.05):
    """The rule a user applies without the map, measured on ``rows``: per ``nu_c``, the smallest ``a_H/t``
    from which the ``model``'s worst error stays within ``level`` for every ``a_H/t`` above, at each
    ``E_c/E_s``; ``None`` where it never does. ``{nu_c: {E_c/E_s: a_H/t or None}}`` (keys as strings)."""
    out = {}
    for nu in sorted({r["nu_c"] for r in rows}):
        per = {}
        for ratio in sorted({r["modulus_ratio"] for r in rows}):
            mine = sorted((r for r in rows if r["nu_c"] == nu and r["modulus_ratio"] == ratio),
                          key=lambda r: r["a_over_t"])
            start = None
            for r in reversed(mine):
                if r[f"{model}_worst"] > level:
                    break
                start = r["a_over_t"]
            per[f"{ratio:g}"] = start
        out[f"{nu:g}"] = per
    return out


def summary_lines(data):
    """The oedometric and the best layer's worst error per case: lines for a terminal."""
    return [f"a/t = {r['a_over_t']:g}, Ec/Es = {r['modulus_ratio']:g}, nu_c = {r['nu_c']:g}: oedometric "
            f"{r['oed_worst']:.1%}, best {r['best_worst']:.1%} (lam/lam_oed = "
            f"{r['lam_best'] / r['lam_oed']:.3g})" for r in data["rows"]]


def main(*, out=None, scene=None, quick=False, progress=None):
    """``contactlab study coating-winkler``: the whole map, or a small one when ``quick``; writes
    ``coating_winkler.json`` into the folder ``out`` (``None``: the current directory). The study
    takes no ``scene``."""
    no_scene("coating-winkler", scene)
    data = run_coating_winkler(quick=bool(quick), progress=progress)
    bad = [r for r in data["rows"] if not r["truth_converged"]]
    return save(out, STEM, data, status=1 if bad else 0)


def _listed(value):
    """Tuples as lists, nested (JSON)."""
    return [_listed(v) for v in value] if isinstance(value, (tuple, list)) else value
