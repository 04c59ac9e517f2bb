"""The figures of a run's report, drawn from its results (:class:`validation.report.documents.results.RunResults`).

Each figure function takes ``(res, work)`` (the results and the folder its files go to) and
returns a :class:`validation.report.render.Figure`, a list of them, or ``None`` when the results
cannot support it; :data:`validation.report.figures.FIGURES` registers them.

Units: those of the whole report (:meth:`RunResults.display`, one per quantity, as in its
tables): readable ones by default (lengths, layer closures included, in mm and pressures in MPa
for an SI scene), the scene's own (``contactlab report --units scene``), or lengths and pressures
divided by the contact's scales (``--units dimensionless``, :meth:`RunResults.scales`: Hertz's
``p_H``, ``a_H`` of a paraboloid, else the BEM peak ``p_max`` and the contact half-width ``a_c``);
profiles are drawn in a window around the contact (:func:`profile_view`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..render.content import Figure, fmt
from ..render.style import method_text
from .profiles import contact_edge

__all__ = ["scale", "axis_label", "Scaled", "ProfileView", "profile_view", "contact_edge", "how", "layer_law",
           "profiles", "pressure_map", "convergence", "fem_von_mises", "stress_view", "stress_figures"]

#: margin of a profile's window beyond the contact edge
PAD = 1.3
#: a contact whose half-widths differ by more than this factor is mapped with unequal axes
ELONGATED = 4.0
_REFERENCE = {"hertz": "Hertz (closed form)", "hertz_elliptic": "Hertz ellipse (closed form)",
              "rigid_layer": "rigid bodies on the layer (closed form)"}


def scale(res, kind):
    """``(factor, name, normalised)``: a ``kind`` (``"length"`` or ``"pressure"``) quantity is drawn
    as ``value / factor``; ``name`` is the symbol of the scale (dimensionless: ``"a_H"``,
    ``"p_H"``, ...) or the unit drawn in (``"mm"``): the report's unit of that quantity
    (:meth:`RunResults.display`), the same in every table and figure."""
    return res.display(kind)


def axis_label(symbol, sc, what=""):
    """Axis label of ``symbol`` drawn with the scale ``sc`` (:func:`scale`): ``what $x\\,/\\,a_H$``
    or ``what $x$ [mm]``."""
    _, name, normalised = sc
    if normalised:
        return rf"{what}${symbol}\,/\,{name}$"
    return f"{what}${symbol}$" + (f" [{name}]" if name and name != "-" else "")


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
        Normalised: the scales for captions (``"a_H = 0.0001866 m"``); else the display units.
    xlim : (float, float)
        Plotted abscissa range (in units of ``x_factor``), symmetric around 0.
    normalised : bool
        Whether the data are divided by the contact's scales (:func:`scale`).
    """

    x_factor: float
    p_factor: float
    x_label: str
    p_label: str
    x_name: str
    p_name: str
    xlim: tuple
    normalised: bool


def profile_view(res, curves, *, axis="x"):
    """Scales, labels and window of a profile along ``axis`` holding every loaded point of ``curves``.

    ``curves`` are the ``(x, p)`` data to be drawn [length], [pressure]. The window is
    ``(-h, h)``, ``h = PAD e`` with ``e`` the contact edge (:func:`contact_edge`), at least the
    length scale when normalised, but not beyond the first curve's data when that still shows
    the edge (``h >= 1.02 e``).
    """
    edge = contact_edge(curves)
    reach = float(np.abs(np.asarray(curves[0][0], dtype=float)).max(initial=0.0)) if curves else 0.0
    length, pressure = scale(res, "length"), scale(res, "pressure")
    (xf, xn, normalised), (pf, pn, _) = length, pressure
    if normalised:
        half = min(PAD * max(edge / xf, 1.0), max(reach, 1.02 * edge) / xf)
        xn, pn = (f"{n} = {fmt(f / e)} {u}".rstrip() for n, f, (e, u) in
                  ((xn, xf, res.engineering("length")), (pn, pf, res.engineering("pressure"))))
    else:
        edge = edge or float(max((np.abs(np.asarray(x, float)).max(initial=0.0) for x, _ in curves), default=1.0)) \
            or 1.0
        half = min(PAD * edge, max(reach, 1.02 * edge)) / xf
    return ProfileView(xf, pf, axis_label(axis, length), axis_label("p", pressure, "contact pressure "), xn, pn,
                       (-half, half), normalised)


