"""3-D views rendered off-screen with pyvista (the optional ``contactlab[3d]`` extra).

pyvista (VTK) draws what matplotlib's mplot3d draws poorly: lit, depth-sorted surfaces and
volumes. The views come back as RGB images that the matplotlib figures of :mod:`.surfaces` and
:mod:`.fields` place in their panels, beside matplotlib's titles and colour bars, so every
figure keeps one look and every file format (:func:`validation.report.render.style.save_figure`).
Without pyvista, or where it cannot render (no OpenGL, EGL or OSMesa library), :func:`pyvista_or_none`
returns ``None`` and the figures draw today's matplotlib views instead.

Rendering is off-screen; without a display (``DISPLAY`` unset) VTK is asked for its EGL window
(``VTK_DEFAULT_OPENGL_WINDOW``), which needs the system's ``libEGL.so.1`` (Debian: ``libegl1``).
"""

from __future__ import annotations

import logging
import os
import re

import numpy as np

__all__ = ["pyvista_or_none", "render_surface", "render_revolved_field", "plain_label"]

log = logging.getLogger(__name__)


def pyvista_or_none():
    """The pyvista module set up for off-screen rendering, or ``None`` when it cannot be imported."""
    try:
        import pyvista
    except (ImportError, OSError) as exc:
        log.debug("pyvista is not available (%s): matplotlib draws the 3-D views", exc)
        return None
    if not os.environ.get("DISPLAY"):
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    pyvista.OFF_SCREEN = True
    return pyvista


def plain_label(label):
    """A mathtext axis label as plain text for VTK (``"$x\\,/\\,a_H$"`` -> ``"x / a_H"``)."""
    text = label.replace("$", "").replace(r"\,", " ").replace(r"\ ", " ")
    text = re.sub(r"\\([A-Za-z]+)", r"\1", text).replace("{", "").replace("}", "")
    return " ".join(text.split())


