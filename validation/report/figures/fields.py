"""Stress fields below the contact: the FEM's (r, z) section, the BEM's x-z section through the
axis, and stress profiles against the depth.

The FEM's von Mises stress is recovered by :func:`fem_reference.fields.nodal_stresses` (the
field its ``.vtu`` file holds) and drawn on the vertex triangulation of the quadratic mesh,
mirrored about the axis. Lengths are divided by ``a`` and stresses by ``scale`` (Hertz's radius
and peak, or display units); other conventions: :mod:`validation.report.figures`.
"""

from __future__ import annotations

import logging

import numpy as np

from bem.checks import InputError, check_positive

from ..render.style import DPI, axis_labels, color_for, new_figure, save_figure

__all__ = ["plot_section_field", "von_mises_of", "section_field_from_vtu", "plot_stress_section",
           "plot_depth_profiles"]

log = logging.getLogger(__name__)


def _mirrored(r, z, triangles, values, a, scale, keep):
    """The (r, z) triangulation and field mirrored about the axis (``r -> -r``), scaled, triangles ``keep``."""
    import matplotlib.tri as mtri

    tri, n = triangles[keep], r.size
    triang = mtri.Triangulation(np.concatenate([r, -r]) / a, np.concatenate([z, z]) / a,
                                np.vstack([tri, tri[:, ::-1] + n]))
    return triang, np.concatenate([values, values]) / scale


def _volume_image(r, z, tri, values, *, window, vmax, contact_radius, size):
    """pyvista's view of the field below the contact (:func:`.views3d.render_revolved_field`), or ``None``."""
    from .views3d import pyvista_or_none, render_revolved_field

    pv = pyvista_or_none()
    if pv is None:
        return None
    try:
        return render_revolved_field(pv, r, z, tri, values, window=window, clim=(0.0, vmax), size=size,
                                     contact_radius=contact_radius)
    except (RuntimeError, ValueError, OSError) as exc:
        log.warning("pyvista cannot render the 3-D view of the stress field (%s): the section alone is drawn", exc)
        return None


def plot_section_field(r, z, triangles, values, path, *, a, scale, label, window=3.0, contact_radius=None,
                       title=None, labels=None, length_unit=None):
    """A scalar field on an (r, z) triangulation, mirrored about the axis for readability.

    With the ``[3d]`` extra (pyvista, :mod:`.views3d`) a left panel shows the lower body
    (``z <= 0``) in 3-D: the section revolved about the axis, a quarter cut away to show the
    field under the contact, the contact patch on top, in the same colours. Without it the
    section alone is drawn.

    Parameters
    ----------
    r, z : array_like, shape (n,)
        Vertex coordinates [length].
    triangles : array_like of int, shape (t, 3)
        Vertex triangles.
    values : array_like, shape (n,)
        Field at the vertices (same unit as ``scale``; colours ``values / scale``).
    label : str
        Colour-bar label (mathtext), e.g. ``r"$\\sigma_{vM}\\,/\\,p_0$"``.
    window : float
        Half-width and half-height of the window in units of ``a``.
    contact_radius : float, optional
        Edge of the contact [length], marked on the interface.
    labels : dict, optional
        ``{"r", "z"}`` axis labels.
    length_unit : str, optional
        Unit of ``r / a`` shown with the contact radius in the legend (default: ``a_H``
        without ``labels``, nothing with them).
    """
    a, scale = check_positive("a", a), check_positive("scale", scale)
    r, z, values = (np.asarray(v, dtype=float) for v in (r, z, values))
    tri = np.asarray(triangles, dtype=np.int64)
    if tri.ndim != 2 or tri.shape[1] != 3 or r.shape != z.shape or values.shape != r.shape:
        raise InputError("r, z, values must have one shape (n,) and triangles the shape (t, 3).")
    near = (r[tri].mean(axis=1) <= 1.15 * window * a) & (np.abs(z[tri].mean(axis=1)) <= 1.15 * window * a)
    if not near.any():
        raise InputError("no triangle lies in the window: make window larger.")
    triang, vv = _mirrored(r, z, tri, values, a, scale, near)
    vmax = float(np.percentile(vv[np.unique(triang.triangles)], 99.8))
    image = _volume_image(r / a, z / a, tri, values / scale, window=window, vmax=vmax, size=(4.4 * DPI, 4.0 * DPI),
                          contact_radius=None if not contact_radius else contact_radius / a)
    with new_figure((5.8, 4.6) if image is None else (10.4, 4.6), title=None if image is not None else title,
                    **({} if image is None else {"ncols": 2, "width_ratios": (4.4, 5.8)})) as (fig, axes):
        ax = axes if image is None else axes[1]
        if image is not None:
            axes[0].imshow(image, interpolation="lanczos")
            axes[0].set_axis_off()
            axes[0].set_title("below the contact, a quarter cut away", fontsize=9.5)
            ax.set_title("(r, z) section", fontsize=9.5)
            if title:
                fig.suptitle(title)
        pc = ax.tripcolor(triang, vv, shading="gouraud", cmap="magma", vmin=0.0, vmax=vmax, rasterized=True)
        ax.tricontour(triang, vv, levels=np.linspace(0, vmax, 9)[1:-1], colors="white", linewidths=0.5, alpha=0.6)
        ax.axhline(0.0, color="#00d0ff", lw=1.0, ls="--")
        if contact_radius:
            rc = contact_radius / a
            unit = " $a_H$" if labels is None and length_unit is None else f" {length_unit}" if length_unit else ""
            ax.plot([-rc, rc], [0.0, 0.0], color="#00d0ff", lw=3.0, solid_capstyle="butt",
                    label=f"contact, $r_c$ = {rc:.4g}{unit}")
            ax.legend(loc="upper right", fontsize=8, facecolor="#333333", labelcolor="white", framealpha=0.8)
        fig.colorbar(pc, ax=ax, pad=0.01).set_label(label)
        ax.set_xlim(-window, window)
        ax.set_ylim(-window, window)
        ax.set_aspect("equal")
        ax.grid(False)
        lab = axis_labels(labels)
        ax.set_xlabel(lab["r"] + " (mirrored about the axis)")
        ax.set_ylabel(lab["z"] + "  (upper body $z > 0$)")
        return save_figure(fig, path)


