"""The coated BEM against the FEM reference with the coating meshed: a sphere on a coated flat, both
methods refined, their convergence orders and extrapolated values compared.

The problem is the one of :mod:`validation.studies.coating_winkler`: an elastic sphere (radius ``R``,
the substrate's material ``E_s, nu_s``) pressed by the force of the Hertz radius ``a_H`` of the
uncoated pair on a flat coated with a bonded layer of thickness ``t = a_H / (a_H/t)``, modulus
``E_c`` and Poisson's ratio ``nu_c``. Each case ``(a_H/t, E_c/E_s, nu_c)`` is solved

- by the BEM (:func:`bem.solve` with ``coating2``) on lattices of step ``a_H / n``, ``n`` in
  ``bem_levels``;
- by the FEM reference (:func:`fem_reference.solve` with ``coating2``, quadratic triangles, the
  coating its own material) with ``n_contact_elements`` in ``fem_levels``, each level with
  ``fem_across * n / fem_levels[0]`` elements across the coating in the contact zone (so that a thin
  coating's elements are halved with the level too) and an edge band ``refine_edge = fem_refine_edge``
  (the interface elements around the computed contact edge that many times smaller).

Measured per level: ``p_max``, the contact radius (the edge of the loaded zone, :func:`bem_edge`
for the BEM; :func:`fem_reference.result.edge_radius` for the FEM) and the approach. Per method and
quantity, from the last three levels (each step half the one before): the observed order
``log2(|q1 - q2| / |q2 - q3|)`` and the Richardson value ``q3 + (q3 - q2) / (2^order - 1)``
(:func:`richardson`). The BEM-vs-FEM differences of the extrapolated and of the finest values. The RMS
of ``p(r)``: at the finest levels with the FEM's ``p(r)`` linear between its nodes (:func:`rms_nodes`,
``rms``), and per paired level (``pressure``) with it edge-aware (:func:`fem_profile`; linear with a
layer, whose pressure has no square-root edge), split into the interior and the edge band
(:func:`rms_parts`), with its order and extrapolation. One case carries a root layer ``w = lam sqrt(p)`` on the coating
(``root_case``, ``root_lam`` in units of ``d_H / sqrt(p_H)``); every case without a layer whose edge-aware RMS
of ``p(r)`` at the finest levels, or whose difference of an extrapolated ``p_max``, radius or approach, is above
``refine_above``, or one of whose levels did not converge, is solved one level finer in each method (:func:`refined_pressure`): the RMS of ``p(r)`` of
every BEM level against every FEM level, and each method's scalars with their orders and extrapolations from
its last three levels (``after``). Interface stresses:
:mod:`validation.studies.coating_fem_stress`.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..progress import each
from . import no_scene, save
from .coating_winkler import _coating, _listed, problem

__all__ = ["SETTINGS", "QUICK", "QUANTITIES", "EDGE_BAND", "RMS_MEASURES", "STEM", "OUTPUT_NAMES", "richardson",
           "bem_edge", "fem_profile", "rms_parts", "rms_nodes",
           "bem_levels", "fem_levels", "compare_case", "refined_pressure", "run_coating_fem", "summary_lines", "main"]

STEM = __name__.rpartition(".")[2]
OUTPUT_NAMES = ("coating_fem.json", "coating_fem.md", "coating_fem.png")
#: the compared scalars of a solution
QUANTITIES = ("p_max", "radius", "approach")
#: the edge band of :func:`rms_parts`: ``r >= (1 - EDGE_BAND)`` times the FEM's contact radius
EDGE_BAND = 0.1
#: the RMS measures of ``p(r)`` per paired level: the FEM's ``p(r)`` linear (``linear``), edge-aware
#: (``total``; linear with a layer), and the latter's ``interior`` and ``edge`` parts (:func:`rms_parts`)
RMS_MEASURES = ("linear", "total", "interior", "edge")

#: the full study (SI units); ``*_levels``: ``a_H / step`` of the BEM, ``n_contact_elements`` of the FEM
SETTINGS = dict(R=0.01, E_s=200e9, nu_s=0.3, a_H=1e-4, a_over_t=(0.1, 1.0, 10.0),
                modulus_ratios=(0.01, 0.1, 10.0, 100.0), nu_c=(0.25, 0.45), bem_levels=(20, 40, 80),
                fem_levels=(6, 12, 24), fem_across=4, fem_refine_edge=4, root_case=(1.0, 0.1, 0.25), root_lam=0.1,
                stresses=True, refine_above=0.005)
#: the small run (``contactlab study coating-fem --quick``): one case
QUICK = dict(SETTINGS, a_over_t=(1.0,), modulus_ratios=(10.0,), nu_c=(0.25,), root_case=None, refine_above=None)


def richardson(values):
    """``(order, extrapolated)`` from the last three values of a sequence on steps halved each time.

    ``order = log2(|q1 - q2| / |q2 - q3|)``; the extrapolated value ``q3 + (q3 - q2) / (2^order - 1)``
    only where the differences keep their sign and the order lies in ``[0.5, 6]`` (else ``None``: the
    sequence is not in its asymptotic range, or has converged to round-off, and the finest value stands).
    """
    q1, q2, q3 = (float(v) for v in values[-3:])
    d1, d2 = q1 - q2, q2 - q3
    if d2 == 0.0 or d1 == 0.0:
        return None, None
    order = math.log2(abs(d1 / d2))
    if d1 * d2 < 0 or not 0.5 <= order <= 6.0:
        return order, None
    return order, q3 - d2 / (2.0**order - 1.0)


def bem_edge(res, *, layer=False):
    """The edge of the BEM's loaded zone [length], from its nodes.

    Smooth bodies: ``p^2`` (which vanishes linearly at a square-root edge) over the loaded nodes: a
    quadratic in ``r`` fitted to it within ``0.4`` area radii of the area radius gives a root, a second fit
    within three lattice steps of that root the edge. With a layer: the overlap taken by the layer,
    ``w(p)`` inside and ``-gap`` outside, which is smooth and changes sign at the edge (where the area
    radius lies within a step or two of it, and a wide quadratic misses it by several steps): two fits in
    turn within three lattice steps, the first around the area radius.
    """
    r = np.hypot(res.x, res.y)
    a = edge = res.contact_radius
    y = np.where(res.p > 0, res.layer.w(res.p), -res.gap) if layer else res.p**2
    for half in ((3.0 * res.step,) * 2 if layer else (0.4 * a, 3.0 * res.step)):
        band = np.abs(r - edge) < half
        if not layer:
            band &= res.p > 0
        if band.sum() < 4:
            break
        c = np.polynomial.polynomial.polyfit((r[band] - edge) / half, y[band] / np.abs(y[band]).max(), 2)
        roots = np.polynomial.polynomial.polyroots(c)
        roots = roots[np.isreal(roots)].real
        roots = roots[np.abs(roots) < 1.0]
        if not roots.size:
            break
        edge = float(edge + half * roots[np.argmin(np.abs(roots))])
    return float(edge)


def fem_profile(fem, r, *, edge_aware=False):
    """The FEM's ``p(r)`` [pressure] at the radii ``r``: linear between its nodes, zero beyond; ``edge_aware``:
    ``p^2`` linear between its loaded nodes and on to zero at its ``edge_radius`` (a square-root edge is
    linear in ``p^2``; without contact, zero)."""
    if not edge_aware:
        return np.interp(r, fem.r, fem.p, right=0.0)
    loaded = np.nonzero(fem.p > 0)[0]
    if not loaded.size:
        return np.zeros(np.shape(r))
    k = int(loaded[-1])
    return np.sqrt(np.interp(r, np.r_[fem.r[:k + 1], max(fem.edge_radius, fem.r[k])], np.r_[fem.p[:k + 1] ** 2, 0.0],
                             right=0.0))


def rms_parts(res, fem, *, edge_aware=True):
    """RMS of the BEM nodes' pressure against the FEM's ``p(r)`` (:func:`fem_profile`) at their radii,
    relative: ``sqrt(sum (p_n - p_FEM(r_n))^2 / sum p_FEM(r_n)^2)`` (a uniform lattice: area weights), as
    ``{"total", "interior", "edge"}``: the sums over every node, over ``r < (1 - EDGE_BAND) a_FEM`` and over
    the rest (``interior^2 + edge^2 = total^2``)."""
    r = np.hypot(res.x, res.y)
    pf = fem_profile(fem, r, edge_aware=edge_aware)
    sq, ref = (res.p - pf) ** 2, np.sum(pf**2)
    inside = r < (1.0 - EDGE_BAND) * fem.edge_radius
    return {k: float(math.sqrt(np.sum(sq[m]) / ref)) for k, m in (("total", slice(None)), ("interior", inside),
                                                                   ("edge", ~inside))}


def rms_nodes(res, fem):
    """:func:`rms_parts` ``["total"]`` with the FEM's ``p(r)`` linear between its nodes."""
    return rms_parts(res, fem, edge_aware=False)["total"]


