"""Pressure along a line through the contact: the axial section (paper Fig. 5), the comparison
of solvers against a reference with the error underneath, and the layer laws ``w(p)`` (Fig. 4).

The axial section is the lattice row ``y = 0`` (lattice row ``j = 0`` holds nodes at
``x = c i`` exactly), so the curves are the computed nodal values, not interpolations.
Conventions: :mod:`validation.report.figures`.
"""

from __future__ import annotations

import numpy as np

from bem.checks import InputError, check_positive

from ...compare import axial_section
from ..render.style import SOLVER_COLORS, axis_labels, color_for, new_figure, save_figure

__all__ = ["axial_section", "section_of", "radial", "contact_edge", "auto_xlim", "curve_style",
           "plot_pressure_profiles", "plot_profile_comparison", "plot_layer_laws", "measured_points"]


def section_of(data, values=None):
    """``(x, p)`` of the axial section of a result, or of an ``(x, p)`` pair as given.

    ``data`` is a :class:`bem.ContactResult` (the lattice row ``y = 0``), an FEM result with
    radial arrays ``r, p`` (mirrored to ``x = -r .. r``), or a pair of arrays ``(x, p)``.
    ``values`` replaces ``p`` for a ContactResult (e.g. an iterate).
    """
    if hasattr(data, "lattice") and hasattr(data, "y"):
        return axial_section(data.x, data.y, data.p if values is None else values)
    if hasattr(data, "r") and hasattr(data, "p"):
        r, p = np.asarray(data.r, dtype=float), np.asarray(data.p, dtype=float)
        keep = r > 0
        return np.concatenate([-r[keep][::-1], r]), np.concatenate([p[keep][::-1], p])
    x, p = data
    return np.asarray(x, dtype=float), np.asarray(p, dtype=float)


def radial(x, p):
    """The half-profile ``x >= 0`` of a section, sorted by radius: ``(r, p)``."""
    x, p = np.asarray(x, dtype=float), np.asarray(p, dtype=float)
    keep = x >= 0
    order = np.argsort(x[keep], kind="stable")
    return x[keep][order], p[keep][order]


def contact_edge(curves):
    """Largest ``|x|`` of a loaded point (``p > 0``) over ``(x, p)`` curves [length]; 0 if none."""
    reach = [float(np.abs(np.asarray(x, float))[np.asarray(p, float) > 0].max(initial=0.0)) for x, p in curves]
    return max(reach, default=0.0)


def auto_xlim(sections, a, *, pad=1.15, least=1.3):
    """Symmetric range of ``x / a`` holding every loaded node of the ``(x, p)`` sections, with a margin."""
    half = max(contact_edge(sections) / a * pad, least)
    return (-half, half)


def curve_style(data, index):
    """Colour and line style of a result: colour by its layer law, dashes for paper methods."""
    layer = getattr(data, "layer", None)
    law = "smooth" if layer is None and hasattr(data, "lattice") else getattr(layer, "law", None)
    dashed = getattr(data, "method", "newton") in ("augmented_gap", "variable_compliance")
    return {"color": color_for(law, index), "linestyle": "--" if dashed else "-",
            "marker": "o" if dashed else None, "markersize": 3.5, "markevery": 2}