def _tolerance(res):
    """The KKT tolerance of the run, ``bem.rtol``."""
    return float(res.bem.rtol)


def how(res):
    """One sentence: how the BEM solution was computed."""
    b, tol, length = res.bem, _tolerance(res), res.display("length")
    text = (f"BEM: {method_text(res.result.method, res.law, short=True)}; lattice step "
            f"c = {fmt(res.shown(b.step, 'length'))} {length.name}, {b.n_nodes} candidate nodes, "
            f"{b.n_contact} in contact")
    if b.nodes_across_contact:
        text += f" ({b.nodes_across_contact:.0f} across the contact)"
    return text + f"; KKT residual {fmt(res.result.kkt_residual)}" + (f" (tolerance {fmt(tol)})." if tol else ".")


def _fem_how(res):
    fem, h = res.fem, res.shown(res.fem.mesh.h_fine, "length")
    return (f"FEM: axisymmetric quadratic triangles, {fmt(fem.n_elements_across_contact, 3)} elements "
            f"across the contact radius (h = {fmt(h)} {res.display('length').name} "
            f"there), {fem.n_dofs} DOFs, interface nodal pressures.")


class Scaled:
    """A layer drawn in display units: ``w(p) = layer.w(p * pf) / wf``."""

    def __init__(self, layer, pf, wf):
        self.layer, self.pf, self.wf, self.law = layer, pf, wf, layer.law

    def w(self, p):
        return self.layer.w(p * self.pf) / self.wf

    def measured(self):
        """The tabulated law's points in display units, or ``None``."""
        from .profiles import measured_points

        points = measured_points(self.layer)
        return None if points is None else (points[0] / self.pf, points[1] / self.wf)


def layer_law(res, work):
    """The layer law w(p) the solver used over ``0 .. 1.25 max(p_max, p_cr, p_star)``, its kinks marked."""
    from .profiles import plot_layer_laws

    if res.layer is None:
        return None
    params = res.layer.to_dict()
    p_top = 1.25 * max(float(res.result.p_max or 0.0), *(float(params.get(k) or 0.0) for k in ("p_cr", "p_star")))
    if p_top <= 0:
        return None
    pressure, length = res.display("pressure"), res.display("length")  # the closure w is a length
    pf, wf = pressure.factor, length.factor
    # "= 0.74 p_H" or "= 1370 MPa"
    unit = rf" ${pressure.name}$" if pressure.normalised else f" {pressure.name}".replace(" -", "")
    marks = [(rf"$p_{{max}}$ (BEM) = {fmt(res.result.p_max / pf, 3)}{unit}", res.result.p_max / pf)]
    marks += [(f"{name} = {fmt(params[key] / pf, 3)}{unit}", params[key] / pf)
              for key, name in (("p_cr", r"$p_{cr}$"), ("p_star", r"$p^*$")) if params.get(key)]
    path = plot_layer_laws([(params["law"].replace("_", "-"), Scaled(res.layer, pf, wf))], work / "layer_law.png",
                           p_max=p_top / pf, marks=marks, p_label=axis_label("p", pressure, "pressure "),
                           w_label=axis_label("w(p)", length, "layer closure "),
                           title="interface layer law: closure $w(p)$ under the pressure $p$")
    return Figure(path, f"The layer law w(p) used by the solver ({params['law']}), rebuilt from the run's result with "
                        "bem.layers.from_dict and evaluated at 200 pressures from 0 to 1.25 times the largest of the "
                        "computed peak pressure and the law's kink pressures (marked)"
                        + ("; the circles are the table's points, between which the law is interpolated."
                           if params["law"] == "tabulated" else "."))


def _reference(res, axis):
    """``(label, s, p)``: the closed form's pressure along ``axis`` as the run recorded it, or None."""
    ref = res.result.analytic
    if ref is None:
        return None
    s, p = (ref.profile["x"], ref.profile["p"]) if axis == "x" else (ref.profile["y"], ref.profile["p_y"])
    return _REFERENCE.get(ref.kind, "closed form"), np.asarray(s, float), np.asarray(p, float)