def _gap(s):
    from bem.gaps import Paraboloid

    return Paraboloid(s["R"])


def bem_levels(case, s, layer=None, keep=None):
    """The BEM at every ``s["bem_levels"]``: ``(rows, finest result)``; each level's result appended to the
    list ``keep`` when given."""
    import bem

    rows, res = [], None
    for n in s["bem_levels"]:
        t0 = time.perf_counter()
        res = bem.solve(_gap(s), E1=s["E_s"], nu1=s["nu_s"], E2=s["E_s"], nu2=s["nu_s"], coating2=_coating(case, s),
                        force=problem(s)[1], step=s["a_H"] / n, extent="auto", layer=layer)
        rows.append(dict(level=n, converged=bool(res.converged), message=res.message, p_max=float(res.p_max),
                         radius=bem_edge(res, layer=layer is not None), area_radius=float(res.contact_radius),
                         approach=float(res.approach), iterations=int(res.iterations), nodes=int(res.p.size),
                         wall_time_s=time.perf_counter() - t0))
        if keep is not None:
            keep.append(res)
    return rows, res


def _across(s, n):
    """Elements across the coating at the FEM level ``n``: ``fem_across`` at the study's coarsest level
    (``fem_base``, default the first of ``fem_levels``), in proportion to ``n`` above it."""
    return max(s["fem_across"], round(s["fem_across"] * n / s.get("fem_base", s["fem_levels"][0])))