def plot_pressure_profiles(curves, path, *, p0, a, title=None, hertz=None, xlim=None, labels=None,
                           section=r"axial section $y = 0$"):
    """Pressure in the axial section ``y = 0``, ``p / p0`` against ``x / a`` (paper Fig. 5).

    Parameters
    ----------
    curves : sequence of (str, data) or (str, data, dict)
        Label and a :class:`bem.ContactResult` (or FEM result, or ``(x, p)`` arrays,
        :func:`section_of`); an optional third item overrides the matplotlib line style.
    hertz : (array_like, array_like), optional
        Hertz's pressure ``(x, p)`` [length], [pressure], drawn as a thin grey band.
    xlim : (float, float), optional
        Range of ``x / a``; default: the widest contact with a margin (:func:`auto_xlim`).
    section : str, optional
        Which line the profile lies on, appended to the x label (``None``: nothing).
    """
    p0, a = check_positive("p0", p0), check_positive("a", a)
    if not curves:
        raise InputError("curves = [] is not allowed: give at least one (label, result) pair.")
    sections = [section_of(item[1]) for item in curves]
    lab = axis_labels(labels)
    with new_figure((8.2, 4.0), title=title) as (fig, ax):
        if hertz is not None:
            ax.plot(np.asarray(hertz[0]) / a, np.asarray(hertz[1]) / p0, color="#999999", lw=3.5, alpha=0.45,
                    zorder=1, label="Hertz (closed form)")
        for i, (item, (x, p)) in enumerate(zip(curves, sections)):
            style = {**curve_style(item[1], i), **(item[2] if len(item) > 2 else {})}
            ax.plot(x / a, p / p0, label=item[0], zorder=3, **style)
        ax.set_xlim(*(xlim or auto_xlim(sections, a)))
        ax.set_ylim(bottom=0.0)
        ax.set_xlabel(lab["x"] + (f"  ({section})" if section else ""))
        ax.set_ylabel(lab["p"])
        fig.legend(loc="outside right upper", frameon=False)
        return save_figure(fig, path)


def plot_profile_comparison(curves, path, *, p0, a, reference=None, title=None, rmax=None, labels=None,
                            error_scale=None):
    """Radial pressure profiles of several solvers (upper panel) with their error against a
    reference, ``(p - p_ref) / error_scale`` at each curve's own nodes (lower panel).

    Parameters
    ----------
    curves : sequence of (str, r, p) or (str, r, p, str)
        Radial samples [length], [pressure]; only ``r >= 0`` is used. An optional 4th item
        names the solver (``"bem"``, ``"fem"``, ...) for its colour.
    reference : (str, callable) or (str, r, p), optional
        The reference ``p_ref(r)``, a closed form or samples (interpolated linearly); without
        it the first curve is the reference.
    rmax : float, optional
        Largest ``r / a`` shown (default: the widest loaded zone of the curves plus 25 %).
    labels : dict, optional
        ``{"x", "p", "err", "err_of"}``: also the error's label and what it is a fraction of.
    error_scale : float, optional
        Pressure the error is divided by [pressure] (default ``p0``).
    """
    p0, a = check_positive("p0", p0), check_positive("a", a)
    e0 = p0 if error_scale is None else check_positive("error_scale", error_scale)
    lab = {"x": r"radius $r\,/\,a_H$", "p": r"contact pressure $p\,/\,p_0$",
           "err": r"error $(p - p_{ref})\,/\,p_0$", "err_of": "$p_0$", **(labels or {})}
    if not curves:
        raise InputError("curves = [] is not allowed: give at least one (label, r, p) curve.")
    curves = list(curves)
    if reference is None:
        reference = tuple(curves.pop(0)[:3])
    if rmax is None:
        rmax = max(1.25 * contact_edge(c[1:3] for c in curves) / a, 1.2)
    if callable(reference[1]):
        ref_fn = reference[1]
        ref_r = np.linspace(0.0, rmax * a, 800)
        ref_p = np.asarray(ref_fn(ref_r), dtype=float)
    else:
        ref_r, ref_p = radial(reference[1], reference[2])

        def ref_fn(r):
            return np.interp(r, ref_r, ref_p, right=0.0)

    with new_figure((6.6, 5.4), title=title or f"pressure profiles against {reference[0]}", nrows=2,
                    sharex=True, gridspec_kw={"height_ratios": [3, 2]}) as (fig, (top, bot)):
        top.plot(ref_r / a, ref_p / p0, color=SOLVER_COLORS["analytic"], lw=1.3, ls="--", label=reference[0],
                 zorder=4)
        bot.axhline(0.0, color=SOLVER_COLORS["analytic"], lw=1.0, ls="--")
        worst = 0.0
        for i, item in enumerate(curves):
            color = color_for(item[3] if len(item) > 3 else None, i + 1)
            r, p = radial(item[1], item[2])
            err = (p - ref_fn(r)) / e0
            shown = r <= rmax * a
            top_err = float(np.abs(err[shown]).max(initial=0.0))
            worst = max(worst, top_err)
            marker = dict(marker="o", markersize=3) if r.size <= 80 else {}
            top.plot(r / a, p / p0, color=color, label=item[0], lw=1.5, **marker)
            bot.plot(r[shown] / a, err[shown], color=color, lw=1.2, **marker,
                     label=f"{item[0]}: max |error| {top_err:.2%} of {lab['err_of']}")
        top.set_xlim(0.0, rmax)
        top.set_ylim(bottom=0.0)
        top.set_ylabel(lab["p"])
        top.legend(loc="upper right", frameon=False)
        bot.set_xlabel(lab["x"])
        bot.set_ylabel(lab["err"])
        if worst > 0:
            bot.set_ylim(-1.15 * worst, 1.15 * worst)
        bot.legend(loc="lower left", frameon=False, fontsize=7.5)
        return save_figure(fig, path)