def profiles(res, work):
    """Pressure along x (and along y for non-axisymmetric scenes), against the references."""
    from .profiles import plot_pressure_profiles, plot_profile_comparison

    figures, fem = [], res.result.fem_profile if res.axisymmetric else None
    prof = res.result.profile
    if prof is None:
        return figures
    fem = None if fem is None else {"r": fem.r, "p": fem.p}
    for axis in ("x",) if res.axisymmetric else ("x", "y"):
        line = {"x": prof.x, "p": prof.p} if axis == "x" else prof.y_axis
        if not line[axis] or not line["p"] or not np.any(np.asarray(line["p"]) > 0):
            continue
        data = np.asarray(line[axis], dtype=float), np.asarray(line["p"], dtype=float)
        ref = _reference(res, axis)
        curves = [data] + ([(np.asarray(fem["r"], float), np.asarray(fem["p"], float))] if fem else [])
        view = profile_view(res, curves, axis="r" if res.axisymmetric else axis)
        where = "the lattice row y = 0" if axis == "x" else "the line x = 0 (BEM field interpolated)"
        text = how(res) + (" " + _fem_how(res) if fem else "") + (f" {_scale_text(view)}" if view.normalised else "")
        path, labels = work / f"profile_{axis}.png", {"x": view.x_label, "p": view.p_label}
        if ref is None and not fem:
            path = plot_pressure_profiles([("BEM", data)], path, p0=view.p_factor, a=view.x_factor, xlim=view.xlim,
                                          labels=labels, title=f"contact pressure along {axis}",
                                          section="axial section $y = 0$" if axis == "x" else "section $x = 0$")
            figures.append(Figure(path, f"BEM contact pressure along {where}, nodal values. {text}"))
            continue
        solvers = [("BEM", *data, "bem")] + ([("FEM", fem["r"], fem["p"], "fem")] if fem and ref else [])
        reference = ref or ("FEM reference", fem["r"], fem["p"])
        against = ref[0] if ref else "the FEM reference"
        p_sym = view.p_name.split(" = ")[0]
        labels.update(err=rf"error $(p - p_{{ref}})\,/\,{p_sym}$" if view.normalised
                      else r"error $(p - p_{ref})\,/\,\max p_{ref}$",
                      err_of=f"${p_sym}$" if view.normalised else r"$\max p_{ref}$")
        e0 = None if view.normalised else float(np.max(reference[2]))
        path = plot_profile_comparison(solvers, path, p0=view.p_factor, a=view.x_factor, reference=reference,
                                       rmax=view.xlim[1], error_scale=e0, labels=labels,
                                       title=f"contact pressure along {'r' if res.axisymmetric else axis} "
                                             f"against {against}")
        figures.append(Figure(path, f"Contact pressure along {where} (upper panel) and its difference to {against} "
                                    f"at each solver's nodes (lower panel). {text}"))
    return figures


def _scale_text(view):
    """Caption sentence naming the scales of a dimensionless figure."""
    if view.x_name.startswith("a_H"):
        return f"Normalised by Hertz's peak {view.p_name} and radius {view.x_name} of the smooth problem."
    return f"Normalised by the BEM peak pressure {view.p_name} and the contact half-width along x {view.x_name}."


def pressure_map(res, work):
    """The BEM pressure over the plane with the contact boundary, or None without a field."""
    from .surfaces import plot_contact_map

    if res.bem_field is None or not np.any(res.bem_field[2] > 0):
        return None
    x, y, p = res.bem_field
    view = profile_view(res, [(np.hypot(x, y) if res.axisymmetric else np.maximum(abs(x), abs(y)), p)])
    labels = {"x": view.x_label, "y": axis_label("y", scale(res, "length")), "p": view.p_label}
    p_cr = (res.result.layer["parameters"] or {}).get("p_cr")
    levels = [(r"$p = p_{cr}$", p_cr)] if p_cr else []
    circle = res.result.contact_radius if res.axisymmetric else None
    kw = dict(a=view.x_factor, labels=labels)
    ex, ey = contact_edge([(x, p)]), contact_edge([(y, p)])
    elongated = not view.normalised and min(ex, ey) > 0 and max(ex, ey) > ELONGATED * min(ex, ey)
    if elongated:  # a roller: the axes stretched to fill the figure
        kw.update(aspect="auto", figsize=(8.2, 3.6))
    else:  # equal axes: a figure as wide as the drawn window (the contact patch within the data)
        half = 1.3 * max(ex, ey)  # the window of surfaces.contact_patch (margin 0.3)
        ratio = min(float(np.abs(x).max()), half) / max(min(float(np.abs(y).max()), half), 1e-300)
        if ratio > 1.3:
            kw["figsize"] = (min(8.6, 1.6 + 2.4 * ratio), 4.4)
    path = plot_contact_map((x, y, p), work / "contact_map.png", p0=view.p_factor, circle=circle, levels=levels,
                            title="BEM contact pressure over the plane", **kw)
    extra = " The dotted contour is p = p_cr (rigid branch of the layer inside)." if levels else ""
    if elongated:
        extra += (f" The contact is elongated (half-widths {fmt(res.shown(ex, 'length'))} and "
                  f"{fmt(res.shown(ey, 'length'))} {res.display('length').name}): "
                  "x and y are drawn to different scales, the y axis stretched.")
    return Figure(path, "BEM contact pressure over the contact plane, interpolated linearly on the lattice "
                        "triangles (bem_field.vtu); white: the contact boundary, midway between loaded and "
                        "unloaded nodes" + ("; dashed: the circle of equal area" if circle else "")
                  + f".{extra} {how(res)}")