def von_mises_of(fem_result):
    """``(r, z, triangles, von_mises)`` of an FEM result: vertex coordinates [length], vertex
    triangles (t, 3) and the von Mises stress at the vertices [pressure]."""
    from fem_reference.fields import nodal_stresses

    model = getattr(fem_result, "model", None)
    if model is None or getattr(fem_result, "displacement_dofs", None) is None:
        raise InputError("fem_result has no model/displacement_dofs: it must come from fem_reference.solve.")
    basis = model.scalar_basis
    vm = nodal_stresses(model, fem_result.displacement_dofs)["von_mises"]
    return basis.mesh.p[0], basis.mesh.p[1], basis.mesh.t.T, vm[basis.nodal_dofs[0]]


def section_field_from_vtu(path, field="von_mises"):
    """``(r, z, triangles, values)`` of a field in an FEM ``.vtu`` file (6- or 3-node triangles)."""
    import meshio

    mesh = meshio.read(path)
    if field not in mesh.point_data:
        raise InputError(f"field = {field!r} is not allowed: {path} holds {sorted(mesh.point_data)}.")
    blocks = [c.data[:, :3] for c in mesh.cells if c.type in ("triangle", "triangle6")]
    if not blocks:
        raise InputError(f"{path} has no triangle cells: it is not an (r, z) section field.")
    return mesh.points[:, 0], mesh.points[:, 1], np.vstack(blocks), np.asarray(mesh.point_data[field], dtype=float)


def _split_at_repeats(z, values):
    """``(z, values)`` split where a depth repeats (a material boundary: the two sides of one depth); parts
    with fewer than two depths are left out."""
    z, values = np.asarray(z, dtype=float), np.asarray(values, dtype=float)
    cuts = np.flatnonzero(np.diff(z) == 0) + 1
    return [(zp, vp) for zp, vp in zip(np.split(z, cuts), np.split(values, cuts)) if zp.size >= 2]


