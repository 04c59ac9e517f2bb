"""Figures of the two-scale check (:mod:`validation.studies.two_scale`).

- :func:`plot_pressure_map`: the resolved rough sphere's pressure, binned onto square pixels,
  with the nominal contact circle (99 % of the force) of the resolved solution and of the
  layer model;
- :func:`plot_windowed_profile`: along ``y = 0``, the resolved pressure averaged over windows of
  one roll-off wavelength, the layer model's nodal pressure and its window averages, and
  Greenwood and Tripp's.

:func:`validation.studies.two_scale_figure.figure_data` keeps what the two figures draw, small
enough for ``two_scale.json``; :func:`plot_two_scale_data` draws them from it (the studies report).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...studies.two_scale_figure import binned_map, nodal, profile_curves
from ..render.style import color_for, new_figure, save_figure

__all__ = ["plot_pressure_map", "plot_pressure_image", "plot_windowed_profile", "plot_profile_curves",
           "plot_two_scale", "plot_two_scale_data"]


def plot_pressure_map(x, y, p, *, extent, radius, layer_radius, path, title=None):
    """The pressure map [GPa] over ``[-extent, extent]^2`` [um] with the nominal contact circles; returns the file.

    Pixels of about two lattice steps (at most 400 across) hold several nodes each
    (:func:`plot_pressure_image`).
    """
    step = np.sqrt(4 * extent**2 / max(np.asarray(x).size, 1))  # about the node spacing
    edges, image = binned_map(x, y, p, extent, pixels=int(min(400, max(8, extent / step))))
    return plot_pressure_image(edges, image, radius=radius, layer_radius=layer_radius, path=path, title=title)


def plot_pressure_image(edges, image, *, radius, layer_radius, path, title=None):
    """A binned pressure map ``image`` [Pa] on square pixels with ``edges`` [m] and the circles of
    ``radius`` (resolved) and ``layer_radius`` [m]; returns the file.

    The colour scale ends at the 99.5th percentile of the pixels, brighter ones are drawn at its end.
    """
    edges, image = np.asarray(edges, dtype=float), np.asarray(image, dtype=float)
    t = np.linspace(0, 2 * np.pi, 361)
    with new_figure((5.6, 4.8), title=title) as (fig, ax):
        im = ax.pcolormesh(edges * 1e6, edges * 1e6, image / 1e9, cmap="viridis", shading="flat",
                           rasterized=True, vmin=0, vmax=np.nanpercentile(image, 99.5) / 1e9)
        fig.colorbar(im, ax=ax, label="pressure [GPa] (pixel mean)")
        ax.plot(radius * np.cos(t) * 1e6, radius * np.sin(t) * 1e6, color="white", lw=1.2,
                label=f"resolved, 99 % of P: {radius * 1e6:.1f} um")
        ax.plot(layer_radius * np.cos(t) * 1e6, layer_radius * np.sin(t) * 1e6, color="#ff7f0e", lw=1.2, ls="--",
                label=f"layer model: {layer_radius * 1e6:.1f} um")
        ax.set_aspect("equal")
        ax.grid(False)
        ax.set_xlabel("x [um]")
        ax.set_ylabel("y [um]")
        ax.legend(loc="upper right", fontsize="small")
        return save_figure(fig, path)


def plot_windowed_profile(resolved, layer, gt, *, width, path, title=None, wide=None):
    """Windowed pressure along ``y = 0`` [GPa] against x [um]; each argument an ``(x, y, p)`` of nodal values.

    ``wide`` (optional): a second window width [length], the resolved pressure's means over it drawn too.
    """
    return plot_profile_curves(profile_curves(resolved, layer, gt, width=width, wide=wide), width=width, wide=wide,
                               path=path, title=title)


def plot_profile_curves(curves, *, width, path, title=None, wide=None):
    """The windowed profile from :func:`profile_curves` (``curves``: name -> ``(x [m], p [Pa])``); returns the file."""
    c = {k: (np.asarray(x, dtype=float), np.asarray(p, dtype=float)) for k, (x, p) in curves.items()}
    with new_figure((6.4, 4.0), title=title) as (fig, ax):
        xr, pr = c["resolved"]
        ax.step(xr * 1e6, pr / 1e9, where="mid", color=color_for("", 0), lw=1.6,
                label=f"resolved, mean over {width * 1e6:g} um windows")
        if wide and "resolved_wide" in c:
            xw, pw = c["resolved_wide"]
            ax.step(xw * 1e6, pw / 1e9, where="mid", color=color_for("", 3), lw=1.2,
                    label=f"resolved, mean over {wide * 1e6:g} um windows")
        xs, ps = c["layer"]
        ax.plot(xs * 1e6, ps / 1e9, color=color_for("", 1), lw=1.2, label="layer model, nodal")
        xl, pl = c["layer_windows"]
        ax.plot(xl * 1e6, pl / 1e9, "o", color=color_for("", 1), ms=4, label="layer model, window means")
        xg, pg = c["gt"]
        ax.plot(xg * 1e6, pg / 1e9, color=color_for("", 2), lw=1.0, ls="--", label="Greenwood-Tripp, nodal")
        ax.set_xlabel("x [um]")
        ax.set_ylabel("pressure [GPa]")
        ax.set_ylim(0, 1.5 * ax.get_ylim()[1])  # room for the legend above the curves
        ax.legend(fontsize="x-small", loc="upper left", ncols=2)
        return save_figure(fig, path)


def plot_two_scale(data, fields, out):
    """The two figures of the case in ``fields`` (:func:`validation.studies.two_scale.run_case`) in ``out``.

    ``fields`` holds ``resolved``, ``layer``, ``gt`` (results or dicts with ``x, y, p``), ``width``,
    ``extent``, ``ratio`` and ``load_factor``; ``data`` the study's dict. Returns the files.
    """
    from validation.studies.two_scale_models import nominal_radius

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    res, lay, gt = nodal(fields["resolved"]), nodal(fields["layer"]), nodal(fields["gt"])
    case = _case(fields)
    return [plot_pressure_map(*res, extent=fields["extent"], radius=nominal_radius(*res),
                              layer_radius=nominal_radius(*lay), path=out / "two_scale_map.png",
                              title=f"Resolved rough sphere, {case}"),
            plot_windowed_profile(res, lay, gt, width=fields["width"], path=out / "two_scale_profile.png",
                                  title=f"Pressure along y = 0, {case}", wide=fields.get("wide"))]


def _case(f):
    return f"a_H/lambda_L = {f['ratio']:g}, P = {f['load_factor']:g} P1"


def plot_two_scale_data(figure, out):
    """The two figures from :func:`figure_data` (``figure``, as read from ``two_scale.json``) in ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    image = np.array([[np.nan if v is None else v for v in row] for row in figure["map"]], dtype=float)
    edges = np.linspace(-figure["extent"], figure["extent"], image.shape[1] + 1)
    case = _case(figure)
    curves = {k: tuple(np.array([np.nan if v is None else v for v in a], dtype=float) for a in xy)
              for k, xy in figure["profile"].items()}
    return [plot_pressure_image(edges, image, radius=figure["radius"], layer_radius=figure["layer_radius"],
                                path=out / "two_scale_map.png", title=f"Resolved rough sphere, {case}"),
            plot_profile_curves(curves, width=figure["width"], wide=figure.get("wide"),
                                path=out / "two_scale_profile.png", title=f"Pressure along y = 0, {case}")]
