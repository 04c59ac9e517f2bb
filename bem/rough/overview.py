"""What a measured surface holds, in one dictionary: the numbers ``contactlab surface`` prints.

:func:`summary` gathers a :class:`bem.rough.RoughSurface`'s statistics (SurfaceTopography's,
in the surface's length unit), its grid and pixel size, the missing points filled when it was
read, its spikes (:func:`bem.rough.find_spikes`), its seam (the edge jump of the periodic cell,
:mod:`bem.rough.surface`) and the default periodic lattice cell that a law or a scene would use
(:meth:`bem.rough.RoughSurface.default_n_cols`, rows by the rule of
:func:`bem.periodic.cell.rows_for`), without resampling.
"""

from __future__ import annotations

from ..periodic.cell import rows_for
from .outliers import SPIKE_THRESHOLD, find_spikes

__all__ = ["summary"]


def summary(surface, *, threshold=SPIKE_THRESHOLD):
    """The numbers of a rough surface as plain JSON values (module docstring).

    Parameters
    ----------
    surface : bem.rough.RoughSurface
        The surface, as read (lengths in its unit, metres from :func:`bem.rough.read_surface`).
    threshold : float
        The spike threshold in robust standard deviations (:func:`bem.rough.find_spikes`).

    Returns
    -------
    dict
        ``stats`` (:meth:`bem.rough.SurfaceStats.as_dict`), ``pixel`` ``(dx, dy)``,
        ``spikes`` (:meth:`bem.rough.Spikes.as_dict` and ``count``), ``lattice`` (``n_cols``, ``n_rows``,
        ``step``, ``nodes``: the default cell) and ``data_points`` (``nx ny``).
    """
    stats = surface.stats
    n_cols = surface.default_n_cols()
    step = surface.size[0] / n_cols
    n_rows = rows_for(step, surface.size[1])
    spikes = find_spikes(surface.heights, threshold=threshold)
    return {"stats": stats.as_dict(), "pixel": list(stats.pixel), "spikes": dict(spikes.as_dict(), count=spikes.count),
            "lattice": {"n_cols": n_cols, "n_rows": n_rows, "step": step, "nodes": n_cols * n_rows},
            "data_points": stats.grid[0] * stats.grid[1]}
