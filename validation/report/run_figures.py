"""Figures of a run's report: axial-section profiles (against the references), contact map,
convergence history and the FEM's von Mises field, all drawn from the result directory.

Units: by default the figures are drawn in the scene's units, lengths in mm and pressures in MPa
for an SI scene (:func:`validation.report.results.report_unit`), in a window around the contact
(:func:`profile_view`). A dimensionless report (``RunResults.dimensionless``, ``contactlab report
--units dimensionless``) divides them by the contact's scales: Hertz's peak ``p_H`` and radius
``a_H`` of a paraboloid scene (``result["scales"]``, paper Fig. 5), else the BEM peak pressure
``p_max`` and the contact half-width ``a_c`` along x.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from .results import report_unit
from .sections import Figure, fmt

__all__ = ["ProfileView", "profile_view", "contact_edge", "profile_figures", "contact_map_figure",
           "convergence_figure", "von_mises_figure", "scales_of"]

log = logging.getLogger(__name__)

#: margin of a profile's window beyond the contact edge
PAD = 1.3
#: a contact whose half-widths differ by more than this factor is mapped with unequal axes
ELONGATED = 4.0


@dataclass(frozen=True)
class ProfileView:
    """How a profile is drawn: plotted value = data / factor.

    Attributes
    ----------
    x_factor, p_factor : float
        Length [length] and pressure [pressure] scales.
    x_label, p_label : str
        Axis labels (mathtext).
    x_name, p_name : str
        Normalised: the scales for captions (``"a_H = 0.0001866 m"``); else the display units
        (``"mm"``, ``"GPa"``).
    xlim : (float, float)
        Plotted abscissa range (in units of ``x_factor``), symmetric around 0.
    normalised : bool
        Whether the scales are Hertz's (else display units).
    """

    x_factor: float
    p_factor: float
    x_label: str
    p_label: str
    x_name: str
    p_name: str
    xlim: tuple
    normalised: bool

    def axis_label(self, name):
        """Label of another length axis drawn with the same scale (e.g. ``"y"``)."""
        if self.normalised:
            return rf"${name}\,/\,{self.x_name.split(' = ')[0]}$"
        return f"${name}$" + (f" [{self.x_name}]" if self.x_name else "")


def scales_of(res):
    """``(p0, a, p_name, a_name)`` of a dimensionless report, or ``None`` (scene units).

    Hertz's peak and radius (``p_H``, ``a_H``) when the run recorded them, else the BEM peak
    pressure and the contact radius (or half-width along x): ``p_{max}``, ``a_c``.
    """
    if not res.dimensionless:
        return None
    sc = res.get("scales") or {}
    p0, a = sc.get("p_hertz"), sc.get("a_hertz")
    if p0 and a and p0 > 0 and a > 0:
        return float(p0), float(a), "p_H", "a_H"
    p0 = res.data.get("p_max")
    a = res.data.get("contact_radius") or (res.get("contact_extent") or {}).get("x")
    if p0 and a and p0 > 0 and a > 0:
        return float(p0), float(a), "p_{max}", "a_c"
    return None


def contact_edge(curves):
    """Largest ``|x|`` of a loaded point (``p > 0``) over ``(x, p)`` curves [length]; 0 if none."""
    reach = [float(np.abs(np.asarray(x, float))[np.asarray(p, float) > 0].max(initial=0.0)) for x, p in curves]
    return max(reach, default=0.0)


def profile_view(res, curves, *, axis="x"):
    """Scales, labels and window of a profile along ``axis`` holding every loaded point of ``curves``.

    Parameters
    ----------
    res : validation.report.results.RunResults
    curves : sequence of (x, p)
        The data to be drawn [length], [pressure].
    axis : {"x", "y", "r"}
        Name of the abscissa.

    Returns
    -------
    ProfileView
        ``xlim = (-h, h)``, ``h = PAD e`` with ``e`` the contact edge (:func:`contact_edge`) in
        plotted units (at least the Hertz radius when normalised), but not beyond the first
        curve's data when that still shows the edge (``h >= 1.02 e``).
    """
    edge = contact_edge(curves)
    reach = float(np.abs(np.asarray(curves[0][0], dtype=float)).max(initial=0.0)) if curves else 0.0
    scales = scales_of(res)
    if scales is not None:
        p0, a, p_name, a_name = scales
        half = min(PAD * max(edge / a, 1.0), max(reach, 1.02 * edge) / a)
        return ProfileView(a, p0, rf"${axis}\,/\,{a_name}$", rf"contact pressure $p\,/\,{p_name}$",
                           f"{a_name} = {fmt(a)} {res.units.of('length')}".replace(" -", ""),
                           f"{p_name} = {fmt(p0)} {res.units.of('pressure')}".replace(" -", ""), (-half, half), True)
    if edge <= 0:
        edge = float(max((np.abs(np.asarray(x, float)).max(initial=0.0) for x, _ in curves), default=1.0)) or 1.0
    x_unit, xf = report_unit(res.units.length)
    p_unit, pf = report_unit(res.units.pressure)
    half = min(PAD * edge, max(reach, 1.02 * edge)) / xf
    return ProfileView(xf, pf, f"${axis}$" + (f" [{x_unit}]" if x_unit else ""),
                       "contact pressure $p$" + (f" [{p_unit}]" if p_unit else ""),
                       x_unit, p_unit, (-half, half), False)


def _reference(res, axis):
    """``(label, p(s))`` of the closed form along ``axis`` (x or y through the centre), or None."""
    from . import run_problem
    from bem import reference as an

    ref = res.get("analytic")
    if not ref:
        return None
    gap, load = res.section("gap"), res.section("load")
    kw = {k: float(load[k]) for k in ("force", "approach") if k in load}
    e_star = float(res.bem.get("E_star", 0.0))
    kind = ref.get("kind")
    try:
        if kind == "hertz":
            sol = an.hertz_sphere(float(gap["R"]), e_star, **kw)
            return "Hertz (closed form)", sol.pressure
        if kind == "hertz_elliptic":
            sol = an.hertz_elliptic(float(gap["Rx"]), float(gap["Ry"]), e_star, **kw)
            if axis == "x":
                return "Hertz ellipse (closed form)", lambda s: sol.pressure(s, np.zeros_like(s))
            return "Hertz ellipse (closed form)", lambda s: sol.pressure(np.zeros_like(s), s)
        if kind == "rigid_layer":
            layer = run_problem.rebuild_layer(res)
            sol = an.rigid_layer_paraboloid(layer, float(gap["R"]), **kw)
            return "rigid bodies on the layer (closed form)", sol.pressure
    except (KeyError, TypeError, ValueError) as exc:
        log.warning("closed form not drawn: %s", exc)
    return None


def _how(res):
    """One sentence: how the BEM solution was computed."""
    from .run_problem import method_text, rebuild_layer

    b = res.bem
    law = getattr(rebuild_layer(res), "law", None)
    tol = b.get("rtol") or _tolerance(res.data.get("message"))
    text = (f"BEM: {method_text(res.data.get('method'), law, short=True)}; lattice step c = {fmt(b.get('step'))} "
            f"{res.units.of('length')}, {b.get('n_nodes', '?')} candidate nodes, {b.get('n_contact', '?')} in "
            f"contact")
    if b.get("nodes_across_contact"):
        text += f" ({b['nodes_across_contact']:.0f} across the contact)"
    text += f"; KKT residual {fmt(res.data.get('kkt_residual'))}" + (f" (tolerance {fmt(tol)})" if tol else "")
    return text + "."


def _fem_how(res):
    fem = res.fem
    mesh = fem.get("mesh") or {}
    return (f"FEM: axisymmetric quadratic triangles, {fmt(fem.get('n_elements_across_contact'), 3)} elements "
            f"across the contact radius (h = {fmt(mesh.get('h_fine'))} {res.units.of('length')} there), "
            f"{fem.get('n_dofs', '?')} DOFs, interface nodal pressures.")


def _section_data(res, axis):
    prof = res.get("profile") or {}
    if axis == "y":
        prof = prof.get("y_axis") or {}
        x = prof.get("y")
    else:
        x = prof.get("x")
    if not x or not prof.get("p"):
        return None
    return np.asarray(x, dtype=float), np.asarray(prof["p"], dtype=float)


def profile_figures(res, work):
    """Pressure along x (and along y for non-axisymmetric scenes), against the references."""
    from .figures_profiles import plot_pressure_profiles
    from .figures_validation import plot_profile_comparison

    figures = []
    axes = ("x",) if res.axisymmetric else ("x", "y")
    fem = res.get("fem_profile") if res.axisymmetric else None
    for axis in axes:
        data = _section_data(res, axis)
        if data is None or not np.any(data[1] > 0):
            continue
        ref = _reference(res, axis)
        curves = [data]
        if fem:
            curves.append((np.asarray(fem["r"], float), np.asarray(fem["p"], float)))
        view = profile_view(res, curves, axis="r" if res.axisymmetric else axis)
        line = "the lattice row y = 0" if axis == "x" else "the line x = 0 (BEM field interpolated)"
        how = _how(res) + (" " + _fem_how(res) if fem else "")
        scale = f" {_scale_text(view)}" if view.normalised else ""
        path = work / f"profile_{axis}.png"
        if ref is None and not fem:
            path = plot_pressure_profiles([("BEM", data)], path, p0=view.p_factor, a=view.x_factor, xlim=view.xlim,
                                          labels={"x": view.x_label, "p": view.p_label},
                                          section=("axial section $y = 0$" if axis == "x" else "section $x = 0$"),
                                          title=f"contact pressure along {axis}")
            figures.append(Figure(path, f"BEM contact pressure along {line}, nodal values. {how}{scale}"))
            continue
        curves = [("BEM", data[0], data[1], "bem")]
        if ref is not None:
            reference, against = ref, ref[0]
            if fem:
                curves.append(("FEM", fem["r"], fem["p"], "fem"))
        else:
            reference, against = ("FEM reference", fem["r"], fem["p"]), "the FEM reference"
        if view.normalised:
            e0 = None
        else:
            e0 = float(np.max(reference[2])) if ref is None else float(np.max(ref[1](np.abs(data[0]))))
        p_sym = view.p_name.split(" = ")[0]
        err = (rf"error $(p - p_{{ref}})\,/\,{p_sym}$" if view.normalised
               else r"error $(p - p_{ref})\,/\,\max p_{ref}$")
        path = plot_profile_comparison(curves, path, p0=view.p_factor, a=view.x_factor, reference=reference,
                                       rmax=view.xlim[1], error_scale=e0,
                                       labels={"x": view.x_label, "p": view.p_label, "err": err,
                                               "err_of": f"${p_sym}$" if view.normalised else r"$\max p_{ref}$"},
                                       title=f"contact pressure along {'r' if res.axisymmetric else axis} "
                                             f"against {against}")
        figures.append(Figure(path, f"Contact pressure along {line} (upper panel) and its difference to "
                                    f"{against} at each solver's nodes (lower panel). {how}{scale}"))
    return figures


def _scale_text(view):
    """Caption sentence naming the scales of a dimensionless figure."""
    if view.p_name.startswith("p_H"):
        return f"Normalised by Hertz's peak {view.p_name} and radius {view.x_name} of the smooth problem."
    return (f"Normalised by the BEM peak pressure {view.p_name} and the contact half-width along x "
            f"{view.x_name}.")


def contact_map_figure(res, work):
    """The BEM pressure over the plane with the contact boundary, or None without a field."""
    from .figures_3d import plot_contact_map

    if res.bem_field is None or not np.any(res.bem_field[2] > 0):
        return None
    x, y, p = res.bem_field
    view = profile_view(res, [(np.hypot(x, y) if res.axisymmetric else np.maximum(abs(x), abs(y)), p)])
    labels = {"x": view.axis_label("x"), "y": view.axis_label("y"), "p": view.p_label}
    params = (res.get("layer") or {}).get("parameters") or {}
    levels = [(r"$p = p_{cr}$", params["p_cr"])] if params.get("p_cr") else []
    circle = res.data.get("contact_radius") if res.axisymmetric else None
    kw = dict(a=view.x_factor, labels=labels)
    ex, ey = contact_edge([(x, p)]), contact_edge([(y, p)])
    elongated = not view.normalised and min(ex, ey) > 0 and max(ex, ey) > ELONGATED * min(ex, ey)
    if elongated:  # a roller: the axes stretched to fill the figure
        kw.update(aspect="auto", figsize=(8.2, 3.6))
    else:  # equal axes: a figure as wide as the drawn window (the contact patch within the data)
        half = 1.3 * max(ex, ey)  # the window of figures_3d.contact_patch (margin 0.3)
        ratio = min(float(np.abs(x).max()), half) / max(min(float(np.abs(y).max()), half), 1e-300)
        if ratio > 1.3:
            kw["figsize"] = (min(8.6, 1.6 + 2.4 * ratio), 4.4)
    path = plot_contact_map((x, y, p), work / "contact_map.png", p0=view.p_factor, circle=circle, levels=levels,
                            title="BEM contact pressure over the plane", **kw)
    extra = " The dotted contour is p = p_cr (rigid branch of the layer inside)." if levels else ""
    if elongated:
        extra += (f" The contact is elongated (half-widths {fmt(ex)} and {fmt(ey)} {res.units.of('length')}): "
                  "x and y are drawn to different scales, the y axis stretched.")
    return Figure(path, "BEM contact pressure over the contact plane, interpolated linearly on the lattice "
                        "triangles (bem_field.vtu); white: the contact boundary, midway between loaded and "
                        "unloaded nodes" + ("; dashed: the circle of equal area" if circle else "")
                  + f".{extra} {_how(res)}")


def convergence_figure(res, work):
    """Peak pressure and KKT residual per iteration, or None without a history."""
    from .figures_iterations import plot_convergence

    hist = res.bem.get("history") or {}
    if not hist.get("p_max"):
        return None
    scales = scales_of(res)
    if scales is not None:
        p0, label = scales[0], rf"max. pressure $\max\,p\,/\,{scales[2]}$"
    else:
        unit, p0 = report_unit(res.units.pressure)
        label = "max. pressure $p_{max}$" + (f" [{unit}]" if unit else "")
    tol = res.bem.get("rtol") or _tolerance(res.data.get("message"))
    from .run_problem import method_text, rebuild_layer

    name = method_text(res.data.get("method"), getattr(rebuild_layer(res), "law", None), short=True)
    path = plot_convergence([(f"BEM: {name}", hist)], work / "convergence.png", p0=p0,
                            tol=tol, p_label=label, title="BEM iterations: peak pressure and KKT residual")
    n = len(hist["p_max"])
    return Figure(path, f"Peak pressure (upper panel) and KKT residual (lower panel, log scale) of the {n} recorded "
                        "iterates on the finest lattice (a nested solve starts there from the interpolated solution "
                        "of the coarser lattices). " + _how(res))


def _round_up(value):
    """``value > 0`` rounded up to two significant digits (0.57 -> 0.57, 0.571 -> 0.58)."""
    unit = 10.0 ** (math.floor(math.log10(value)) - 1)
    return math.ceil(value / unit * (1 - 1e-12)) * unit


def _tolerance(message):
    """The KKT tolerance quoted in the solver's message (``... rtol 1.0e-10``), or None."""
    import re

    m = re.search(r"rtol\s+([0-9.eE+-]+)", str(message or ""))
    try:
        return float(m.group(1)) if m else None
    except ValueError:
        return None


