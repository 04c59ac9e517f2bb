"""The "Subsurface stresses" section of a run's report (scenes with a ``[stress]`` section).

Drawn from ``result.json["stress"]`` (:func:`validation.run.stress.stress_summary`): the maxima per
body, the x-z section map of the von Mises stress with the contact, the depth profiles on the
axis, and, when the FEM reference ran, its recovered stresses overlaid (``fem_field.vtu``) and
the comparison of the maxima.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from .figures_stress import plot_depth_profiles, plot_stress_section
from .results import display_unit
from .run_figures import scales_of
from .sections import Figure, Section, Table, fmt

__all__ = ["stress_section"]

log = logging.getLogger(__name__)

_SIGN = {"body1": 1.0, "body2": -1.0}


def _view(res, bodies):
    """``(a, scale, length name, stress name, normalised)``."""
    scales = scales_of(res)
    if scales is not None:
        return scales[1], scales[0], scales[3], scales[2], True
    peak = max(float(b["max_von_mises"]) for b in bodies.values())
    depth = max(float(np.max(b["axis"]["z"])) for b in bodies.values())
    l_unit, a = display_unit(res.units.length, depth)
    s_unit, scale = display_unit(res.units.pressure, peak)
    return a, scale, l_unit, s_unit, False


def _hertz_axis(res, z, nu):
    """Hertz's von Mises stress on the axis (Johnson 1985, eq. 3.45) [pressure], or None."""
    sc = res.get("scales") or {}
    p0, a = sc.get("p_hertz"), sc.get("a_hertz")
    if (res.get("analytic") or {}).get("kind") != "hertz" or not (p0 and a):
        return None
    zeta = np.maximum(np.asarray(z, dtype=float) / a, 1e-12)
    s_z = -1.0 / (1.0 + zeta**2)
    s_r = -(1.0 + nu) * (1.0 - zeta * np.arctan(1.0 / zeta)) + 0.5 / (1.0 + zeta**2)
    return p0 * np.abs(s_z - s_r)


def _fem_field(res):
    if res.fem_field_path is None:
        return None
    from .figures_fem import section_field_from_vtu

    try:
        return section_field_from_vtu(res.fem_field_path)
    except Exception as exc:  # noqa: BLE001 - an unreadable field only drops the overlay
        log.warning("FEM stresses not overlaid: %s", exc)
        return None


def _table(res, bodies, a, scale, l_name, s_name):
    u = res.units
    rows = []
    for name, b in bodies.items():
        x, y, _ = b["location_of_max"]
        rows.append((name, fmt(b["nu"]), fmt(b["max_von_mises"] / scale), fmt(b["depth_of_max"] / a),
                     f"{fmt(x / a)}, {fmt(y / a)}", fmt(b["max_tresca"] / scale), fmt(b["depth_of_max_tresca"] / a)))
    columns = ("body", "nu", f"max von Mises / {s_name}", f"its depth / {l_name}", f"at x, y / {l_name}",
               f"max shear / {s_name}", f"its depth / {l_name}")
    caption = ("Largest von Mises stress and largest maximum shear (s1 - s3)/2 of each body over all candidate "
               "nodes and depths, refined in depth by a parabola through the largest sample and its neighbours. "
               f"Units: {s_name} = {fmt(scale)} {u.of('pressure')}, {l_name} = {fmt(a)} {u.of('length')}.")
    items = [Table(columns, tuple(rows), caption=caption)]
    fem_rows = [(name, fmt(b["fem"]["max_von_mises"] / scale), f"{100 * b['fem']['max_von_mises_rel']:+.2f} %",
                 fmt(b["fem"]["max_tresca"] / scale), f"{100 * b['fem']['max_tresca_rel']:+.2f} %",
                 fmt(b["fem"]["axis_depth_of_max"] / a), fmt(b["fem"]["bem_axis_depth_of_max"] / a),
                 f"{100 * b['fem']['axis_depth_of_max_rel']:+.2f} %", "yes" if b["fem"]["on_axis"] else "no")
                for name, b in bodies.items() if b.get("fem")]
    if fem_rows:
        items.append(Table(("body", f"FEM max von Mises / {s_name}", "BEM - FEM", f"FEM max shear / {s_name}",
                            "BEM - FEM", f"FEM depth of the axis max / {l_name}",
                            f"BEM depth of the axis max / {l_name}", "BEM - FEM", "largest value on the axis"),
                           tuple(fem_rows),
                           caption="BEM against the FEM reference: largest values over the body (FEM: recovered "
                                   "nodal stresses), relative differences (BEM - FEM) / FEM. Depth of the largest "
                                   "von Mises stress on the axis from a least-squares parabola through the axis "
                                   "values within 4 % of the largest, the BEM evaluated at the FEM's axis nodes (the "
                                   "maximum is flat, so the depth of the largest nodal value alone scatters with the "
                                   "nodes); it is the depth of the body's largest value where the last column says "
                                   "yes."))
    return items


