"""Figures of the subsurface stresses: the x-z section map and the depth profiles on the axis.

Plain data in, one PNG out (matplotlib, imported inside the functions, drawn with the report
style of :mod:`validation.report.style`). Lengths are divided by ``a`` and stresses by ``scale``
(the Hertz radius and peak when the scene has them, else display units).
"""

from __future__ import annotations

import numpy as np

from bem.checks import InputError, check_positive

from .style import color_for, new_figure, save_figure

__all__ = ["plot_stress_section", "plot_depth_profiles"]


def _checked(a, scale, items, name, what):
    """``(a, scale)`` checked positive; ``items`` must not be empty."""
    if not items:
        raise InputError(f"{name} = [] is not allowed: give at least one {what}.")
    return check_positive("a", a), check_positive("scale", scale)


def plot_stress_section(panels, path, *, a, scale, label, contact_radius=None, fem=None, labels=None,
                        title=None):
    """Von Mises stress in the x-z section through the axis, body 1 above and body 2 below the interface.

    Parameters
    ----------
    panels : sequence of (sign, x, z, values)
        One per body: ``sign`` +1 (drawn at ``+z``, upper body) or -1 (at ``-z``), ``x`` (n_x,)
        [length], ``z`` (n_z,) depths [length], ``values`` (n_z, n_x) in the unit of ``scale``.
    path : path-like
        PNG file to write.
    a, scale : float
        Length and stress scales (axes in ``x / a``, colours ``values / scale``).
    label : str
        Colour-bar label (mathtext).
    contact_radius : float, optional
        Drawn as a thick line on the interface [length].
    fem : tuple, optional
        ``(r, z, triangles, values)`` of the FEM (r, z) field in the same units: its contours,
        mirrored about the axis, are drawn over the map at the same levels (dashed).
    labels : dict, optional
        ``{"x", "z"}`` axis labels.
    title : str, optional

    Returns
    -------
    str
        ``path``.
    """
    a, scale = _checked(a, scale, panels, "panels", "body's section")
    vmax = max(float(np.max(v)) for _, _, _, v in panels) / scale
    levels = np.linspace(0.0, vmax, 11)[1:-1]
    labels = {"x": r"$x\,/\,a_H$", "z": r"$z\,/\,a_H$", **(labels or {})}
    x_lim = max(float(np.max(np.abs(x))) for _, x, _, _ in panels) / a
    z_lim = max(float(np.max(z)) for _, _, z, _ in panels) / a
    span = z_lim * (2 if len(panels) > 1 else 1)
    height = 5.2 if len(panels) > 1 else 3.6
    width = min(9.0, max(3.8, 1.6 + (height - 0.8) * 2 * x_lim / span))
    with new_figure((width, height)) as (fig, ax):
        for sign, x, z, values in panels:
            xx, zz = np.meshgrid(np.asarray(x) / a, sign * np.asarray(z) / a)
            vv = np.asarray(values) / scale
            mesh = ax.pcolormesh(xx, zz, vv, shading="gouraud", cmap="magma", vmin=0.0, vmax=vmax)
            ax.contour(xx, zz, vv, levels=levels, colors="white", linewidths=0.6, alpha=0.7)
        if fem is not None:
            import matplotlib.tri as mtri

            r, zf, tri, vf = (np.asarray(v) for v in fem)
            n = r.size
            keep = np.all(np.abs(zf[tri]) / a <= 1.05 * z_lim, axis=1) & np.all(r[tri] / a <= 1.05 * x_lim, axis=1)
            triang = mtri.Triangulation(np.concatenate([r, -r]) / a, np.concatenate([zf, zf]) / a,
                                        np.vstack([tri[keep], tri[keep][:, ::-1] + n]))
            ax.tricontour(triang, np.concatenate([vf, vf]) / scale, levels=levels, colors="#00d0ff",
                          linewidths=0.8, linestyles="--")
            ax.plot([], [], color="#00d0ff", ls="--", lw=0.8, label="FEM reference (same levels)")
        ax.axhline(0.0, color="#bbbbbb", lw=0.8)
        if contact_radius:
            rc = contact_radius / a
            ax.plot([-rc, rc], [0.0, 0.0], color="#00d0ff", lw=3.0, solid_capstyle="butt", label="contact")
        if contact_radius or fem is not None:
            ax.legend(loc="lower right", fontsize=8, facecolor="#333333", labelcolor="white", framealpha=0.8)
        bar = fig.colorbar(mesh, ax=ax, pad=0.01)
        bar.set_label(label)
        ax.set_xlim(-x_lim, x_lim)
        low = -z_lim if any(s < 0 for s, *_ in panels) else 0.0
        high = z_lim if any(s > 0 for s, *_ in panels) else 0.0
        ax.set_ylim(low, high)
        ax.set_aspect("equal")
        ax.grid(False)
        ax.set_xlabel(labels["x"])
        ax.set_ylabel(labels["z"] + ("  (body 1 above, body 2 below)" if low < 0 < high else ""))
        if title:
            ax.set_title(title)
        return save_figure(fig, path)


def plot_depth_profiles(curves, path, *, a, scale, stress_label, depth_label=r"depth $z\,/\,a_H$", marks=(),
                        title=None):
    """Stresses against the depth on the axis (depth downwards).

    Parameters
    ----------
    curves : sequence of dict
        ``{"label", "z", "values"}`` [length], [stress] and optionally ``"key"`` (colour of a law,
        method or solver, :func:`validation.report.style.color_for`), ``"ls"``, ``"marker"``.
    path : path-like
        PNG file to write.
    a, scale : float
        Depth and stress scales.
    stress_label, depth_label : str
        Axis labels (mathtext).
    marks : sequence of (depth, value, color)
        Points to mark (e.g. the maxima) [length], [stress].
    title : str, optional

    Returns
    -------
    str
        ``path``.
    """
    a, scale = _checked(a, scale, curves, "curves", "profile")
    with new_figure((5.6, 4.4)) as (fig, ax):
        for i, c in enumerate(curves):
            ax.plot(np.asarray(c["values"]) / scale, np.asarray(c["z"]) / a, label=c["label"],
                    color=color_for(c.get("key", ""), i), ls=c.get("ls", "-"), marker=c.get("marker"),
                    markersize=3.5, lw=1.5)
        for depth, value, color in marks:
            ax.plot([value / scale], [depth / a], "o", color=color, markersize=6, markerfacecolor="none")
        ax.invert_yaxis()
        ax.set_xlabel(stress_label)
        ax.set_ylabel(depth_label)
        ax.legend(fontsize=8)
        if title:
            ax.set_title(title)
        return save_figure(fig, path)
