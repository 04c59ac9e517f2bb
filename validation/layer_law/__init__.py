"""The layer law of a rough surface as a folder: the law file and its figures (``contactlab layer-law``).

:func:`surface_from_file` and :func:`synthetic_surface` make the surface in SI units,
:func:`make_layer_law` solves the ladder (:func:`bem.rough.layer_from_topography`) and writes
the folder, :mod:`.figures` draws the law. The law file needs the ``rough`` extra, the figures
the ``report`` extra.
"""

from .build import (FIGURE_NAMES, LAW_FILE, NAMES, LayerLawFolder, ladder, make_layer_law, surface_from_file,
                    synthetic_surface)

__all__ = ["make_layer_law", "surface_from_file", "synthetic_surface", "ladder", "LayerLawFolder", "LAW_FILE",
           "FIGURE_NAMES", "NAMES"]