def _fem_level(case, s, layer, n, a_est=None):
    """One FEM level: its row and result."""
    from fem_reference import solve

    from .coating_fem_stress import fem_scalars

    t0 = time.perf_counter()
    res = solve(_gap(s), E1=s["E_s"], nu1=s["nu_s"], E2=s["E_s"], nu2=s["nu_s"], coating2=_coating(case, s),
                force=problem(s)[1], layer=layer, n_contact_elements=n, refine_edge=s["fem_refine_edge"],
                n_across_coating=_across(s, n), a_est=a_est)
    row = dict(level=n, converged=bool(res.converged), message=res.message, p_max=float(res.p_max),
               radius=float(res.edge_radius), approach=float(res.approach), elements=int(res.n_elements),
               a_est=res.mesh["a_est"], wall_time_s=time.perf_counter() - t0)
    if s.get("stresses") and res.converged:
        row["stress"] = fem_scalars(res, _coating(case, s))
    return row, res


def fem_levels(case, s, layer=None, keep=None):
    """The FEM reference at every ``s["fem_levels"]``: ``(rows, finest result)``; with ``s["stresses"]`` each
    converged level's row carries ``stress`` (:func:`~validation.studies.coating_fem_stress.fem_scalars`);
    each level's ``p(r)`` (``r``, ``p``, ``edge_radius``, ``converged``) appended to the list ``keep`` when given.

    A level that does not converge on the mesh sized by the estimated radius (the FEM's default ``a_est``, the
    substrate's Hertz radius) is solved once more on a mesh sized by the contact radius of the finest level that
    converged (as the FEM's own re-mesh does after a converged solve): a thick soft coating makes the contact
    several times larger than the estimate, and the coarsest meshes sized by the estimate can give a truncation
    correction that leaves the interface compliance indefinite. Its row keeps ``first``, the first attempt's row.
    """
    from types import SimpleNamespace

    rows, results = [], []
    for n in s["fem_levels"]:
        row, res = _fem_level(case, s, layer, n)
        rows.append(row)
        results.append(res)
    done = [res for res in results if res.converged]
    for i, res in enumerate(results):
        if not res.converged and done:
            first = rows[i]
            rows[i], results[i] = _fem_level(case, s, layer, s["fem_levels"][i], float(done[-1].edge_radius))
            rows[i]["first"] = first
    if keep is not None:
        keep.extend(SimpleNamespace(r=res.r, p=res.p, edge_radius=float(res.edge_radius), converged=res.converged)
                    for res in results)
    return rows, results[-1]


