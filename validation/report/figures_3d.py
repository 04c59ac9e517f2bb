"""Pressure over the contact: isometric 3-D surfaces (paper Fig. 9, 11) and 2-D maps.

The surface is the piecewise-linear pressure on a Delaunay triangulation of the lattice
nodes in and around the contact (the lattice is equilateral, so the triangulation is the
lattice's own), lifted by ``p / p0`` and drawn off-screen with pyvista.
"""

from __future__ import annotations

import contextlib
import math

import numpy as np

from bem.checks import InputError, check_positive

from .style import axis_labels, new_figure, save_figure

__all__ = ["contact_patch", "plot_pressure_surfaces", "plot_contact_map"]


def _nodal(data):
    if isinstance(data, (tuple, list)):
        x, y, p = (np.asarray(v, dtype=float) for v in data)
    else:
        x, y, p = (np.asarray(v, dtype=float) for v in (data.x, data.y, data.p))
    return x, y, p


def contact_patch(x, y, p, *, margin=0.25):
    """Nodes of the contact and a margin around it, and their Delaunay triangles.

    Parameters
    ----------
    x, y, p : ndarray, shape (N,)
        Nodes [length] and pressures.
    margin : float
        Margin around the bounding box of the loaded nodes, as a fraction of its
        half-size.

    Returns
    -------
    xs, ys, ps : ndarray, shape (M,)
        The selected nodes and pressures.
    triangles : ndarray of int, shape (T, 3)
        Triangles (indices into the selection).
    """
    from scipy.spatial import Delaunay

    loaded = p > 0
    if not loaded.any():
        raise InputError("p has no positive value: there is no contact to draw.")
    half = max(np.abs(x[loaded]).max(), np.abs(y[loaded]).max())
    half = half * (1.0 + margin)
    keep = (np.abs(x) <= half) & (np.abs(y) <= half)
    xs, ys, ps = x[keep], y[keep], p[keep]
    tri = Delaunay(np.column_stack([xs, ys]))
    return xs, ys, ps, tri.simplices.astype(np.int64)


@contextlib.contextmanager
def _quiet_vtk():
    """Keep VTK's own logger off stderr below errors (e.g. 'bad X server connection')."""
    try:
        from vtkmodules.vtkCommonCore import vtkLogger
    except ImportError:  # pragma: no cover - very old VTK
        yield
        return
    old = vtkLogger.GetCurrentVerbosityCutoff()
    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_ERROR)
    try:
        yield
    finally:
        vtkLogger.SetStderrVerbosity(old)


def _render_panel(pv, xs, ys, ps, tri, *, p0, a, height, vmax, size, section):
    """One off-screen isometric rendering of a lifted pressure surface, as an RGB array."""
    pts = np.column_stack([xs / a, ys / a, height * ps / p0])
    faces = np.column_stack([np.full(len(tri), 3), tri]).ravel()
    mesh = pv.PolyData(pts, faces)
    mesh["p / p0"] = ps / p0
    pl = pv.Plotter(off_screen=True, window_size=size)
    try:
        pl.set_background("white")
        pl.add_mesh(mesh, scalars="p / p0", cmap="viridis", clim=(0.0, vmax), show_scalar_bar=False,
                    smooth_shading=True, specular=0.15, ambient=0.25)
        pl.add_mesh(mesh.extract_all_edges(), color="#1a1a1a", opacity=0.12, line_width=0.5)
        if section is not None:
            xs0, ps0 = section
            line = np.column_stack([xs0 / a, np.zeros_like(xs0), height * ps0 / p0 + 0.004])
            pl.add_mesh(pv.lines_from_points(line), color="black", line_width=4.0)
        pl.view_isometric()
        pl.enable_parallel_projection()
        pl.reset_camera(bounds=mesh.bounds)
        pl.camera.zoom(1.1)
        img = np.asarray(pl.screenshot(return_img=True))
    finally:
        pl.close()
    return _trim(img)


def _trim(img, pad=6):
    """Crop the white border of an RGB(A) image, keeping ``pad`` pixels."""
    ink = np.any(img[..., :3] < 250, axis=-1)
    rows, cols = np.nonzero(ink.any(axis=1))[0], np.nonzero(ink.any(axis=0))[0]
    if rows.size == 0:
        return img
    r0, r1 = max(rows[0] - pad, 0), min(rows[-1] + pad + 1, img.shape[0])
    c0, c1 = max(cols[0] - pad, 0), min(cols[-1] + pad + 1, img.shape[1])
    return img[r0:r1, c0:c1]