def stress_section(res, work):
    """The report section of ``result.json["stress"]``, or None when the run computed no stresses."""
    block = res.get("stress")
    if not block or not block.get("bodies"):
        return None
    bodies = block["bodies"]
    a, scale, l_name, s_name, normalised = _view(res, bodies)
    labels = ({"x": rf"$x\,/\,{l_name}$", "z": rf"$z\,/\,{l_name}$"} if normalised
              else {"x": "$x$" + (f" [{l_name}]" if l_name else ""), "z": "$z$" + (f" [{l_name}]" if l_name else "")})
    s_label = (rf"$\sigma\,/\,{s_name}$" if normalised else r"$\sigma$" + (f" [{s_name}]" if s_name else ""))
    fem = _fem_field(res)
    panels = [(_SIGN[name], b["section"]["x"], b["section"]["z"], b["section"]["von_mises"])
              for name, b in bodies.items()]
    rc = res.data.get("contact_radius")
    section = plot_stress_section(panels, work / "stress_section.png", a=a, scale=scale,
                                  label="von Mises " + s_label.replace(r"\sigma", r"\sigma_{vM}"),
                                  contact_radius=rc, fem=fem and fem, labels=labels,
                                  title="von Mises stress in the section y = 0")
    curves, marks = [], []
    for i, (name, b) in enumerate(bodies.items()):
        ax = b["axis"]
        curves.append({"label": f"{name} (nu = {fmt(b['nu'])}): von Mises", "z": ax["z"], "values": ax["von_mises"],
                       "key": ("bem", "fem")[i % 2] if i else "bem", "ls": "-"})
        curves.append({"label": f"{name}: max shear", "z": ax["z"], "values": ax["tresca"],
                       "key": ("bem", "fem")[i % 2] if i else "bem", "ls": ":"})
        marks.append((b["depth_of_max"], b["max_von_mises"], "black"))
        if b.get("fem"):
            curves.append({"label": f"{name}: FEM von Mises", "z": b["fem"]["axis"]["z"],
                           "values": b["fem"]["axis"]["von_mises"], "key": "analytic", "ls": "none", "marker": "x"})
        hertz = _hertz_axis(res, np.linspace(0.0, float(np.max(ax["z"])), 200), float(b["nu"]))
        if hertz is not None and i == 0:
            curves.append({"label": f"Hertz, Johnson eq. 3.45 (nu = {fmt(b['nu'])})",
                           "z": np.linspace(0.0, float(np.max(ax["z"])), 200), "values": hertz, "key": "smooth",
                           "ls": "--"})
    profiles = plot_depth_profiles(curves, work / "stress_profiles.png", a=a, scale=scale, stress_label=s_label,
                                   depth_label=labels["z"].replace("$z", "depth $z"), marks=marks,
                                   title="stresses on the axis x = y = 0")
    depths = np.asarray(block["depths"], dtype=float)
    how = (f"{depths.size} depths from {fmt(depths.min())} to {fmt(depths.max())} {res.units.of('length')}"
           f" (down to {fmt(depths.max() / block['scale'])} contact half-widths), every candidate node; "
           "bem.subsurface_stress: the BEM pressure (pyramids on the lattice) convolved with the stresses "
           "under one pyramid, frictionless, each body with its own Poisson ratio.")
    overlay = " Dashed: the FEM reference's von Mises stress at the same levels." if fem is not None else ""
    items = _table(res, bodies, a, scale, l_name, s_name) + [
        Figure(section, "Von Mises stress of the BEM solution in the x-z section through the axis (lattice row "
                        "y = 0), body 1 above and body 2 below the interface; the thick line marks the contact."
                        + overlay + " " + how),
        Figure(profiles, "Von Mises stress (solid) and maximum shear (dotted) on the axis against the depth; "
                         "circles: the maxima over the whole field." + (" Crosses: FEM axis nodes." if any(
                             b.get("fem") for b in bodies.values()) else "") + " " + how)]
    text = "The contact pressure matters for the strength of the parts through the stresses it causes below " \
           "the surface: yielding starts where the von Mises stress (or the maximum shear) is largest, below " \
           "the surface for a smooth contact."
    if math.isfinite(float(block.get("wall_time_s") or 0.0)):
        text += f" Computed in {fmt(float(block['wall_time_s']), 3)} s."
    return Section("Subsurface stresses", kind="results", text=(text,), items=tuple(items))