def _extrapolate(rows, names=QUANTITIES):
    out = {}
    for q in names:
        values = [r[q] for r in rows]
        order, value = richardson(values) if None not in values and len(values) >= 3 else (None, None)
        out[q] = dict(order=order, extrapolated=value, finest=values[-1])
    return out


def _best(x):
    return x["extrapolated"] if x["extrapolated"] is not None else x["finest"]


def _differences(bx, fx):
    """``BEM/FEM - 1`` per :data:`QUANTITIES` of two methods' :func:`_extrapolate` values: ``extrapolated``
    (the best value of each, :func:`_best`) and ``finest``."""
    return {q: dict(extrapolated=_best(bx[q]) / _best(fx[q]) - 1.0, finest=bx[q]["finest"] / fx[q]["finest"] - 1.0)
            for q in QUANTITIES}


def _pressure_levels(bs, fs, edge_aware=True):
    """The RMS measures of ``p(r)`` per paired level (coarsest first; ``None`` where a solve did not
    converge), their orders and extrapolations. ``edge_aware``: bodies without a layer, whose pressure has a
    square-root edge (read edge-aware); with a layer it vanishes smoothly and ``total`` reads it linearly."""
    rows = [dict(linear=rms_nodes(b, f), **rms_parts(b, f, edge_aware=edge_aware)) if b.converged and f.converged
            else dict.fromkeys(RMS_MEASURES) for b, f in zip(bs, fs)]
    return dict(levels=rows, **_extrapolate(rows, RMS_MEASURES))


def _stress_levels(case, s, bs, fem_rows, f):
    """Interface stresses: finest levels compared, and the per-level scalars of both methods."""
    from .coating_fem_stress import STRESS_SCALARS, bem_scalars, interface_stresses

    coating = _coating(case, s)
    out, points = interface_stresses(bs[-1], f, coating, s)
    b_rows = [bem_scalars(b, coating, s, points) for b in bs]
    f_rows = [r.get("stress", {q: None for q in STRESS_SCALARS}) for r in fem_rows]
    bx, fx = _extrapolate(b_rows, STRESS_SCALARS), _extrapolate(f_rows, STRESS_SCALARS)
    out["levels"] = dict(bem=b_rows, fem=f_rows, bem_x=bx, fem_x=fx,
                         diff={q: None if None in (_best(bx[q]), _best(fx[q])) or _best(fx[q]) == 0 else
                               _best(bx[q]) / _best(fx[q]) - 1.0 for q in STRESS_SCALARS})
    return out


