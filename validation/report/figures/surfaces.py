"""Pressure over the contact: isometric 3-D surfaces (paper Fig. 9, 11) and 2-D maps.

The surface is the piecewise-linear pressure on a Delaunay triangulation of the lattice
nodes in and around the contact (the lattice is equilateral, so the triangulation is the
lattice's own), lifted by ``p / p0``; pyvista renders it off-screen when the ``[3d]`` extra
is installed (:mod:`.views3d`), matplotlib's mplot3d draws it otherwise. Conventions:
:mod:`validation.report.figures`.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from bem.checks import InputError, check_positive

from ..render.style import DPI, axis_labels, new_figure, save_figure
from .profiles import axial_section

__all__ = ["contact_patch", "covered_window", "plot_pressure_surfaces", "plot_contact_map"]

log = logging.getLogger(__name__)


def _nodal(data):
    """``(x, y, p)`` of a :class:`bem.ContactResult` or of nodal arrays."""
    return tuple(np.asarray(v, dtype=float) for v in (data if isinstance(data, (tuple, list)) else
                                                       (data.x, data.y, data.p)))


def contact_patch(x, y, p, *, margin=0.25):
    """``(xs, ys, ps, triangles)``: the nodes ``(x, y)`` [length] of the contact (``p > 0``) and a
    ``margin`` around its bounding box (a fraction of its half-size), their pressures and their
    Delaunay triangles (indices into the selection, shape (T, 3))."""
    from scipy.spatial import Delaunay

    loaded = p > 0
    if not loaded.any():
        raise InputError("p has no positive value: there is no contact to draw.")
    half = max(np.abs(x[loaded]).max(), np.abs(y[loaded]).max()) * (1.0 + margin)
    keep = (np.abs(x) <= half) & (np.abs(y) <= half)
    xs, ys, ps = x[keep], y[keep], p[keep]
    tri = Delaunay(np.column_stack([xs, ys]))
    return xs, ys, ps, tri.simplices.astype(np.int64)


def _surface_panel(ax, xs, ys, ps, tri, *, p0, a, height, vmax, section, lab):
    """One isometric pressure surface on the 3-D axes ``ax`` (orthographic view, labelled axes)."""
    from matplotlib.ticker import MaxNLocator

    ax.plot_trisurf(xs / a, ys / a, ps / p0, triangles=tri, cmap="viridis", vmin=0.0, vmax=vmax,
                    linewidth=0.0, antialiased=False, rasterized=True, zorder=1)
    if section is not None:
        xs0, ps0 = section
        ax.plot(xs0 / a, np.zeros_like(xs0), ps0 / p0, color="black", lw=1.2, zorder=3)
    half = float(max(np.abs(xs).max(), np.abs(ys).max())) / a
    ax.set_xlim(-half, half)
    ax.set_ylim(-half, half)
    ax.set_zlim(0.0, vmax)
    ax.set_box_aspect((1.0, 1.0, height * vmax / (2.0 * half)), zoom=0.98)
    ax.set_proj_type("ortho")
    ax.view_init(elev=34.0, azim=-58.0)
    ax.computed_zorder = False
    for axis, bins in ((ax.xaxis, 4), (ax.yaxis, 4), (ax.zaxis, 2)):
        axis.set_major_locator(MaxNLocator(nbins=bins, steps=[1, 2, 2.5, 5, 10]))
        axis.pane.set_facecolor((0.96, 0.96, 0.96, 1.0))
        axis.set_tick_params(labelsize=7, pad=0)
        axis.label.set_size(8)
    ax.set_xlabel(lab["x"], labelpad=-1)
    ax.set_ylabel(lab["y"], labelpad=-1)
    ax.set_zlabel(lab["p_short"], labelpad=-3)


def _rendered(patches, *, p0, a, height, vmax, lab, size):
    """The pyvista image of every panel, or ``None`` (no pyvista, or it cannot render: mplot3d draws)."""
    from .views3d import plain_label, pyvista_or_none, render_surface

    pv = pyvista_or_none()
    if pv is None:
        return None
    names = tuple(plain_label(lab[k]) for k in ("x", "y", "p_short"))
    try:
        return [render_surface(pv, xs / a, ys / a, ps / p0, tri, clim=(0.0, vmax), size=size, labels=names,
                               ztop=1.25 * height * vmax,
                               section=None if sec is None else (sec[0] / a, sec[1] / p0))
                for _label, xs, ys, ps, tri, sec in patches]
    except (RuntimeError, ValueError, OSError) as exc:
        log.warning("pyvista cannot render the 3-D pressure surfaces (%s): drawn with matplotlib", exc)
        return None


def covered_window(x, y):
    """``(x0, x1), (y0, y1)``: the largest axis-parallel rectangle that the triangulation of the
    lattice nodes ``(x, y)`` covers [length].

    The rows of the equilateral lattice are shifted by half a step in turn, so the nodes of a
    square patch end alternately half a step short at the left and right; their triangles
    leave notches there and at the corners. The window runs from the largest row start to the
    smallest row end, and from the lowest to the highest row.
    """
    _, row = np.unique(np.round(y / max(float(np.ptp(y)), 1e-300) * 1e6), return_inverse=True)
    row_min = np.full(row.max() + 1, np.inf)
    row_max = np.full(row.max() + 1, -np.inf)
    np.minimum.at(row_min, row, x)
    np.maximum.at(row_max, row, x)
    return (float(row_min.max()), float(row_max.min())), (float(y.min()), float(y.max()))


def plot_pressure_surfaces(panels, path, *, p0, a, height=0.8, columns=None, panel_inches=(3.3, 2.8),
                           title=None, section=True, labels=None):
    """Isometric 3-D pressure surfaces, one panel per result, on a common colour scale.

    Each panel is the piecewise-linear pressure on the lattice triangles (orthographic view,
    axes with ticks and labels, the axial section ``y = 0`` as a black line), rendered by
    pyvista off-screen (lit, smooth-shaded) when the ``[3d]`` extra is installed and drawn
    with matplotlib's mplot3d otherwise (or when pyvista cannot render); one colour bar gives
    the scale of all panels. The coloured surface is rasterised at the figure's DPI in
    SVG/PDF output (the titles, colour bar and text stay vector).

    Parameters
    ----------
    panels : sequence of (str, data)
        Panel title and a :class:`bem.ContactResult` or ``(x, y, p)`` nodal arrays.
    height : float
        Drawn height of the highest peak relative to the width of the patch.
    columns : int, optional
        Panels per row (default: 2, so that a panel fills half the width of a report page).
    panel_inches : (float, float)
        Size of one panel [inch].
    section : bool
        Draw the axial section ``y = 0`` on each surface (where nodes lie on it).
    labels : dict, optional
        ``{"x", "y", "p"}`` and ``"p_short"`` for the vertical axis.
    """
    import matplotlib as mpl

    p0, a = check_positive("p0", p0), check_positive("a", a)
    if not panels:
        raise InputError("panels = [] is not allowed: give at least one (title, result) pair.")
    data = [(label, _nodal(d)) for label, d in panels]
    vmax = max(float(p.max()) for _, (_, _, p) in data) / p0
    n = len(data)
    ncol = columns or min(n, 2)
    nrow = math.ceil(n / ncol)
    lab = axis_labels(labels)
    lab.setdefault("p_short", lab["p"].replace("contact pressure ", ""))
    w, h = panel_inches
    patches = []
    for label, (x, y, p) in data:
        xs, ys, ps, tri = contact_patch(x, y, p)
        on_axis = np.abs(ys) <= 1e-9 * float(np.abs(xs).max(initial=1.0))
        patches.append((label, xs, ys, ps, tri, axial_section(xs, ys, ps) if section and on_axis.sum() > 1 else None))
    images = _rendered(patches, p0=p0, a=a, height=height, vmax=vmax, lab=lab, size=(w * DPI, h * DPI))
    with new_figure((w * ncol + 0.9, h * nrow + (0.35 if title else 0.0))) as (fig, _):
        fig.delaxes(_)
        fig.set_layout_engine("none")
        grid = fig.add_gridspec(nrow, ncol + 1, width_ratios=[1.0] * ncol + [0.045], left=0.0, right=0.92,
                                bottom=0.03, top=0.91 if title else 0.98, wspace=0.22, hspace=0.1)
        for k, (label, xs, ys, ps, tri, sec) in enumerate(patches):
            if images is not None:
                ax = fig.add_subplot(grid[k // ncol, k % ncol])
                ax.imshow(images[k], interpolation="lanczos")
                ax.set_axis_off()
                ax.set_title(label, fontsize=9.5, pad=2)
                continue
            ax = fig.add_subplot(grid[k // ncol, k % ncol], projection="3d")
            _surface_panel(ax, xs, ys, ps, tri, p0=p0, a=a, height=height, vmax=vmax, section=sec, lab=lab)
            ax.set_title(label, fontsize=9.5, pad=-6)
        cax = fig.add_subplot(grid[:, ncol])
        fig.colorbar(mpl.cm.ScalarMappable(norm=mpl.colors.Normalize(0.0, vmax), cmap="viridis"),
                     cax=cax).set_label(lab["p"])
        box = cax.get_position()
        cax.set_position([box.x0, box.y0 + 0.1 * box.height, box.width, 0.8 * box.height])
        if title:
            fig.suptitle(title, fontsize=10.5)
        return save_figure(fig, path)


def plot_contact_map(result, path, *, p0, a, title=None, circle=None, levels=(), labels=None, aspect="equal",
                     figsize=(5.4, 4.4)):
    """Map of the contact pressure ``p / p0`` over the plane with the contact boundary.

    The boundary is drawn midway between the loaded nodes (``p > 0``) and their unloaded
    neighbours (the 0.5 level of the loaded-node indicator), i.e. within half a lattice
    step of the true edge; the dashed circle has the area of the contact,
    ``r = sqrt(A / pi)``.

    Parameters
    ----------
    result : bem.ContactResult or (x, y, p)
        Nodal pressures.
    circle : float, optional
        Radius of the equal-area circle [length]; default from the loaded node count
        and the lattice node area when ``result`` is a ContactResult.
    levels : sequence of (str, float)
        Labelled pressure contours [pressure] (e.g. ``("p = p_cr", p_cr)``: the line between
        the rigid and elastic branches of an elastic-rigid layer).
    aspect : {"equal", "auto"} or float
        Aspect of the axes (``"auto"``: an elongated contact, a roller, fills them).
    figsize : (float, float)
        Figure size [inch].
    """
    import matplotlib.tri as mtri

    p0, a = check_positive("p0", p0), check_positive("a", a)
    xs, ys, ps, tri = contact_patch(*_nodal(result), margin=0.3)
    triang = mtri.Triangulation(xs / a, ys / a, tri)
    if circle is None and hasattr(result, "contact_radius"):
        circle = result.contact_radius
    with new_figure(figsize, title=title) as (fig, ax):
        pc = ax.tripcolor(triang, ps / p0, shading="gouraud", cmap="viridis", vmin=0.0, rasterized=True)
        loaded = (ps > 0).astype(float)
        if loaded.min() < 0.5:
            ax.tricontour(triang, loaded, levels=[0.5], colors="white", linewidths=1.4)
            ax.plot([], [], color="white", lw=1.4, label="contact boundary")
        for k, (label, value) in enumerate(levels):
            color = ("#ff4d4d", "#00e5ff", "#ffffff")[k % 3]
            if not ps.min() < value < ps.max():
                continue
            ax.tricontour(triang, ps, levels=[value], colors=color, linewidths=1.3, linestyles=":")
            ax.plot([], [], color=color, lw=1.3, ls=":", label=label)
        if circle:
            t = np.linspace(0.0, 2.0 * np.pi, 361)
            ax.plot(circle / a * np.cos(t), circle / a * np.sin(t), color="#ff7f0e", ls="--", lw=1.2,
                    label=r"equal-area circle $r = \sqrt{A/\pi}$")
        lab = axis_labels(labels)
        fig.colorbar(pc, ax=ax, pad=0.01).set_label(lab["p"])
        ax.set_aspect(aspect)
        (x0, x1), (y0, y1) = covered_window(xs, ys)
        ax.set_xlim(x0 / a, x1 / a)
        ax.set_ylim(y0 / a, y1 / a)
        ax.grid(False)
        ax.set_xlabel(lab["x"])
        ax.set_ylabel(lab["y"])
        leg = fig.legend(loc="outside lower center", ncols=2, fontsize=8, facecolor="#555555", framealpha=1.0)
        for text in leg.get_texts():
            text.set_color("white")
        return save_figure(fig, path)
