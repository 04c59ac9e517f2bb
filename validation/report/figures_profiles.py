"""Pressure in the axial section and the layer laws (the paper's Fig. 4 b-d and Fig. 5).

The axial section is the lattice row ``y = 0`` (lattice row ``j = 0`` holds nodes at
``x = c i`` exactly), so the curves are the computed nodal values, not interpolations.
"""

from __future__ import annotations

import numpy as np

from bem.checks import InputError, check_positive

from .style import axis_labels, color_for, new_figure, save_figure

__all__ = ["axial_section", "section_of", "auto_xlim", "curve_style", "plot_pressure_profiles", "plot_layer_laws"]


def axial_section(x, y, values, *, tol=None):
    """Nodes on the line ``y = 0``, sorted by ``x``.

    Parameters
    ----------
    x, y : array_like, shape (N,)
        Node coordinates [length].
    values : array_like, shape (N,)
        Nodal values (any unit).
    tol : float, optional
        ``|y| <= tol`` counts as on the line [length]; default ``1e-9 max|x|``.

    Returns
    -------
    xs, vs : ndarray
        Abscissae [length] and values on the section, ``xs`` increasing.
    """
    x, y, values = (np.asarray(v, dtype=float) for v in (x, y, values))
    if not (x.shape == y.shape == values.shape):
        raise InputError(f"x, y, values have shapes {x.shape}, {y.shape}, {values.shape} which is not allowed: "
                         "they must be equal.")
    tol = 1e-9 * float(np.abs(x).max(initial=1.0)) if tol is None else tol
    on = np.abs(y) <= tol
    if not on.any():
        raise InputError("x, y have no node on the axial section y = 0: the section needs nodes with |y| <= tol.")
    order = np.argsort(x[on], kind="stable")
    return x[on][order], values[on][order]


def section_of(data, values=None):
    """``(x, p)`` of the axial section of a result, or of an ``(x, p)`` pair as given.

    ``data`` is a :class:`bem.ContactResult` (the lattice row ``y = 0``), an FEM
    result with radial arrays ``r, p`` (mirrored to ``x = -r .. r``), or a pair of
    arrays ``(x, p)``. ``values`` replaces ``p`` for a ContactResult (e.g. an iterate).
    """
    if hasattr(data, "lattice") and hasattr(data, "y"):
        return axial_section(data.x, data.y, data.p if values is None else values)
    if hasattr(data, "r") and hasattr(data, "p"):
        r, p = np.asarray(data.r, dtype=float), np.asarray(data.p, dtype=float)
        keep = r > 0
        return np.concatenate([-r[keep][::-1], r]), np.concatenate([p[keep][::-1], p])
    x, p = data
    return np.asarray(x, dtype=float), np.asarray(p, dtype=float)


def auto_xlim(sections, a, *, pad=1.15, least=1.3):
    """Symmetric range of ``x / a`` holding every loaded node of the sections, with a margin."""
    reach = [float(np.abs(x[p > 0]).max()) for x, p in sections if np.any(p > 0)]
    half = max(max(reach, default=0.0) / a * pad, least)
    return (-half, half)


def curve_style(data, index):
    """Colour and line style of a result: colour by its layer law, dashes for paper methods."""
    layer = getattr(data, "layer", None)
    law = "smooth" if layer is None and hasattr(data, "lattice") else getattr(layer, "law", None)
    color = color_for(law, index) if law is not None else color_for(None, index)
    method = getattr(data, "method", "newton")
    dashed = method in ("augmented_gap", "variable_compliance")
    return {"color": color, "linestyle": "--" if dashed else "-",
            "marker": "o" if dashed else None, "markersize": 3.5, "markevery": 2}


