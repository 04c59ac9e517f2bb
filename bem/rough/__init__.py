"""Rough surfaces on the periodic triangular lattice.

:mod:`bem.rough.instrument_files` reads measured topographies from instrument files and
:mod:`bem.rough.surface` synthesises seeded self-affine surfaces, both through the optional
package SurfaceTopography (``pip install "contactlab[rough]"``), with their statistics and the
periodic cell of a measured patch; :mod:`bem.rough.layer_law` makes the layer law ``w(p)`` of a
rough surface from its periodic contact under a ladder of mean pressures (:mod:`bem.rough.law_file` reads its
table file back); :mod:`bem.rough.outliers`
finds and removes spikes, :mod:`bem.rough.patch` makes the periodic cell of a surface as measured,
:mod:`bem.rough.persson` gives Persson's theory from a PSD; :mod:`bem.rough.lattice_heights`
resamples a periodic height grid onto the lattice cell (numpy only, no extra needed). docs/rough.md
shows the whole path.

:mod:`bem.rough.file_guards` checks a file's header before it is read and
:mod:`bem.rough.overview` gathers what a surface holds (``contactlab surface``).
"""

from .lattice_heights import MAX_STRETCH, LatticeHeights, to_lattice
from .instrument_files import formats, read_surface
from .instrument_files import FILLS, MAX_MISSING
from .overview import summary
from .outliers import SPIKE_THRESHOLD, Spikes, find_spikes, remove_spikes
from .patch import CELLS, DETREND_CHOICES, PatchCell, patch_cell
from .layer_law import LadderNotConverged, TopographyLaw, layer_from_topography
from .law_file import read_layer_law
from .surface import (DETRENDS, EDGE_JUMP_LIMIT, MIN_POINTS, RoughSurface, SurfaceStats, combined, from_heights,
                      self_affine)

__all__ = ["RoughSurface", "SurfaceStats", "LatticeHeights", "read_surface", "self_affine", "from_heights",
           "combined", "formats", "to_lattice", "layer_from_topography", "read_layer_law", "TopographyLaw",
           "LadderNotConverged", "Spikes", "find_spikes", "remove_spikes", "SPIKE_THRESHOLD", "PatchCell",
           "patch_cell", "CELLS", "DETREND_CHOICES", "DETRENDS",
           "EDGE_JUMP_LIMIT", "MAX_STRETCH", "MIN_POINTS"]
__all__ += ["FILLS", "MAX_MISSING", "summary"]
