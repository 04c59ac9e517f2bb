"""Families of axial-section curves (paper Fig. 5, 6, 9, 10), the transition line of the
elastic-rigid law (Fig. 7) and scalar results against a swept value.

For the elastic-rigid law ``w = lam min(p, p_cr)`` the contact splits into region I
(``p >= p_cr``: the layer is on its rigid branch) around the centre and region II
(``0 < p < p_cr``: elastic branch) around it; the transition radius is where the
axial-section pressure crosses ``p_cr``. Conventions: :mod:`validation.report.figures`.
"""

from __future__ import annotations

import numpy as np

from bem.checks import InputError, check_positive

from ..render.style import axis_labels, new_figure, save_figure
from .profiles import auto_xlim, radial

__all__ = ["transition_radius", "edge_radius", "plot_sweep", "plot_transition_line", "plot_sweep_scalars"]


def transition_radius(x, p, level):
    """Outermost radius where the section pressure ``p(x)`` [pressure] falls through ``level`` [length].

    Scans the half-profile ``x >= 0`` outwards from the last node with ``p >= level > 0`` and
    interpolates linearly to the crossing with the next node; 0 when no node reaches ``level``
    (region I is empty).
    """
    level = check_positive("level", level)
    r, q = radial(x, p)
    above = np.nonzero(q >= level)[0]
    if above.size == 0:
        return 0.0
    k = int(above[-1])
    if k + 1 >= r.size:
        return float(r[-1])
    return float(r[k] + (r[k + 1] - r[k]) * (q[k] - level) / (q[k] - q[k + 1]))


def edge_radius(x, p):
    """Radius of the contact edge on the section: midway between the last loaded node and the
    next one [length] (0 without contact)."""
    r, q = radial(x, p)
    loaded = np.nonzero(q > 0)[0]
    if loaded.size == 0:
        return 0.0
    k = int(loaded[-1])
    return float(r[k] if k + 1 >= r.size else 0.5 * (r[k] + r[k + 1]))


def plot_sweep(curves, path, *, p0, a, name, title=None, cmap="plasma", xlim=None, extra=(), labels=None,
               ticklabels=None, log=False):
    """A family of axial-section curves coloured by a parameter, with its colour bar.

    Parameters
    ----------
    curves : sequence of (float, array_like, array_like)
        ``(alpha, x, p)``: parameter value, section abscissae [length], pressures [pressure].
    name : str
        Parameter name for the colour bar (mathtext, e.g. ``r"$\\alpha_a$"``).
    cmap : str
        Matplotlib colormap (its lower 90 % is used).
    xlim : (float, float), optional
        Range of ``x / a`` (default: the widest contact with a margin).
    extra : sequence of (str, x, p, dict)
        Reference curves ``(label, x, p, style)`` drawn on top, with a legend.
    ticklabels : sequence of str, optional
        Colour-bar tick labels, one per curve (values that are not numbers: the curves then
        carry their index as ``alpha``).
    log : bool
        Logarithmic colour scale (``alpha > 0``).
    """
    import matplotlib as mpl

    p0, a = check_positive("p0", p0), check_positive("a", a)
    if not curves:
        raise InputError("curves = [] is not allowed: give at least one (alpha, x, p) triple.")
    alphas = np.array([float(c[0]) for c in curves])
    lo, hi = float(alphas.min()), float(alphas.max())
    norm = (mpl.colors.LogNorm if log else mpl.colors.Normalize)(lo, hi if hi > lo else lo + 1.0)
    colors = mpl.colormaps[cmap]
    sections = [(np.asarray(x, dtype=float), np.asarray(p, dtype=float)) for _, x, p in curves]
    lab = axis_labels(labels)
    with new_figure((6.8, 4.0), title=title) as (fig, ax):
        for alpha, (x, p) in zip(alphas, sections):
            ax.plot(x / a, p / p0, color=colors(0.9 * norm(alpha)), lw=1.4)
        for label, x, p, style in extra:
            ax.plot(np.asarray(x) / a, np.asarray(p) / p0, label=label, **{"lw": 1.2, **style})
        bar = fig.colorbar(mpl.cm.ScalarMappable(norm=norm, cmap=mpl.colors.ListedColormap(
            colors(np.linspace(0, 0.9, 256)))), ax=ax, pad=0.01)
        bar.set_label(name)
        if len(alphas) <= 12:
            bar.set_ticks(alphas)
            bar.set_ticklabels(list(ticklabels) if ticklabels is not None else [f"{v:.3g}" for v in alphas])
        ax.set_xlim(*(xlim or auto_xlim(sections, a)))
        ax.set_ylim(bottom=0.0)
        ax.set_xlabel(lab["x"] + "  (axial section $y = 0$)")
        ax.set_ylabel(lab["p"])
        if extra:
            ax.legend(loc="upper right", frameon=False)
        return save_figure(fig, path)