def plot_pressure_profiles(curves, path, *, p0, a, title=None, hertz=False, xlim=None, labels=None,
                           section=r"axial section $y = 0$"):
    """Pressure in the axial section ``y = 0``, ``p / p0`` against ``x / a`` (paper Fig. 5).

    Parameters
    ----------
    curves : sequence of (str, data) or (str, data, dict)
        Label and a :class:`bem.ContactResult` (or FEM result, or ``(x, p)`` arrays);
        an optional third item overrides the matplotlib line style.
    path : path-like
        PNG file to write (atomically).
    p0 : float
        Hertz peak pressure of the smooth problem [pressure] (scale of the y axis).
    a : float
        Hertz contact radius [length] (scale of the x axis).
    title : str, optional
        Axes title.
    hertz : bool
        Also draw Hertz's ``p0 sqrt(1 - x^2/a^2)`` as a thin grey reference.
    xlim : (float, float), optional
        Range of ``x / a``; default: the widest contact with a margin (:func:`auto_xlim`).
    labels : dict, optional
        Axis labels ``{"x": ..., "p": ...}`` (:func:`validation.report.style.axis_labels`);
        default: normalised by the Hertz radius and peak.
    section : str, optional
        Which line the profile lies on, appended to the x label (``None``: nothing).

    Returns
    -------
    str
        ``path``.
    """
    p0, a = check_positive("p0", p0), check_positive("a", a)
    if not curves:
        raise InputError("curves = [] is not allowed: give at least one (label, result) pair.")
    sections = [section_of(item[1]) for item in curves]
    lab = axis_labels(labels)
    with new_figure((8.2, 4.0)) as (fig, ax):
        if hertz:
            s = np.linspace(-1.0, 1.0, 401)
            ax.plot(s, np.sqrt(1.0 - s**2), color="#999999", lw=3.5, alpha=0.45, zorder=1,
                    label="Hertz (analytic)")
        for i, item in enumerate(curves):
            label, data = item[0], item[1]
            style = curve_style(data, i)
            if len(item) > 2:
                style.update(item[2])
            x, p = sections[i]
            ax.plot(x / a, p / p0, label=label, zorder=3, **style)
        ax.set_xlim(*(xlim or auto_xlim(sections, a)))
        ax.set_ylim(bottom=0.0)
        ax.set_xlabel(lab["x"] + (f"  ({section})" if section else ""))
        ax.set_ylabel(lab["p"])
        if title:
            ax.set_title(title)
        fig.legend(loc="outside right upper", frameon=False)
        return save_figure(fig, path)


def plot_layer_laws(laws, path, *, p_max, p_unit="", w_unit="", title=None, marks=None):
    """The layer laws ``w(p)`` of the problem statement on one plot (paper Fig. 4 b-d).

    Parameters
    ----------
    laws : sequence of (str, bem.layers.Layer or None)
        Label and law; ``None`` (smooth bodies, ``w = 0``) is drawn on the axis.
    path : path-like
        PNG file to write.
    p_max : float
        Largest pressure drawn [pressure].
    p_unit, w_unit : str
        Unit labels of pressure and closure (e.g. ``"MPa"``, ``"um"``); blank in
        normalised units.
    title : str, optional
        Axes title.
    marks : sequence of (str, float), optional
        Labelled vertical lines at special pressures (e.g. ``("p_cr", 0.24)``).

    Returns
    -------
    str
        ``path``.
    """
    p_max = check_positive("p_max", p_max)
    if not laws:
        raise InputError("laws = [] is not allowed: give at least one (label, layer) pair.")
    p = np.linspace(0.0, p_max, 600)
    w_top = 0.0
    with new_figure((6.0, 3.8)) as (fig, ax):
        for i, (label, layer) in enumerate(laws):
            law = "smooth" if layer is None else getattr(layer, "law", None)
            w = np.zeros_like(p) if layer is None else np.asarray(layer.w(p), dtype=float)
            w_top = max(w_top, float(np.max(w, initial=0.0)))
            ax.plot(p, w, color=color_for(law, i), label=label, lw=max(3.0 - 0.45 * i, 1.2),
                    linestyle="--" if layer is None else "-")
        for k, (label, value) in enumerate(marks or ()):
            ax.axvline(value, color="#666666", lw=0.9, ls=":")
            right = value > 0.6 * p_max  # label on the left of a line near the right border
            ax.annotate(label, (value, 1.0), xycoords=("data", "axes fraction"), xytext=(-3 if right else 3,
                                                                                       -12 - 11 * k),
                        textcoords="offset points", fontsize=8.5, color="#444444", ha="right" if right else "left")
        ax.set_xlim(0.0, p_max)
        if w_top > 0:
            ax.set_ylim(0.0, 1.15 * w_top)  # headroom for the labels of the marks
        else:
            ax.set_ylim(bottom=0.0)
        ax.set_xlabel("pressure $p$" + (f" [{p_unit}]" if p_unit else ""))
        ax.set_ylabel("layer closure $w(p)$" + (f" [{w_unit}]" if w_unit else ""))
        if title:
            ax.set_title(title)
        ax.legend(loc="upper left", frameon=False)
        return save_figure(fig, path)