def plot_stress_section(panels, path, *, a, scale, label, contact_radius=None, fem=None, labels=None, title=None,
                        interfaces=()):
    """Von Mises stress in the x-z section through the axis, body 1 above and body 2 below the interface.

    Parameters
    ----------
    panels : sequence of (sign, x, z, values)
        One per body: ``sign`` +1 (drawn at ``+z``, upper body) or -1 (at ``-z``), ``x`` (n_x,)
        [length], ``z`` (n_z,) depths [length], ``values`` (n_z, n_x) in the unit of ``scale``. A depth
        given twice is a material boundary (a coated body's interface: the coating's side first); the
        field is drawn on each side of it up to it.
    label : str
        Colour-bar label (mathtext).
    contact_radius : float, optional
        Drawn as a thick line on the interface [length].
    fem : tuple, optional
        ``(r, z, triangles, values)`` of the FEM (r, z) field in the same units: its contours,
        mirrored about the axis, are drawn over the map at the same levels (dashed).
    labels : dict, optional
        ``{"x", "z"}`` axis labels.
    interfaces : sequence of float
        Heights ``z`` [length] (``+t`` in the upper body, ``-t`` in the lower one) of coating/substrate
        interfaces, drawn as dashed lines.
    """
    if not panels:
        raise InputError("panels = [] is not allowed: give at least one body's section.")
    a, scale = check_positive("a", a), check_positive("scale", scale)
    vmax = max(float(np.max(v)) for _, _, _, v in panels) / scale
    levels = np.linspace(0.0, vmax, 11)[1:-1]
    labels = axis_labels(labels)
    x_lim = max(float(np.max(np.abs(x))) for _, x, _, _ in panels) / a
    z_lim = max(float(np.max(z)) for _, _, z, _ in panels) / a
    span = z_lim * (2 if len(panels) > 1 else 1)
    height = 5.2 if len(panels) > 1 else 3.6
    width = min(9.0, max(3.8, 1.6 + (height - 0.8) * 2 * x_lim / span))
    with new_figure((width, height), title=title) as (fig, ax):
        for sign, x, z_body, values_body in panels:
            for z, values in _split_at_repeats(z_body, values_body):
                xx, zz = np.meshgrid(np.asarray(x) / a, sign * z / a)
                vv = values / scale
                mesh = ax.pcolormesh(xx, zz, vv, shading="gouraud", cmap="magma", vmin=0.0, vmax=vmax)
                ax.contour(xx, zz, vv, levels=levels, colors="white", linewidths=0.6, alpha=0.7)
        for i, height in enumerate(interfaces):
            ax.axhline(height / a, color="#7fff7f", lw=1.0, ls="--",
                       label="coating/substrate interface" if i == 0 else None)
        if fem is not None:
            r, zf, tri, vf = (np.asarray(v) for v in fem)
            keep = np.all(np.abs(zf[tri]) / a <= 1.05 * z_lim, axis=1) & np.all(r[tri] / a <= 1.05 * x_lim, axis=1)
            ax.tricontour(*_mirrored(r, zf, tri, vf, a, scale, keep), levels=levels, colors="#00d0ff",
                          linewidths=0.8, linestyles="--")
            ax.plot([], [], color="#00d0ff", ls="--", lw=0.8, label="FEM reference (same levels)")
        ax.axhline(0.0, color="#bbbbbb", lw=0.8)
        if contact_radius:
            rc = contact_radius / a
            ax.plot([-rc, rc], [0.0, 0.0], color="#00d0ff", lw=3.0, solid_capstyle="butt", label="contact")
        if contact_radius or fem is not None or len(interfaces):
            ax.legend(loc="lower right", fontsize=8, facecolor="#333333", labelcolor="white", framealpha=0.8)
        fig.colorbar(mesh, ax=ax, pad=0.01).set_label(label)
        ax.set_xlim(-x_lim, x_lim)
        low = -z_lim if any(s < 0 for s, *_ in panels) else 0.0
        high = z_lim if any(s > 0 for s, *_ in panels) else 0.0
        ax.set_ylim(low, high)
        ax.set_aspect("equal")
        ax.grid(False)
        ax.set_xlabel(labels["x"])
        ax.set_ylabel(labels["z"] + ("  (body 1 above, body 2 below)" if low < 0 < high else ""))
        return save_figure(fig, path)


def plot_depth_profiles(curves, path, *, a, scale, stress_label, depth_label=r"depth $z\,/\,a_H$", marks=(),
                        title=None, interfaces=()):
    """Stresses against the depth on the axis (depth downwards).

    Parameters
    ----------
    curves : sequence of dict
        ``{"label", "z", "values"}`` [length], [stress] and optionally ``"key"`` (colour of a law,
        method or solver, :func:`validation.report.render.style.color_for`), ``"ls"``, ``"marker"``.
    stress_label, depth_label : str
        Axis labels (mathtext); depths are divided by ``a``, stresses by ``scale``.
    marks : sequence of (depth, value, color)
        Points to mark (e.g. the maxima) [length], [stress].
    interfaces : sequence of (depth, label)
        Depths [length] of coating/substrate interfaces, drawn as dashed lines.
    """
    if not curves:
        raise InputError("curves = [] is not allowed: give at least one profile.")
    a, scale = check_positive("a", a), check_positive("scale", scale)
    with new_figure((5.6, 4.4), title=title) as (fig, ax):
        for i, c in enumerate(curves):
            ax.plot(np.asarray(c["values"]) / scale, np.asarray(c["z"]) / a, label=c["label"],
                    color=color_for(c.get("key", ""), i), ls=c.get("ls", "-"), marker=c.get("marker"),
                    markersize=3.5, lw=1.5)
        for depth, value, color in marks:
            ax.plot([value / scale], [depth / a], "o", color=color, markersize=6, markerfacecolor="none")
        for depth, text in interfaces:
            ax.axhline(depth / a, color="#2ca02c", lw=0.9, ls="--", label=text)
        ax.invert_yaxis()
        ax.set_xlabel(stress_label)
        ax.set_ylabel(depth_label)
        ax.legend(fontsize=8)
        return save_figure(fig, path)