def measured_points(layer):
    """``(p, w)``: the points a tabulated law interpolates (``layer.measured()`` when it has one,
    e.g. a law drawn in display units), or ``None`` for a law given by a formula."""
    if layer is None:
        return None
    if hasattr(layer, "measured"):
        return layer.measured()
    params = layer.to_dict() if hasattr(layer, "to_dict") else {}
    if params.get("law") != "tabulated":
        return None
    return np.asarray(params["p"], dtype=float), np.asarray(params["w"], dtype=float)


def plot_layer_laws(laws, path, *, p_max, p_unit="", w_unit="", title=None, marks=(), p_label=None, w_label=None):
    """The layer laws ``w(p)`` on one plot (paper Fig. 4 b-d); a tabulated law's points as markers.

    Parameters
    ----------
    laws : sequence of (str, bem.layers.Layer or None)
        Label and law; ``None`` (smooth bodies, ``w = 0``) is drawn on the axis.
    p_max : float
        Largest pressure drawn [pressure].
    p_unit, w_unit : str
        Unit labels of pressure and closure (e.g. ``"MPa"``, ``"mm"``); blank when normalised.
    p_label, w_label : str, optional
        Axis labels (mathtext) replacing ``pressure $p$ [p_unit]`` and ``layer closure $w(p)$ [w_unit]``.
    marks : sequence of (str, float)
        Labelled vertical lines at special pressures (e.g. ``("p_cr", 0.24)``) [pressure].
    """
    p_max = check_positive("p_max", p_max)
    if not laws:
        raise InputError("laws = [] is not allowed: give at least one (label, layer) pair.")
    p = np.linspace(0.0, p_max, 600)
    w_top = 0.0
    with new_figure((6.0, 3.8), title=title) as (fig, ax):
        for i, (label, layer) in enumerate(laws):
            w = np.zeros_like(p) if layer is None else np.asarray(layer.w(p), dtype=float)
            w_top = max(w_top, float(np.max(w, initial=0.0)))
            color = color_for("smooth" if layer is None else getattr(layer, "law", None), i)
            ax.plot(p, w, color=color, label=label, lw=max(3.0 - 0.45 * i, 1.2),
                    linestyle="--" if layer is None else "-")
            points = measured_points(layer)
            if points is not None:
                shown = points[0] <= p_max
                ax.plot(points[0][shown], points[1][shown], "o", color=color, mfc="white", mew=1.4, ms=5.5,
                        clip_on=False, label=f"{label}: the table's points ({int(shown.sum())} of {points[0].size} "
                                             "in view)")
                w_top = max(w_top, float(np.max(points[1][shown], initial=0.0)))
        for k, (label, value) in enumerate(marks):
            ax.axvline(value, color="#666666", lw=0.9, ls=":")
            right = value > 0.6 * p_max  # label on the left of a line near the right border
            ax.annotate(label, (value, 1.0), xycoords=("data", "axes fraction"),
                        xytext=(-3 if right else 3, -12 - 11 * k), textcoords="offset points", fontsize=8.5,
                        color="#444444", ha="right" if right else "left")
        ax.set_xlim(0.0, p_max)
        ax.set_ylim(0.0, 1.15 * w_top if w_top > 0 else None)  # headroom for the labels of the marks
        ax.set_xlabel(p_label or "pressure $p$" + (f" [{p_unit}]" if p_unit else ""))
        ax.set_ylabel(w_label or "layer closure $w(p)$" + (f" [{w_unit}]" if w_unit else ""))
        ax.legend(loc="upper left", frameon=False)
        return save_figure(fig, path)
