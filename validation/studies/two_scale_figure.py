"""What the two figures of the two-scale check draw (:mod:`validation.studies.two_scale`), as data.

:func:`figure_data` keeps it small enough for ``two_scale.json`` (a binned map and the profiles);
:mod:`validation.report.figures.two_scale` draws it.
"""

from __future__ import annotations

import numpy as np

from ..compare import axial_section
from .two_scale_models import nominal_radius, windowed

__all__ = ["binned_map", "window_row", "profile_curves", "nodal", "figure_data", "JSON_PIXELS"]

#: pixels across the pressure map kept in ``two_scale.json``
JSON_PIXELS = 96


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
    ix, iy, mean, _ = windowed(x, y, p, width)
    row = iy == 0
    order = np.argsort(ix[row])
    return ix[row][order] * width, mean[row][order]


def profile_curves(resolved, layer, gt, *, width, wide=None):
    """The curves of the windowed profile along ``y = 0``: ``{name: (x [m], p [Pa])}``.

    ``resolved`` (window means of ``width``, and of ``wide`` when given), ``layer`` (nodal),
    ``layer_windows`` (its window means), ``gt`` (nodal); each argument an ``(x, y, p)`` of nodal values.
    """
    out = {"resolved": window_row(*resolved, width)}
    if wide:
        out["resolved_wide"] = window_row(*resolved, wide)
    out.update(layer=axial_section(*layer), layer_windows=window_row(*layer, width), gt=axial_section(*gt))
    return out


def nodal(r):
    """``(x, y, p)`` arrays of a result or of a dict with those keys."""
    return tuple(np.asarray(r[k] if isinstance(r, dict) else getattr(r, k)) for k in ("x", "y", "p"))


def _short(values):
    """Floats rounded to 4 significant digits, NaN as None (JSON)."""
    a = np.asarray(values, dtype=float)
    return [None if not np.isfinite(v) else float(f"{v:.4g}") for v in a.ravel()] if a.ndim == 1 else \
        [_short(row) for row in a]


def figure_data(fields, pixels=JSON_PIXELS):
    """What the two figures of the case in ``fields`` draw, JSON-ready and modest in size.

    ``map``: the resolved pressure [Pa] binned on ``pixels x pixels`` squares over
    ``[-extent, extent]^2``, at most ``pixels`` and about two lattice steps across (``image[i][j]``:
    row ``i`` along y; ``None`` where no node falls);
    ``radius``, ``layer_radius``: the nominal radii [m]; ``profile``: the curves of
    :func:`profile_curves`, each ``[x [m], p [Pa]]``; ``width``, ``wide`` [m]; 4 significant digits.
    """
    res, lay, gt = nodal(fields["resolved"]), nodal(fields["layer"]), nodal(fields["gt"])
    extent = float(fields["extent"])
    step = np.sqrt(4 * extent**2 / max(res[0].size, 1))  # about the node spacing: pixels of two steps or more
    _, image = binned_map(*res, extent, pixels=int(min(pixels, max(8, extent / step))))
    curves = profile_curves(res, lay, gt, width=fields["width"], wide=fields.get("wide"))
    return dict(ratio=fields["ratio"], load_factor=fields["load_factor"], extent=extent,
                width=float(fields["width"]), wide=fields.get("wide"), radius=nominal_radius(*res),
                layer_radius=nominal_radius(*lay), map=_short(image),
                profile={k: [_short(x), _short(p)] for k, (x, p) in curves.items()})