def compare_case(case, s, *, layer=None, keep=None):
    """One case: both methods' levels, orders, extrapolated values, differences and interface stresses;
    the finest levels' pressures (the BEM's nodes ``x``, ``y``, ``p``; the profile of :func:`fem_levels`) stored in
    the dict ``keep`` (``"bem"``, ``"fem"``, with ``converged``) when given, for :func:`refined_pressure`."""
    from types import SimpleNamespace

    t0 = time.perf_counter()
    bs, fs = [], []
    b_rows, b = bem_levels(case, s, layer, bs)
    f_rows, f = fem_levels(case, s, layer, fs)
    bx, fx = _extrapolate(b_rows), _extrapolate(f_rows)
    diff = _differences(bx, fx)
    row = dict(a_over_t=case[0], modulus_ratio=case[1], nu_c=case[2], thickness=_coating(case, s).thickness,
               layer=None if layer is None else layer.to_dict(),
               converged=all(r["converged"] for r in b_rows + f_rows), bem=b_rows, fem=f_rows, bem_x=bx, fem_x=fx,
               diff=diff, rms=rms_nodes(b, f), pressure=_pressure_levels(bs, fs, layer is None))
    row["worst_extrapolated"] = max(abs(d["extrapolated"]) for d in diff.values())
    row["worst_finest"] = max(abs(d["finest"]) for d in diff.values())
    if s.get("stresses") and f.converged:
        row["stresses"] = _stress_levels(case, s, bs, f_rows, f)
    row["wall_time_s"] = time.perf_counter() - t0
    if keep is not None:
        b = bs[-1]
        keep.update(bem=SimpleNamespace(x=b.x, y=b.y, p=b.p, converged=bool(b.converged)), fem=fs[-1])
    return row


def refined_pressure(row, s, *, finest=None):
    """One level beyond the study's finest in each method for the case of ``row`` (of :func:`compare_case`): the
    BEM at the last two of ``bem_levels`` doubled once, the FEM likewise. ``rows``: every BEM level against every
    FEM level (``bem``, ``fem``, ``linear`` and the :func:`rms_parts`); ``bem``, ``fem``: the two levels' rows of
    :func:`bem_levels`, :func:`fem_levels`; ``after``: each method's orders and extrapolations of
    :data:`QUANTITIES` from its last three levels (the coarser ones from ``row``) and their differences
    (``diff``, as in :func:`compare_case`). ``finest``: the ``keep`` of :func:`compare_case` for this case (the
    study's finest levels are then not solved again)."""
    nb, nf = s["bem_levels"][-1], s["fem_levels"][-1]
    base = dict(s, stresses=False, fem_base=s["fem_levels"][0])  # the coating's elements keep the study's scale
    t0 = time.perf_counter()
    case = (row["a_over_t"], row["modulus_ratio"], row["nu_c"])
    bs, fs = ([], []) if finest is None else ([finest["bem"]], [finest["fem"]])
    if finest is None:
        bem_levels(case, dict(base, bem_levels=(nb,)), None, bs)
        fem_levels(case, dict(base, fem_levels=(nf,)), None, fs)
    b_rows, _ = bem_levels(case, dict(base, bem_levels=(2 * nb,)), None, bs)
    f_rows, _ = fem_levels(case, dict(base, fem_levels=(2 * nf,)), None, fs)
    b_rows = row["bem"][-1:] + b_rows
    f_rows = [{k: v for k, v in r.items() if k != "stress"} for r in row["fem"][-1:]] + f_rows
    rows = [dict(bem=i, fem=j, linear=rms_nodes(b, f), **rms_parts(b, f))
            for i, b in zip((nb, 2 * nb), bs) for j, f in zip((nf, 2 * nf), fs)]
    out = dict(a_over_t=case[0], modulus_ratio=case[1], nu_c=case[2], rows=rows, bem=b_rows, fem=f_rows,
               converged=all(x.converged for x in bs + fs))
    bx, fx = _extrapolate(row["bem"][:-1] + b_rows), _extrapolate(row["fem"][:-1] + f_rows)
    out["after"] = dict(bem_x=bx, fem_x=fx, diff=_differences(bx, fx))
    out["wall_time_s"] = time.perf_counter() - t0
    return out