def plot_pressure_surfaces(panels, path, *, p0, a, height=0.8, columns=None, panel_size=(520, 420),
                           title=None, section=True, labels=None):
    """Isometric 3-D pressure surfaces, one panel per result, on a common colour scale.

    Each panel is rendered off-screen by pyvista (lit surface, faint lattice edges, the
    axial section ``y = 0`` as a black line) and the panels are laid out by matplotlib
    with one shared colour bar.

    Parameters
    ----------
    panels : sequence of (str, data)
        Panel title and a :class:`bem.ContactResult` or ``(x, y, p)`` nodal arrays.
    path : path-like
        PNG file to write.
    p0, a : float
        Pressure scale [pressure] and length scale [length] (Hertz peak and radius).
    height : float
        Height of ``p = p0`` in units of ``a`` (vertical exaggeration of the surface).
    columns : int, optional
        Panels per row (default: all in one row up to 3, then rows of 3; 2 x 2 for 4).
    panel_size : (int, int)
        Pixels of one rendering.
    title : str, optional
        Figure title.
    section : bool
        Draw the axial section ``y = 0`` on each surface (where nodes lie on it).
    labels : dict, optional
        ``{"p": colour-bar label}`` (:func:`validation.report.style.axis_labels`).

    Returns
    -------
    str
        ``path``.
    """
    import pyvista as pv

    from .figures_profiles import axial_section

    p0, a = check_positive("p0", p0), check_positive("a", a)
    if not panels:
        raise InputError("panels = [] is not allowed: give at least one (title, result) pair.")
    pv.OFF_SCREEN = True
    data = [(label, _nodal(d)) for label, d in panels]
    vmax = max(float(p.max()) for _, (_, _, p) in data) / p0
    n = len(data)
    ncol = columns or (2 if n == 4 else min(n, 3))
    nrow = math.ceil(n / ncol)
    images = []
    with _quiet_vtk():
        for _, (x, y, p) in data:
            xs, ys, ps, tri = contact_patch(x, y, p)
            on_axis = np.abs(ys) <= 1e-9 * float(np.abs(xs).max(initial=1.0))
            sec = axial_section(xs, ys, ps) if section and on_axis.sum() > 1 else None
            images.append(_render_panel(pv, xs, ys, ps, tri, p0=p0, a=a, height=height, vmax=vmax,
                                        size=panel_size, section=sec))
    import matplotlib as mpl

    width = 3.3 * ncol + 0.9
    with new_figure((width, 2.75 * nrow + (0.35 if title else 0.0)), nrows=nrow, ncols=ncol,
                    squeeze=False) as (fig, axes):
        for ax in axes.ravel():
            ax.set_axis_off()
        for ax, (label, _), img in zip(axes.ravel(), data, images):
            ax.imshow(img, interpolation="lanczos")
            ax.set_title(label, fontsize=9.5)
        sm = mpl.cm.ScalarMappable(norm=mpl.colors.Normalize(0.0, vmax), cmap="viridis")
        bar = fig.colorbar(sm, ax=axes.ravel().tolist(), shrink=0.8, pad=0.01, aspect=25)
        bar.set_label(axis_labels(labels)["p"])
        if title:
            fig.suptitle(title, fontsize=10.5)
        return save_figure(fig, path)


def plot_contact_map(result, path, *, p0, a, title=None, circle=None, levels=(), labels=None, b=None,
                     aspect="equal", figsize=(5.4, 4.4)):
    """Map of the contact pressure ``p / p0`` over the plane with the contact boundary.

    The boundary is drawn midway between the loaded nodes (``p > 0``) and their unloaded
    neighbours (the 0.5 level of the loaded-node indicator), i.e. within half a lattice
    step of the true edge; the dashed circle has the area of the contact,
    ``r = sqrt(A / pi)``.

    Parameters
    ----------
    result : bem.ContactResult or (x, y, p)
        Nodal pressures.
    path : path-like
        PNG file to write.
    p0, a : float
        Pressure and length scales (Hertz peak and radius).
    title : str, optional
        Axes title.
    circle : float, optional
        Radius of the equal-area circle [length]; default from the loaded node count
        and the lattice node area when ``result`` is a ContactResult.
    levels : sequence of (str, float)
        Labelled pressure contours [pressure] (e.g. ``("p = p_cr", p_cr)``: the line between
        the rigid and elastic branches of an elastic-rigid layer).
    labels : dict, optional
        ``{"x", "y", "p"}`` axis labels (:func:`validation.report.style.axis_labels`).
    b : float, optional
        Length scale of the y axis [length] (default ``a``); with ``aspect="auto"`` an
        elongated contact (a roller) fills the axes.
    aspect : {"equal", "auto"} or float
        Aspect of the axes in the scaled coordinates.
    figsize : (float, float)
        Figure size [inch].

    Returns
    -------
    str
        ``path``.
    """
    import matplotlib.tri as mtri

    p0, a = check_positive("p0", p0), check_positive("a", a)
    b = a if b is None else check_positive("b", b)
    x, y, p = _nodal(result)
    xs, ys, ps, tri = contact_patch(x, y, p, margin=0.3)
    triang = mtri.Triangulation(xs / a, ys / b, tri)
    if circle is None and hasattr(result, "contact_radius"):
        circle = result.contact_radius
    with new_figure(figsize) as (fig, ax):
        pc = ax.tripcolor(triang, ps / p0, shading="gouraud", cmap="viridis", vmin=0.0)
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
            ax.plot(circle / a * np.cos(t), circle / b * np.sin(t), color="#ff7f0e", ls="--", lw=1.2,
                    label=r"equal-area circle $r = \sqrt{A/\pi}$")
        bar = fig.colorbar(pc, ax=ax, pad=0.01)
        lab = axis_labels(labels)
        bar.set_label(lab["p"])
        ax.set_aspect(aspect)
        ax.grid(False)
        ax.set_xlabel(lab["x"])
        ax.set_ylabel(lab["y"])
        if title:
            ax.set_title(title)
        leg = fig.legend(loc="outside lower center", ncols=2, fontsize=8, facecolor="#555555", framealpha=1.0)
        for text in leg.get_texts():
            text.set_color("white")
        return save_figure(fig, path)