def plot_transition_line(alpha, r_transition, path, *, a, r_contact=None,
                         name=r"$\alpha_a = p_{cr}\,/\,p_{max}^{\lambda}$", title=None):
    """Radius of the transition between the rigid and elastic branches against the threshold
    parameter (paper Fig. 7), with regions I and II shaded.

    Parameters
    ----------
    alpha : array_like
        Values of the parameter (``alpha_a = p_cr / p_max^lambda``).
    r_transition : array_like
        Transition radii [length] (:func:`transition_radius`).
    r_contact : array_like, optional
        Contact radii [length]; region II lies between the two lines.
    name : str
        Label of the parameter axis (mathtext).
    """
    a = check_positive("a", a)
    alpha = np.asarray(alpha, dtype=float)
    rt = np.asarray(r_transition, dtype=float) / a
    if alpha.shape != rt.shape or alpha.size < 2:
        raise InputError(f"alpha, r_transition have shapes {alpha.shape}, {rt.shape} which is not allowed: "
                         "they must be equal, with at least 2 values.")
    order = np.argsort(alpha)
    alpha, rt = alpha[order], rt[order]
    with new_figure((6.0, 4.0), title=title) as (fig, ax):
        ax.fill_between(alpha, 0.0, rt, color="#d62728", alpha=0.18, lw=0, label="I: rigid branch, $p \\geq p_{cr}$")
        ax.plot(alpha, rt, color="#d62728", marker="o", markersize=4, label="transition line $p = p_{cr}$")
        if r_contact is not None:
            rc = np.asarray(r_contact, dtype=float)[order] / a
            ax.fill_between(alpha, rt, rc, color="#1f77b4", alpha=0.15, lw=0,
                            label="II: elastic branch, $0 < p < p_{cr}$")
            ax.plot(alpha, rc, color="#1f77b4", marker="s", markersize=3.5, label="contact edge")
        ax.set_ylim(0.0, 1.08 * float(rc.max()) if r_contact is not None else None)
        ax.set_xlim(float(alpha.min()), float(alpha.max()))
        ax.set_xlabel(name)
        ax.set_ylabel(r"radius $r\,/\,a_H$")
        ax.legend(loc="lower left", frameon=True, framealpha=0.85)
        return save_figure(fig, path)


def plot_sweep_scalars(values, series, path, *, name, title=None, ticklabels=None):
    """Scalar results of a sweep against the swept value, one panel per quantity.

    Parameters
    ----------
    values : array_like
        The swept values (numbers; give ``ticklabels`` for values that are not).
    series : sequence of (str, array_like)
        ``(axis label with unit, values)`` per panel; ``NaN`` marks a missing point.
    name : str
        Label of the swept parameter (mathtext allowed).
    ticklabels : sequence of str, optional
        Tick labels at ``values``.
    """
    x = np.asarray(values, dtype=float)
    if not series or x.size < 1:
        raise InputError("series = [] is not allowed: give at least one (label, values) pair.")
    with new_figure((6.4, 1.2 + 1.9 * len(series)), title=title, nrows=len(series), sharex=True,
                    squeeze=False) as (fig, axes):
        for ax, (label, y) in zip(axes[:, 0], series):
            y = np.asarray(y, dtype=float)
            if y.shape != x.shape:
                raise InputError(f"series {label!r} has shape {y.shape} which is not allowed: it must match "
                                 f"values, {x.shape}.")
            ax.plot(x, y, marker="o", markersize=4, color="#1f77b4")
            ax.set_ylabel(label)
        axes[-1, 0].set_xlabel(name)
        if ticklabels is not None:
            axes[-1, 0].set_xticks(x, list(ticklabels))
        return save_figure(fig, path)