def _root(s):
    from bem.layers import Root

    _, _, p_H, d_H = problem(s)
    return Root(s["root_lam"] * d_H / math.sqrt(p_H))


def run_coating_fem(settings=None, *, quick=False, progress=None):
    """Run the study; returns a JSON-ready dict: ``rows`` (one per case, :func:`compare_case`; the root
    layer's case last), ``settings``, ``wall_time_s``. ``progress(label, done, total)``: one step per case."""
    s = dict(QUICK if quick else SETTINGS, **(settings or {}))
    cases = [(c, None) for c in ((x, e, n) for n in s["nu_c"] for e in s["modulus_ratios"] for x in s["a_over_t"])]
    if s.get("root_case"):
        cases.append((tuple(s["root_case"]), _root(s)))
    t0 = time.perf_counter()
    kept = [{} for _ in cases]
    rows = [compare_case(c, s, layer=lay, keep=k) for (c, lay), k in
            zip(each(cases, progress, lambda c: "a/t = {:g}, Ec/Es = {:g}, nu_c = {:g}".format(*c[0])
                     + (" + root layer" if c[1] is not None else "")), kept)]
    above = [(r, k) for r, k in zip(rows, kept) if s.get("refine_above") is not None and r["layer"] is None
             and (_worst(r) > s["refine_above"] or _unordered(r))]
    refined = [refined_pressure(r, s, finest=k) for r, k in
               each(above, progress, lambda rk: "one level finer: a/t = {a_over_t:g}, Ec/Es = {modulus_ratio:g}, "
                    "nu_c = {nu_c:g}".format(**rk[0]))]
    return {"study": STEM, "mode": "quick" if quick else "full", "settings": {k: _listed(v) for k, v in s.items()},
            "rows": rows, "refined": refined, "wall_time_s": time.perf_counter() - t0}


def summary_lines(data):
    """Per case: the BEM-vs-FEM differences of the extrapolated values; lines for a terminal."""
    return [f"a/t = {r['a_over_t']:g}, Ec/Es = {r['modulus_ratio']:g}, nu_c = {r['nu_c']:g}"
            + (" (root layer)" if r["layer"] else "") + ": "
            + ", ".join(f"{q} {r['diff'][q]['extrapolated']:+.2%}" for q in QUANTITIES)
            + f", RMS p {r['rms']:.2%}" + _edge_aware(r) for r in data["rows"]]


def _finest_rms(row):
    """The edge-aware RMS of ``p(r)`` at the finest levels of a case (``None`` where not measured)."""
    return (row.get("pressure") or {}).get("total", {}).get("finest")


def _worst(row):
    """The largest of a case's edge-aware RMS of ``p(r)`` at the finest levels and its differences of the
    extrapolated :data:`QUANTITIES` (the measures :func:`refined_pressure` refines)."""
    return max([_finest_rms(row) or 0.0] + [abs(row["diff"][q]["extrapolated"]) for q in QUANTITIES])


def _unordered(row):
    """Whether a method of the case has a level that did not converge (its orders then rest on fewer than
    three levels; :func:`refined_pressure` adds one)."""
    return not all(r["converged"] for r in row.get("bem", []) + row.get("fem", []))


def _edge_aware(row):
    value = _finest_rms(row)
    return "" if value is None else f" (edge-aware {value:.2%})"


def main(*, out=None, scene=None, quick=False, progress=None):
    """``contactlab study coating-fem``: the whole grid, or one case when ``quick``; writes
    ``coating_fem.json`` into the folder ``out`` (``None``: the current directory). The study takes no
    ``scene``; the exit status is 1 when a solve did not converge."""
    no_scene("coating-fem", scene)
    data = run_coating_fem(quick=bool(quick), progress=progress)
    return save(out, STEM, data, status=0 if all(r["converged"] for r in data["rows"]) else 1)