def _screenshot(plotter):
    """The plotter's image (RGB uint8); RuntimeError when it is blank (nothing was rendered)."""
    try:
        img = np.asarray(plotter.screenshot(return_img=True))
    finally:
        plotter.close()
    if img.ndim != 3 or float(img.std()) < 1.0:
        raise RuntimeError("the off-screen rendering is blank")
    img = img[:, :, :3]
    drawn = np.nonzero((img < 250).any(axis=2))
    pad = max(4, img.shape[0] // 40)  # cropped to what was drawn, with a margin
    top, left = max(drawn[0].min() - pad, 0), max(drawn[1].min() - pad, 0)
    return img[top: drawn[0].max() + pad + 1, left: drawn[1].max() + pad + 1]


def _camera(plotter, elevation, azimuth, zoom=1.0):
    """An orthographic view from ``elevation`` above the x-y plane and ``azimuth`` from the -y axis [degree]."""
    el, az = np.radians(elevation), np.radians(azimuth - 90.0)
    center = np.asarray(plotter.bounds, dtype=float).reshape(3, 2).mean(axis=1)
    direction = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    plotter.camera_position = [tuple(center + 10.0 * direction), tuple(center), (0.0, 0.0, 1.0)]
    plotter.enable_parallel_projection()
    plotter.reset_camera()
    plotter.camera.zoom(zoom)


def render_surface(pv, xs, ys, zs, triangles, *, clim, size, ztop, labels, section=None, z_range=None,
                   cmap="viridis"):
    """A lit surface ``z(x, y)`` on triangles, coloured by ``z``, with labelled axes; returns RGB.

    Parameters
    ----------
    pv : module
        :func:`pyvista_or_none`.
    xs, ys, zs : ndarray, shape (n,)
        Nodes, already scaled to the drawn units (``zs`` drawn and coloured).
    triangles : ndarray of int, shape (t, 3)
    clim : (float, float)
        Colour range of ``zs``.
    size : (int, int)
        Image width and height [pixel].
    ztop : float
        Drawn height of ``clim[1]`` (the vertical exaggeration of the view).
    labels : (str, str, str)
        Axis titles (plain text).
    section : (ndarray, ndarray), optional
        ``(x, z)`` of the axial section ``y = 0``, drawn as a black line.
    z_range : (float, float), optional
        The values the vertical axis labels span (default ``clim``).
    """
    k = ztop / clim[1]
    faces = np.column_stack([np.full(len(triangles), 3), triangles]).ravel()
    mesh = pv.PolyData(np.column_stack([xs, ys, zs * k]), faces)
    mesh["value"] = zs
    pl = pv.Plotter(off_screen=True, window_size=[int(size[0]), int(size[1])])
    pl.set_background("white")
    pl.add_mesh(mesh, scalars="value", cmap=cmap, clim=clim, show_scalar_bar=False, smooth_shading=True,
                ambient=0.45, diffuse=0.6, specular=0.1)
    if section is not None:
        xa, za = section
        pl.add_mesh(pv.lines_from_points(np.column_stack([xa, np.zeros_like(xa), za * k + 1e-3 * ztop])),
                    color="black", line_width=3)
    font = max(10, int(size[1] / 20))
    z0, z1 = z_range or clim
    pl.show_bounds(bounds=[xs.min(), xs.max(), ys.min(), ys.max(), 0.0, ztop],
                   axes_ranges=[xs.min(), xs.max(), ys.min(), ys.max(), z0, z1], xtitle=labels[0],
                   ytitle=labels[1], ztitle=labels[2], color="black", font_size=font, location="outer",
                   n_xlabels=3, n_ylabels=3, n_zlabels=2, fmt="%.2g", grid=False, ticks="outside")
    _camera(pl, 30.0, -35.0, 0.85)
    return _screenshot(pl)


def render_revolved_field(pv, r, z, triangles, values, *, window, clim, size, contact_radius=None,
                          cmap="magma", cut=90.0, azimuth=-35.0, n_r=64, n_theta=73, n_z=64):
    """The lower body ``z <= 0`` of an axisymmetric (r, z) field revolved about the axis, a
    ``cut``-degree wedge removed to show the field inside, the contact patch on top; returns RGB.

    Parameters
    ----------
    pv : module
        :func:`pyvista_or_none`.
    r, z : ndarray, shape (n,)
        Vertices of the section, already scaled (e.g. by ``a_H``).
    triangles : ndarray of int, shape (t, 3)
    values : ndarray, shape (n,)
        Field at the vertices (scaled as it is coloured).
    window : float
        Radius and depth of the drawn cylinder (in the units of ``r``).
    clim : (float, float)
        Colour range.
    size : (int, int)
        Image width and height [pixel].
    contact_radius : float, optional
        Radius of the contact patch drawn on the surface ``z = 0`` (its outline, cyan).
    cut : float
        Angle of the wedge removed, facing the camera [degree].
    azimuth : float
        Direction of the camera about the axis, from the -y axis [degree].
    """
    from matplotlib.tri import LinearTriInterpolator, Triangulation

    lower = triangles[(z[triangles] <= 1e-12 * window).all(axis=1)]
    interp = LinearTriInterpolator(Triangulation(r, z, lower), values)
    rr = np.linspace(0.0, window, n_r)
    zz = np.linspace(-window, 0.0, n_z)
    facing = azimuth - 90.0  # the direction of the camera, about the axis [degree]
    theta = np.radians(np.linspace(facing + cut / 2.0, facing + 360.0 - cut / 2.0, n_theta))
    field = np.ma.filled(interp(*np.meshgrid(rr, zz, indexing="ij")), np.nan)  # (n_r, n_z)
    if np.isnan(field).all():
        raise RuntimeError("the field has no value below the contact in the window")
    field = np.where(np.isnan(field), np.nanmin(field), field)
    R, T, Z = np.meshgrid(rr, theta, zz, indexing="ij")
    grid = pv.StructuredGrid(R * np.cos(T), R * np.sin(T), Z)
    grid["value"] = np.broadcast_to(field[:, None, :], R.shape).ravel(order="F")
    pl = pv.Plotter(off_screen=True, window_size=[int(size[0]), int(size[1])])
    pl.set_background("white")
    pl.add_mesh(grid, scalars="value", cmap=cmap, clim=clim, show_scalar_bar=False, lighting=False)
    if contact_radius:
        ring = np.radians(np.linspace(0.0, 360.0, 145))
        edge = np.column_stack([contact_radius * np.cos(ring), contact_radius * np.sin(ring),
                                np.full(ring.size, 2e-3 * window)])
        pl.add_mesh(pv.lines_from_points(edge), color="#00d0ff", line_width=5)
    _camera(pl, 28.0, azimuth, 1.35)
    return _screenshot(pl)
