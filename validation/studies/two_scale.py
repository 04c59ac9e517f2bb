"""The two-scale check: a fully resolved rough sphere against the smooth sphere with the layer law of its roughness.

A sphere of radius ``R`` carries a seeded self-affine roughness (Hurst 0.8, roll-off wavelength
``lambda_L``, cut-off ``lambda_L/4``, on a periodic cell of ``4 lambda_L``, tiled): the resolved
model is :func:`bem.solve` with the gap :class:`~validation.studies.two_scale_models.TiledRoughness`
(paraboloid plus the roughness, exact at the lattice nodes). The layer model is the smooth sphere
with the law :func:`bem.rough.layer_from_topography` of the same cell; Greenwood and Tripp's
model (:func:`~validation.studies.two_scale_models.greenwood_tripp_law`) stands beside it.

With ``settings["hardness"] = H`` [pressure] the asperities are plastic: every solve caps the
pressure at ``H`` (:func:`bem.solve`): the resolved sphere, the law's ladder
(:func:`bem.rough.layer_from_topography`, tabulated up to ``HARDNESS_SHARE H`` at most) and the
smooth sphere with either law (its nominal pressure is at most ``H`` as well). ``None`` (the
default): elastic.

Cases: the ratio of the Hertz radius to the roll-off wavelength ``a_H/lambda_L`` (5, 10, 20) at
the lighter load ``P1``; a sphere with ``sigma R/a_H^2 = ALPHA`` (Greenwood and Tripp's
roughness parameter); loads ``P1`` and ``LOAD_RATIO P1``. Every model runs under force control.

Errors of a model against the resolved solution (relative to the resolved value):

- approach: both measured from the flat touching the plane of the cell's highest summit at the
  apex (the layer law's zero; the resolved solution's own first touch is ``first_touch_offset``
  earlier, reported);
- nominal radius: the radius of the circle about the apex that holds 99 % of the force
  (:func:`~validation.studies.two_scale_models.nominal_radius`), the same rule for every model;
- windowed pressure: the pressure averaged over square windows of side ``lambda_L`` centred at
  multiples of ``lambda_L`` (:func:`~validation.studies.two_scale_models.windowed`), the model's
  pressure averaged over the same windows; L2 over the windows inside the region, and the peak;
  also the L2 over windows of ``WIDE lambda_L``.

:func:`refinement` solves the resolved sphere at three lattice steps (``lambda_L/8, /16, /32``)
and gives the observed orders of the approach and of the windowed pressure.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..labels import fmt
from ..progress import each
from . import no_scene, save
from .two_scale_models import (TiledRoughness, greenwood_tripp_law, nominal_radius, spectral_moments,
                               windowed)

__all__ = ["SETTINGS", "QUICK", "make_surface", "run_case", "run_two_scale", "refinement", "summary_lines",
           "OUTPUT_NAMES", "main", "STEM", "HARDNESS_SHARE"]

#: the study's file is ``STEM + ".json"``, named after this module (:data:`validation.studies.STUDY_FILES`)
STEM = __name__.rpartition(".")[2]

#: the files of the study: its JSON (:func:`main`), Markdown and figures (the report)
OUTPUT_NAMES = ("two_scale.json", "two_scale.md", "two_scale_map.png", "two_scale_profile.png")

#: the full study (SI units)
SETTINGS = dict(E_star=115e9, hurst=0.8, roll_off=20e-6, cutoff_ratio=4, cell_roll_offs=4, rms_height=0.1e-6,
                seed=1, alpha=0.1, load_ratio=2.0, ratios=(5, 10, 20), nodes_per_roll_off=16, extent_factor=2.0,
                layer_nodes_across=80, rtol=1e-8, refine=(8, 16, 32), refine_ratio=5, hardness=None)
#: the small run ``rough_sphere_two_scale`` (``contactlab study two-scale --quick``)
QUICK = dict(SETTINGS, ratios=(3,), nodes_per_roll_off=8, layer_nodes_across=40, refine=(4, 8, 16), refine_ratio=3)
#: the law of plastic asperities is tabulated up to this share of the hardness at most (a cell's mean
#: pressure is below the hardness)
HARDNESS_SHARE = 0.9


def _plastic(s):
    """The keywords of :func:`bem.solve` for the hardness of settings ``s`` (none when elastic)."""
    return {} if s.get("hardness") is None else {"hardness": s["hardness"]}


def make_surface(s):
    """The roughness cell of settings ``s``: a :class:`bem.rough.RoughSurface` of ``cell_roll_offs`` roll-offs."""
    from bem import rough

    size = s["cell_roll_offs"] * s["roll_off"]
    n_cols = 4 * s["cell_roll_offs"]  # the coarsest lattice of the study (4 nodes per roll-off)
    n_rows = 2 * round(n_cols / math.sqrt(3))  # even, nearest 2 n_cols/sqrt(3): the cell is a lattice cell
    grid = 4 * s["cell_roll_offs"] * s["cutoff_ratio"]  # 4 points per cut-off wavelength
    return rough.self_affine((grid, grid), (size, size * n_rows * math.sqrt(3) / (2 * n_cols)),
                             hurst=s["hurst"], rms_height=s["rms_height"], long_cutoff=s["roll_off"],
                             short_cutoff=s["roll_off"] / s["cutoff_ratio"], seed=s["seed"])


def _sphere(s, ratio):
    """``(R, P1)``: the sphere with ``sigma R/a_H^2 = alpha`` and the load of the Hertz radius ``ratio lambda_L``."""
    a = ratio * s["roll_off"]
    R = s["alpha"] * a**2 / s["rms_height"]
    return R, 4 * s["E_star"] * a**3 / (3 * R)


#: the wider windows, in roll-off wavelengths: how much of the windowed error is the scatter of few asperities
WIDE = 4


def _windows(res, width, extent):
    ix, iy, mean, _ = windowed(res.x, res.y, res.p, width)
    inside = ((np.abs(ix) + 0.5) * width <= extent) & ((np.abs(iy) + 0.5) * width <= extent)
    return {(int(i), int(j)): float(m) for i, j, m in zip(ix[inside], iy[inside], mean[inside])}


def _summary(res, width, extent):
    """Approach, nominal radius and windowed pressure (windows of ``width`` and ``WIDE width``) of a result."""
    return dict(approach=float(res.approach), radius=nominal_radius(res.x, res.y, res.p),
                windows=_windows(res, width, extent), wide=_windows(res, WIDE * width, extent),
                p_max=float(res.p_max), converged=bool(res.converged), iterations=int(res.iterations),
                wall_time_s=float(res.wall_time_s), nodes=int(res.lattice.n_nodes))


def _window_errors(model, resolved):
    """``(L2, peak)`` relative errors of the window means ``model`` against ``resolved`` (common windows)."""
    keys = sorted(set(model) & set(resolved))
    pm = np.array([model[k] for k in keys])
    pr = np.array([resolved[k] for k in keys])
    return float(np.linalg.norm(pm - pr) / np.linalg.norm(pr)), float((pm.max() - pr.max()) / pr.max())


def _errors(model, resolved):
    l2, peak = _window_errors(model["windows"], resolved["windows"])
    return dict(approach=(model["approach"] - resolved["approach"]) / resolved["approach"],
                radius=(model["radius"] - resolved["radius"]) / resolved["radius"], l2=l2, peak=peak,
                l2_wide=_window_errors(model["wide"], resolved["wide"])[0])


def resolved_solve(s, surface, R, force, nodes_per_roll_off, extent):
    """The fully resolved rough sphere: :func:`bem.solve` with the tiled roughness at ``nodes_per_roll_off``."""
    import bem

    cell = surface.to_lattice(nodes_per_roll_off * s["cell_roll_offs"])
    gap = TiledRoughness(cell, R)
    return bem.solve(gap, E_star=s["E_star"], force=force, step=cell.step, extent=extent, rtol=s["rtol"],
                     **_plastic(s)), gap


def layer_laws(s, surface, p_max):
    """``(topography law, Greenwood-Tripp law)`` of the cell, tabulated up to ``p_max`` [pressure] (at most
    :data:`HARDNESS_SHARE` times the hardness)."""
    from bem import rough

    n_cols = s["nodes_per_roll_off"] * s["cell_roll_offs"]
    if s.get("hardness") is not None:
        p_max = min(p_max, HARDNESS_SHARE * s["hardness"])
    pressures = np.geomspace(1e-4, 1.0, 16) * p_max
    topo = rough.layer_from_topography(surface, s["E_star"], pressures=pressures, n_cols=n_cols, rtol=s["rtol"],
                                       **_plastic(s))
    moments = spectral_moments(surface.heights, surface.size)
    return topo, greenwood_tripp_law(moments, s["E_star"], topo.first_touch_gap, p_max)


def run_case(s, surface, laws, ratio, load_factor):
    """One row: the resolved sphere, the layer model and Greenwood-Tripp at ``ratio`` and ``load_factor P1``."""
    import bem

    R, P1 = _sphere(s, ratio)
    force = load_factor * P1
    a_hertz = (3 * force * R / (4 * s["E_star"])) ** (1 / 3)
    extent = s["extent_factor"] * a_hertz
    width = s["roll_off"]
    t0 = time.perf_counter()
    res, gap = resolved_solve(s, surface, R, force, s["nodes_per_roll_off"], extent)
    resolved = _summary(res, width, extent)
    first_touch = float(gap(res.x, res.y).min())
    row = dict(ratio=ratio, load_factor=load_factor, R=R, force=force, a_hertz=a_hertz,
               resolved_nodes=resolved["nodes"], resolved_converged=resolved["converged"],
               resolved_time_s=time.perf_counter() - t0, first_touch_offset=first_touch,
               approach=resolved["approach"], radius=resolved["radius"], p_window_max=max(resolved["windows"].values()))
    step = min(width / 8, 2 * a_hertz / s["layer_nodes_across"])
    models, results = {}, {}
    for name, law in zip(("layer", "gt"), laws):
        out = results[name] = bem.solve(bem.gaps.Paraboloid(R), E_star=s["E_star"], force=force, step=step, extent=extent,
                        layer=law, rtol=s["rtol"], **_plastic(s))
        models[name] = _summary(out, width, extent)
        row[f"{name}_converged"] = models[name]["converged"]
        row.update({f"{name}_{k}_err": v for k, v in _errors(models[name], resolved).items()})
    return row, dict(resolved=res, layer=results["layer"], gt=results["gt"], width=width, wide=WIDE * width,
                     extent=extent,
                     ratio=ratio, load_factor=load_factor)


def run_two_scale(settings=None, *, quick=False, keep=False, progress=None):
    """Run the two-scale check; returns a JSON-ready dict (``rows``, ``refinement``, ``settings``,
    ``figure``: what the figures of the first case draw,
    :func:`validation.studies.two_scale_figure.figure_data`).

    ``keep``: also return the fields of the first case (for the figures) under ``"fields"``;
    ``progress(label, done, total)`` (:mod:`validation.progress`): one step per case.
    """
    from .two_scale_figure import figure_data

    s = dict(QUICK if quick else SETTINGS, **(settings or {}))
    surface = make_surface(s)
    R, P1 = _sphere(s, min(s["ratios"]))  # the highest pressure: smallest sphere, heaviest load
    a = (3 * s["load_ratio"] * P1 * R / (4 * s["E_star"])) ** (1 / 3)
    p_max = 1.5 * 3 * s["load_ratio"] * P1 / (2 * math.pi * a**2)
    laws = layer_laws(s, surface, 4 * p_max)
    rows, fields = [], None
    cases = [(ratio, factor) for ratio in s["ratios"] for factor in (1.0, s["load_ratio"])]
    for ratio, factor in each(cases, progress, lambda c: "a_H/lambda_L = {:g}, P = {:g} P1".format(*c)):
        row, f = run_case(s, surface, (laws[0].law, laws[1]), ratio, factor)
        rows.append(row)
        fields = fields or f
    out = {"study": "two_scale", "mode": "quick" if quick else "full",
           "settings": {k: list(v) if isinstance(v, tuple) else v for k, v in s.items()},
           "surface": surface.stats.as_dict(), "first_touch_gap": float(laws[0].first_touch_gap),
           "rows": rows, "refinement": refinement(s, surface), "figure": figure_data(fields)}
    if keep:
        out["fields"] = fields
    return out


def refinement(s, surface):
    """The resolved sphere at the steps ``lambda_L/n``, ``n`` in ``s["refine"]``: approach, windowed pressure, orders.

    The roughness is the same band-limited surface at every step (its cut-off is carried by the
    coarsest lattice). Orders ``log2(|e_1 - e_2|/|e_2 - e_3|)``, of the approach and of the
    windowed pressure (L2 over the common windows).
    """
    R, P1 = _sphere(s, s["refine_ratio"])
    extent = s["extent_factor"] * s["refine_ratio"] * s["roll_off"]
    runs = []
    for n in s["refine"]:
        res, _ = resolved_solve(s, surface, R, P1, n, extent)
        runs.append(dict(nodes_per_roll_off=n, **_summary(res, s["roll_off"], extent)))
    keys = sorted(set.intersection(*(set(r["windows"]) for r in runs)))
    w = [np.array([r["windows"][k] for k in keys]) for r in runs]
    d = [r["approach"] for r in runs]
    dw = [np.linalg.norm(w[0] - w[1]), np.linalg.norm(w[1] - w[2])]
    ratio = s["refine"][1] / s["refine"][0]
    return dict(ratio=s["refine_ratio"], levels=[{k: v for k, v in r.items() if k not in ("windows", "wide")} for r in runs],
                approach_change=[abs(d[1] - d[0]), abs(d[2] - d[1])],
                window_change_rel=[float(x / np.linalg.norm(w[2])) for x in dw],
                order_approach=math.log(abs(d[1] - d[0]) / abs(d[2] - d[1])) / math.log(ratio),
                order_windows=math.log(dw[0] / dw[1]) / math.log(ratio))


#: the table's columns: (key, heading, format)
COLUMNS = (("ratio", "a_H/lambda_L", "d"), ("load_factor", "P/P1", "g"), ("resolved_nodes", "nodes", "d"),
           ("layer_approach_err", "approach, layer", "+.2e"), ("gt_approach_err", "approach, GT", "+.2e"),
           ("layer_radius_err", "radius, layer", "+.2e"), ("gt_radius_err", "radius, GT", "+.2e"),
           ("layer_l2_err", "windowed L2, layer", ".2e"), ("gt_l2_err", "windowed L2, GT", ".2e"),
           ("layer_peak_err", "windowed peak, layer", "+.2e"), ("gt_peak_err", "windowed peak, GT", "+.2e"),
           ("layer_l2_wide_err", f"L2 over {WIDE} lambda_L, layer", ".2e"),
           ("gt_l2_wide_err", f"L2 over {WIDE} lambda_L, GT", ".2e"),
           ("resolved_time_s", "resolved time [s]", ".1f"))


def table(data):
    """``(headings, rows)`` of the errors table."""
    heads = tuple(h for _, h, _ in COLUMNS)
    rows = [tuple(fmt(r[k], spec) for k, _, spec in COLUMNS) for r in data["rows"]]
    return heads, rows


def summary_lines(data):
    """The key errors of the layer model and of Greenwood-Tripp per case: lines for a terminal."""
    lines = []
    for r in data["rows"]:
        case = f"a_H/lambda_L = {r['ratio']:g}, P = {r['load_factor']:g} P1"
        for model, name in (("layer", "layer model"), ("gt", "Greenwood-Tripp")):
            lines.append(f"{case}, {name}: approach {r[f'{model}_approach_err']:+.2%}, radius "
                         f"{r[f'{model}_radius_err']:+.2%}, windowed pressure L2 {r[f'{model}_l2_err']:.2%} "
                         f"(over {WIDE} lambda_L {r[f'{model}_l2_wide_err']:.2%})")
    return lines


def main(*, out=None, scene=None, quick=False, progress=None):
    """``contactlab study two-scale``: the full check, or the small run ``rough_sphere_two_scale`` when
    ``quick``; writes ``two_scale.json`` into the folder ``out`` (``None``: the current directory) and
    returns the :class:`~validation.studies.StudyRun` with the fields of the first case (for its
    figures, :func:`validation.report.documents.studies.write_study_outputs`). Needs the ``rough``
    extra; the study takes no ``scene``."""
    from ..extras import require

    no_scene("two-scale", scene)
    require("rough", "the two-scale check (the self-affine surface)")
    data = run_two_scale(quick=bool(quick), keep=True, progress=progress)
    fields = data.pop("fields")
    return save(out, STEM, data, fields=fields)