def convergence(res, work):
    """Peak pressure and KKT residual per iteration, or None without a history."""
    from .iterations import plot_convergence

    hist = res.bem.history
    if not hist.get("p_max"):
        return None
    sc = scale(res, "pressure")
    name = method_text(res.result.method, res.law, short=True)
    path = plot_convergence([(f"BEM: {name}", hist)], work / "convergence.png", p0=sc[0], tol=_tolerance(res),
                            p_label=axis_label(r"\max\,p" if sc[2] else "p_{max}", sc, "max. pressure "),
                            title="BEM iterations: peak pressure and KKT residual")
    return Figure(path, f"Peak pressure (upper panel) and KKT residual (lower panel, log scale) of the "
                        f"{len(hist['p_max'])} recorded iterates on the finest lattice (a nested solve starts there "
                        "from the interpolated solution of the coarser lattices). " + how(res))


def _round_up(value):
    """``value > 0`` rounded up to two significant digits (0.57 -> 0.57, 0.571 -> 0.58)."""
    unit = 10.0 ** (math.floor(math.log10(value)) - 1)
    return math.ceil(value / unit * (1 - 1e-12)) * unit


def fem_von_mises(res, work):
    """Von Mises stress of the FEM reference in the (r, z) section, or None without its field."""
    from .fields import plot_section_field

    if res.fem_field is None:
        return None
    r, z, tri, vm = res.fem_field
    rc = float(res.fem.edge_radius or res.result.contact_radius or 0.0)
    (a, l_name, normalised), (p0, s_name, _) = scale(res, "length"), scale(res, "pressure")
    hertz = normalised and l_name == "a_H"  # the figure's default labels
    labels = None if hertz else {k: axis_label(k, (a, l_name, normalised)) for k in ("r", "z")}
    if rc > 0:
        window = 3.0 * (max(rc / a, 0.5) if normalised else rc / a)
    else:
        window = 3.0 if normalised else 0.5 * float(np.max(r)) / a
    path = plot_section_field(r, z, tri, vm, work / "fem_von_mises.png", a=a, scale=p0,
                              label=axis_label(r"\sigma_{vM}", (p0, s_name, normalised), "von Mises stress "),
                              window=_round_up(window), contact_radius=rc or None, labels=labels,
                              length_unit=None if hertz else (f"${l_name}$" if normalised else l_name),
                              title="FEM reference: von Mises stress in the (r, z) section")
    from .views3d import pyvista_or_none

    view = ("Left: the lower body (z <= 0) in 3-D, the section revolved about the axis with a quarter cut away, "
            "the contact patch outlined in cyan (rendered with pyvista); right: the section. "
            if pyvista_or_none() is not None else "")
    return Figure(path, view + "Von Mises stress of the FEM reference in the axial (r, z) section, mirrored about the "
                               "axis, from the stresses recovered at the mesh nodes (fem_field.vtu); the thick line "
                               "marks the contact. " + _fem_how(res))


def stress_view(res):
    """``(a, scale, length name, stress name, normalised)`` of the ``stress`` block's figures and tables:
    the units (or scales) of every other figure of the report, one unit per quantity."""
    (a, l_name, normalised), (s, s_name, _) = scale(res, "length"), scale(res, "pressure")  # as every figure
    return a, s, l_name, s_name, normalised


