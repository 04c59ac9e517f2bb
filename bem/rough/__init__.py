"""Rough surfaces on the periodic triangular lattice.

:mod:`bem.rough.surface` reads measured topographies from instrument files and synthesises
seeded self-affine surfaces through the optional package SurfaceTopography
(``pip install "contactlab[rough]"``), with their statistics and the periodic cell of a
measured patch; :mod:`bem.rough.lattice_heights` resamples a periodic height grid onto the
lattice cell (numpy only, no extra needed). docs/rough.md shows the whole path.
"""

from .lattice_heights import MAX_STRETCH, LatticeHeights, to_lattice
from .surface import (DETRENDS, EDGE_JUMP_LIMIT, MIN_POINTS, RoughSurface, SurfaceStats, combined, formats,
                      from_heights, read_surface, self_affine)

__all__ = ["RoughSurface", "SurfaceStats", "LatticeHeights", "read_surface", "self_affine", "from_heights",
           "combined", "formats", "to_lattice", "DETRENDS", "EDGE_JUMP_LIMIT", "MAX_STRETCH", "MIN_POINTS"]
