"""Figures of the two-scale check (:mod:`validation.studies.two_scale`).

- :func:`plot_pressure_map`: the resolved rough sphere's pressure, binned onto square pixels,
  with the nominal contact circle (99 % of the force) of the resolved solution and of the
  layer model;
- :func:`plot_windowed_profile`: along ``y = 0``, the resolved pressure averaged over windows of
  one roll-off wavelength, the layer model's nodal pressure and its window averages, and
  Greenwood and Tripp's.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..render.style import color_for, new_figure, save_figure

__all__ = ["binned_map", "window_row", "plot_pressure_map", "plot_windowed_profile", "plot_two_scale"]


def binned_map(x, y, p, extent, pixels=400):
    """``(edges, image)``: the mean of the nodal ``p`` in ``pixels x pixels`` squares over ``[-extent, extent]^2``.

    ``image[i, j]`` is the square ``i`` along y, ``j`` along x; NaN where no node falls.
    """
    edges = np.linspace(-extent, extent, pixels + 1)
    total, _, _ = np.histogram2d(y, x, bins=(edges, edges), weights=p)
    count, _, _ = np.histogram2d(y, x, bins=(edges, edges))
    with np.errstate(invalid="ignore", divide="ignore"):
        return edges, np.where(count > 0, total / np.maximum(count, 1), np.nan)


def window_row(x, y, p, width):
    """``(centres, means)`` of the windows of side ``width`` on the row through ``y = 0`` (sorted by x)."""
    from validation.studies.two_scale_models import windowed

    ix, iy, mean, _ = windowed(x, y, p, width)
    row = iy == 0
    order = np.argsort(ix[row])
    return ix[row][order] * width, mean[row][order]


def plot_pressure_map(x, y, p, *, extent, radius, layer_radius, path, title=None):
    """The pressure map [GPa] over ``[-extent, extent]^2`` [um] with the nominal contact circles; returns the file.

    Pixels of about two lattice steps (at most 400 across) hold several nodes each; the colour
    scale ends at the 99.5th percentile of the pixels, brighter ones are drawn at its end.
    """
    step = np.sqrt(4 * extent**2 / max(np.asarray(x).size, 1))  # about the node spacing
    edges, image = binned_map(x, y, p, extent, pixels=int(min(400, max(8, extent / step))))
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
    from .profiles import axial_section

    with new_figure((6.4, 4.0), title=title) as (fig, ax):
        xr, pr = window_row(*resolved, width)
        ax.step(xr * 1e6, pr / 1e9, where="mid", color=color_for("", 0), lw=1.6,
                label=f"resolved, mean over {width * 1e6:g} um windows")
        if wide:
            xw, pw = window_row(*resolved, wide)
            ax.step(xw * 1e6, pw / 1e9, where="mid", color=color_for("", 3), lw=1.2,
                    label=f"resolved, mean over {wide * 1e6:g} um windows")
        xs, ps = axial_section(*layer)
        ax.plot(xs * 1e6, ps / 1e9, color=color_for("", 1), lw=1.2, label="layer model, nodal")
        xl, pl = window_row(*layer, width)
        ax.plot(xl * 1e6, pl / 1e9, "o", color=color_for("", 1), ms=4, label="layer model, window means")
        xg, pg = axial_section(*gt)
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
    def nodal(r):
        return tuple(np.asarray(r[k] if isinstance(r, dict) else getattr(r, k)) for k in ("x", "y", "p"))

    from validation.studies.two_scale_models import nominal_radius

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    res, lay, gt = nodal(fields["resolved"]), nodal(fields["layer"]), nodal(fields["gt"])
    case = f"a_H/lambda_L = {fields['ratio']:g}, P = {fields['load_factor']:g} P1"
    return [plot_pressure_map(*res, extent=fields["extent"], radius=nominal_radius(*res),
                              layer_radius=nominal_radius(*lay), path=out / "two_scale_map.png",
                              title=f"Resolved rough sphere, {case}"),
            plot_windowed_profile(res, lay, gt, width=fields["width"], path=out / "two_scale_profile.png",
                                  title=f"Pressure along y = 0, {case}", wide=fields.get("wide"))]