def von_mises_figure(res, work):
    """Von Mises stress of the FEM reference in the (r, z) section, or None without its field."""
    from .figures_fem import plot_section_field, section_field_from_vtu

    if res.fem_field_path is None:
        return None
    r, z, tri, vm = section_field_from_vtu(res.fem_field_path)
    rc = float(res.fem.get("contact_radius") or res.data.get("contact_radius") or 0.0)
    scales = scales_of(res)
    if scales is not None:
        p0, a, p_name, a_name = scales
        labels = None if a_name == "a_H" else {k: rf"${k}\,/\,{a_name}$" for k in ("r", "z")}
        l_unit, label = (None if a_name == "a_H" else f"${a_name}$"), rf"von Mises stress $\sigma_{{vM}}\,/\,{p_name}$"
    else:
        l_unit, a = report_unit(res.units.length)
        s_unit, p0 = report_unit(res.units.pressure)
        labels = {"r": f"$r$ [{l_unit}]" if l_unit else "$r$", "z": f"$z$ [{l_unit}]" if l_unit else "$z$"}
        label = r"von Mises stress $\sigma_{vM}$" + (f" [{s_unit}]" if s_unit else "")
    if rc > 0:
        window = 3.0 * (max(rc / a, 0.5) if scales is not None else rc / a)
    else:
        window = 3.0 if scales is not None else 0.5 * float(np.max(r)) / a
    path = plot_section_field(r, z, tri, vm, work / "fem_von_mises.png", a=a, scale=p0, label=label,
                              window=_round_up(window), contact_radius=rc or None, labels=labels,
                              length_unit=l_unit,
                              title="FEM reference: von Mises stress in the (r, z) section")
    return Figure(path, "Von Mises stress of the FEM reference in the axial (r, z) section, mirrored about the "
                        "axis, from the stresses recovered at the mesh nodes (fem_field.vtu); the thick line "
                        "marks the contact. " + _fem_how(res))
