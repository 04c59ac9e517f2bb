"""The paper's finding in stress terms: how much each layer law lowers the subsurface maximum and moves it.

The Fig. 5 cases (:mod:`validation.report.paper`, the same force for every law) with their
subsurface stresses (:func:`bem.subsurface_stress`, ``PaperResults.stress``): a table of the
largest von Mises stress and maximum shear, their depths and their change against the smooth
contact, and the von Mises profiles on the axis.
"""

from __future__ import annotations

import numpy as np

from .figures_stress import plot_depth_profiles
from .sections import Figure, Section, Table

__all__ = ["stress_section"]

_KEYS = {"smooth": "smooth", "linear Winkler": "linear", "elastic-rigid": "elastic_rigid", "root": "root",
         "bilinear": "bilinear"}


def _rows(res):
    pb, smooth = res.problem, res.stress["smooth"]
    rows = []
    for label, st in res.stress.items():
        x, y, _ = st.location_of_max
        rows.append((label, st.max_von_mises / pb.p0, f"{100 * (st.max_von_mises / smooth.max_von_mises - 1):+.1f} %",
                     st.depth_of_max / pb.a, f"{(st.depth_of_max - smooth.depth_of_max) / pb.a:+.3f}",
                     float(np.hypot(x, y)) / pb.a, st.max_tresca / pb.p0,
                     f"{100 * (st.max_tresca / smooth.max_tresca - 1):+.1f} %", res.base[label].p_max / pb.p0))
    return tuple(rows)


def _summary(res):
    pb, st = res.problem, res.stress
    smooth = st["smooth"]
    parts = []
    for label, s in st.items():
        if label == "smooth":
            continue
        shift = (s.depth_of_max - smooth.depth_of_max) / pb.a
        parts.append(f"{label} {100 * (1 - s.max_von_mises / smooth.max_von_mises):.0f} % lower "
                     f"(p_max {100 * (1 - res.base[label].p_max / res.base['smooth'].p_max):.0f} % lower), "
                     f"{abs(shift):.3f} a_H {'deeper' if shift > 0 else 'shallower'}")
    deeper = [k for k, s in st.items() if s.depth_of_max > smooth.depth_of_max and k != "smooth"]
    shallower = [k for k, s in st.items() if s.depth_of_max < smooth.depth_of_max and k != "smooth"]
    moves = []
    if deeper:
        moves.append(f"deeper with {', '.join(deeper)}")
    if shallower:
        moves.append(f"towards the surface with {', '.join(shallower)}")
    return (f"Smooth bodies: the largest von Mises stress is {smooth.max_von_mises / pb.p0:.3f} p0 at depth "
            f"{smooth.depth_of_max / pb.a:.3f} a_H below the centre (Hertz: 0.620 p0 at 0.481 a_H for nu = 0.3). "
            "With the same force it is, for the laws of Fig. 5: " + "; ".join(parts) + ". "
            + ("It moves " + " and ".join(moves) + "." if moves else ""))


def stress_section(res, work):
    """The section "Subsurface stresses of the layer laws", or None when no stresses were computed."""
    if not res.stress or "smooth" not in res.stress:
        return None
    pb = res.problem
    curves, marks = [], []
    for label, st in res.stress.items():
        n = st.nearest(0.0, 0.0)
        key = _KEYS.get(label, label)
        curves.append({"label": label, "z": st.z, "values": st.von_mises[:, n], "key": key})
        if np.hypot(*st.location_of_max[:2]) <= 0.5 * res.base[label].step:
            marks.append((st.depth_of_max, st.max_von_mises, "black"))
    path = plot_depth_profiles(curves, work / "fig_stress_profiles_laws.png", a=pb.a, scale=pb.p0,
                               stress_label=r"von Mises stress $\sigma_{vM}\,/\,p_0$",
                               depth_label=r"depth $z\,/\,a_H$", marks=marks,
                               title="von Mises stress on the axis, same force, each layer law")
    depths = next(iter(res.stress.values())).z
    table = Table(("case", "max von Mises / p0", "vs smooth", "its depth / a_H", "depth shift / a_H",
                   "its distance from the axis / a_H", "max shear / p0", "vs smooth", "p_max / p0"), _rows(res),
                  caption="Largest von Mises stress and largest maximum shear (s1 - s3)/2 over the body (every "
                          f"candidate node, {depths.size} depths from 0 to {depths.max() / pb.a:g} a_H, refined in "
                          f"depth by a parabola), nu = {pb.nu}; changes against the smooth contact. The peak contact "
                          "pressure p_max is repeated for comparison.")
    how = (f"bem.subsurface_stress of the Newton solutions of Fig. 5 (a_H/c = {pb.nodes_per_radius}), nu = {pb.nu} "
           "(both bodies alike), frictionless; circles: the maxima over the whole field where they lie on the axis.")
    text = (
        "The paper's conclusion is that the interface layer changes the contact pressure and, through it, the "
        "stress-strain state of the bodies. What matters for the strength of a heavily loaded part is the "
        "stress below the surface, where it yields first: here the same force is applied with each layer law "
        "and the largest von Mises stress is compared with that of the smooth contact.",
        _summary(res),
    )
    return Section("Subsurface stresses of the layer laws", kind="results", text=text,
                   items=(Figure(path, "Von Mises stress on the axis below the centre of the contact against the "
                                       "depth, for every law of Fig. 5 at the same force. " + how), table))
