"""The FEM reference's stress field in the axial (r, z) section.

The von Mises stress is recovered by :func:`fem_reference.fields.nodal_stresses` (the same
field the ``.vtu`` file holds); it is drawn on the vertex triangulation of the quadratic
mesh, both bodies, in a window of a few contact radii around the contact.
"""

from __future__ import annotations

import numpy as np

from bem.checks import InputError, check_positive

from .style import axis_labels, new_figure, save_figure

__all__ = ["plot_section_field", "plot_von_mises", "von_mises_of", "section_field_from_vtu"]


def plot_section_field(r, z, triangles, values, path, *, a, scale, label, window=3.0, contact_radius=None,
                       title=None, labels=None, length_unit=None):
    """A scalar field on an (r, z) triangulation, mirrored about the axis for readability.

    Parameters
    ----------
    r, z : array_like, shape (n,)
        Vertex coordinates [length].
    triangles : array_like of int, shape (t, 3)
        Vertex triangles.
    values : array_like, shape (n,)
        Field at the vertices (same unit as ``scale``).
    path : path-like
        PNG file to write.
    a : float
        Length scale [length] (axes in ``r / a``, ``z / a``).
    scale : float
        Field scale (colour bar shows ``values / scale``).
    label : str
        Colour-bar label (mathtext), e.g. ``r"$\\sigma_{vM}\\,/\\,p_0$"``.
    window : float
        Half-width and half-height of the window in units of ``a``.
    contact_radius : float, optional
        Edge of the contact [length], marked on the interface.
    title : str, optional
        Axes title.
    labels : dict, optional
        ``{"r", "z"}`` axis labels (:func:`validation.report.style.axis_labels`).
    length_unit : str, optional
        Unit of ``r / a`` shown with the contact radius in the legend (default: ``a_H``
        without ``labels``, nothing with them).

    Returns
    -------
    str
        ``path``.
    """
    import matplotlib.tri as mtri

    a, scale = check_positive("a", a), check_positive("scale", scale)
    r, z, values = (np.asarray(v, dtype=float) for v in (r, z, values))
    tri = np.asarray(triangles, dtype=np.int64)
    if tri.ndim != 2 or tri.shape[1] != 3 or r.shape != z.shape or values.shape != r.shape:
        raise InputError("r, z, values must have one shape (n,) and triangles the shape (t, 3).")
    centre_r = r[tri].mean(axis=1)
    centre_z = z[tri].mean(axis=1)
    near = (centre_r <= 1.15 * window * a) & (np.abs(centre_z) <= 1.15 * window * a)
    tri = tri[near]
    if tri.size == 0:
        raise InputError("no triangle lies in the window: make window larger.")
    # mirror about the axis: r -> -r
    n = r.size
    rr = np.concatenate([r, -r]) / a
    zz = np.concatenate([z, z]) / a
    vv = np.concatenate([values, values]) / scale
    tt = np.vstack([tri, tri[:, ::-1] + n])
    triang = mtri.Triangulation(rr, zz, tt)
    vmax = float(np.percentile(vv[np.unique(tt)], 99.8))
    with new_figure((5.8, 4.6)) as (fig, ax):
        pc = ax.tripcolor(triang, vv, shading="gouraud", cmap="magma", vmin=0.0, vmax=vmax, rasterized=True)
        ax.tricontour(triang, vv, levels=np.linspace(0, vmax, 9)[1:-1], colors="white", linewidths=0.5,
                      alpha=0.6)
        ax.axhline(0.0, color="#00d0ff", lw=1.0, ls="--")
        if contact_radius:
            rc = contact_radius / a
            ax.plot([-rc, rc], [0.0, 0.0], color="#00d0ff", lw=3.0, solid_capstyle="butt",
                    label=f"contact, $r_c$ = {rc:.4g}" + (" $a_H$" if labels is None and length_unit is None
                                                           else f" {length_unit}" if length_unit else ""))
            ax.legend(loc="upper right", fontsize=8, facecolor="#333333", labelcolor="white", framealpha=0.8)
        bar = fig.colorbar(pc, ax=ax, pad=0.01)
        bar.set_label(label)
        ax.set_xlim(-window, window)
        ax.set_ylim(-window, window)
        ax.set_aspect("equal")
        ax.grid(False)
        lab = axis_labels(labels)
        ax.set_xlabel(lab["r"] + " (mirrored about the axis)")
        ax.set_ylabel(lab["z"] + "  (upper body $z > 0$)")
        if title:
            ax.set_title(title)
        return save_figure(fig, path)


def von_mises_of(fem_result):
    """Vertex coordinates, triangles and von Mises stress of an FEM result.

    Returns
    -------
    r, z : ndarray
        Vertex coordinates [length].
    triangles : ndarray of int, shape (t, 3)
    von_mises : ndarray
        Von Mises stress at the vertices [pressure].
    """
    from fem_reference.fields import nodal_stresses

    model = getattr(fem_result, "model", None)
    if model is None or getattr(fem_result, "displacement", None) is None:
        raise InputError("fem_result has no model/displacement: it must come from fem_reference.solve.")
    basis = model.scalar_basis
    vm = nodal_stresses(model, fem_result.displacement)["von_mises"]
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


def plot_von_mises(fem_result, path, *, a, p0, window=3.0, title=None):
    """Von Mises stress ``sigma_vM / p0`` of an FEM reference solution in the (r, z) section.

    Parameters
    ----------
    fem_result : fem_reference.FemResult
        Solution of :func:`fem_reference.solve` (holds the model and displacement).
    path : path-like
        PNG file to write.
    a, p0 : float
        Length and stress scales (Hertz radius and peak pressure).
    window : float
        Half-size of the window in units of ``a``.
    title : str, optional
        Axes title.

    Returns
    -------
    str
        ``path``.
    """
    r, z, tri, vm = von_mises_of(fem_result)
    return plot_section_field(r, z, tri, vm, path, a=a, scale=p0, label=r"von Mises stress $\sigma_{vM}\,/\,p_0$",
                              window=window, contact_radius=fem_result.contact_radius,
                              title=title or "FEM reference: von Mises stress in the axial section")