def _hertz_axis(res, z, nu):
    """Hertz's von Mises stress on the axis (Johnson 1985, eq. 3.45) [pressure], or None."""
    sc, ref = res.result.scales, res.result.analytic
    if ref is None or ref.kind != "hertz" or sc is None or not (sc.p_hertz and sc.a_hertz):
        return None
    p0, a = sc.p_hertz, sc.a_hertz
    zeta = np.maximum(np.asarray(z, dtype=float) / a, 1e-12)
    s_r = -(1.0 + nu) * (1.0 - zeta * np.arctan(1.0 / zeta)) + 0.5 / (1.0 + zeta**2)
    return p0 * np.abs(-1.0 / (1.0 + zeta**2) - s_r)


def stress_figures(res, work):
    """The x-z section map of the von Mises stress and the stresses on the axis, or None without stresses."""
    from .fields import plot_depth_profiles, plot_stress_section

    block = res.result.stress
    if block is None or not block.bodies:
        return None
    bodies = block.bodies
    a, s, l_name, s_name, normalised = stress_view(res)
    length = (a, l_name, normalised)
    z_label, s_label = axis_label("z", length), axis_label(r"\sigma", (s, s_name, normalised))
    sign = {"body1": 1.0, "body2": -1.0}
    panels = [(sign[name], b.section["x"], b.section["z"], b.section["von_mises"]) for name, b in bodies.items()]
    coated = [(name, b.coated.thickness) for name, b in bodies.items() if b.coated is not None]
    section = plot_stress_section(panels, work / "stress_section.png", a=a, scale=s,
                                  label="von Mises " + s_label.replace(r"\sigma", r"\sigma_{vM}"),
                                  contact_radius=res.result.contact_radius, fem=res.fem_field,
                                  labels={"x": axis_label("x", length), "z": z_label},
                                  title="von Mises stress in the section y = 0",
                                  interfaces=[sign[name] * t for name, t in coated])
    curves, marks = [], []
    for i, (name, b) in enumerate(bodies.items()):
        ax, key = b.axis, ("bem", "fem")[i % 2] if i else "bem"
        coat = "" if b.coated is None else ", coated"
        curves += [{"label": f"{name} (nu = {fmt(b.nu)}{coat}): von Mises", "z": ax["z"], "values": ax["von_mises"],
                    "key": key, "ls": "-"},
                   {"label": f"{name}: max shear", "z": ax["z"], "values": ax["tresca"], "key": key, "ls": ":"}]
        marks.append((b.depth_of_max, b.max_von_mises, "black"))
        if b.fem is not None:
            curves.append({"label": f"{name}: FEM von Mises", "z": b.fem.axis["z"],
                           "values": b.fem.axis["von_mises"], "key": "analytic", "ls": "none", "marker": "x"})
        depths = np.linspace(0.0, float(np.max(ax["z"])), 200)
        hertz = _hertz_axis(res, depths, float(b.nu)) if i == 0 else None
        if hertz is not None:
            curves.append({"label": f"Hertz, Johnson eq. 3.45 (nu = {fmt(b.nu)})", "z": depths, "values": hertz,
                           "key": "smooth", "ls": "--"})
    profiles_ = plot_depth_profiles(curves, work / "stress_profiles.png", a=a, scale=s, stress_label=s_label,
                                    depth_label=z_label.replace("$z", "depth $z"), marks=marks,
                                    title="stresses on the axis x = y = 0",
                                    interfaces=[(t, f"{name}: coating/substrate interface") for name, t in coated])
    depths = np.asarray(block.depths, dtype=float)
    text = (f"{depths.size} depths from {fmt(depths.min() / a)} to {fmt(depths.max() / a)} {l_name}"
            f" (down to {fmt(depths.max() / block.scale)} contact half-widths), every candidate node; "
            "bem.subsurface_stress: the BEM pressure (pyramids on the lattice) convolved with the stresses "
            "under one pyramid, frictionless, each body with its own Poisson ratio"
            + ("; a coated body: bem.coated_stress, in its coating and its substrate (the nu shown), the interface "
               "(dashed) evaluated from both sides, so that the stresses jump there." if coated else "."))
    overlay = " Dashed: the FEM reference's von Mises stress at the same levels." if res.fem_field is not None else ""
    crosses = " Crosses: FEM axis nodes." if any(b.fem is not None for b in bodies.values()) else ""
    return [Figure(section, "Von Mises stress of the BEM solution in the x-z section through the axis (lattice row "
                            "y = 0), body 1 above and body 2 below the interface; the thick line marks the contact."
                   + overlay + " " + text),
            Figure(profiles_, "Von Mises stress (solid) and maximum shear (dotted) on the axis against the depth; "
                              "circles: the maxima over the whole field." + crosses + " " + text)]
