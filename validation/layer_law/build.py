"""A rough surface's layer law written as a folder: the law file and its figures.

The folder (a ``"layer-law"`` folder, :mod:`validation.io`) holds

- ``layer_law.toml``: the table file of :meth:`bem.rough.TopographyLaw.save`, whose ``[layer]``
  a scene names by ``[layer] law = "tabulated"``, ``file = "layer_law.toml"``;
- ``closure.png``, ``contact_fraction.png``, ``stiffness.png``, ``persson.png``: the law ``w(p)``
  on linear and logarithmic axes, the contact fraction ``A/A0`` against ``p/(E* h'_rms)``, the
  interfacial stiffness ``K(p)``, and ``A/A0`` and the mean gap beside Persson's theory for the
  cell's spectrum (:mod:`validation.layer_law.figures`).

Units are SI: a surface file's lengths are converted to metres by the unit the file states
(or by ``scale``), ``E*`` and the pressures are in Pa. The ladder of mean pressures is
geometric, by default from ``3e-3`` to ``0.3`` times ``E* h'_rms`` (``h'_rms`` the surface's
rms slope, ``stats.rms_slope``): from a contact fraction of about 1 % to well into the
exponential regime. Its last pressure must exceed the largest local pressure of the problems
the law is used in: beyond it a tabulated law holds no data (:func:`bem.layers.beyond_table`).
Below its first pressure the law is a straight line through ``(0, 0)``: the ladder is extended
downwards until that holds at most :data:`MAX_INTERPOLATED` (1 %) of its closure.

With a hardness ``H`` [Pa] the asperities flow at ``H`` (:mod:`bem.rough.layer_law`): the law file
records ``H`` and the share of the cell that flows, the figures name ``H``, and the ladder must
lie below ``H`` (a default ladder reaching it is refused by name: give a lower range).

A measured surface becomes its periodic cell by :func:`bem.rough.patch_cell` (detrending,
spikes, a repeated or mirrored cell); the law file records what was done
(``[topography.preparation]``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bem.checks import check_int, check_positive, fail

from ..io import atomic_directory, check_output_dir, output_errors, recover_output_dir

__all__ = ["make_layer_law", "surface_from_file", "synthetic_surface", "ladder", "LayerLawFolder", "KIND",
           "LAW_FILE", "FIGURE_NAMES", "NAMES", "DEFAULT_RANGE", "MAX_INTERPOLATED"]

KIND = "layer-law"
LAW_FILE = "layer_law.toml"
FIGURE_NAMES = ("closure.png", "contact_fraction.png", "stiffness.png", "persson.png")
NAMES = (LAW_FILE, *FIGURE_NAMES)
#: the default ladder's first and last mean pressure, in units of ``E* h'_rms``
DEFAULT_RANGE = (3e-3, 0.3)
#: the largest share of the closure a law leaves below its first pressure (:func:`make_layer_law`)
MAX_INTERPOLATED = 0.01


@dataclass(frozen=True)
class LayerLawFolder:
    """What :func:`make_layer_law` wrote.

    Attributes
    ----------
    path : pathlib.Path
        The folder.
    law : bem.rough.TopographyLaw
        The law and its ladder.
    law_file : pathlib.Path
        ``path / "layer_law.toml"``.
    figures : dict
        ``{file name: matplotlib Figure}`` of the figures written (empty without figures).
    """

    path: Path
    law: object
    law_file: Path
    figures: dict = field(default_factory=dict)


def surface_from_file(file, *, scale=None, physical_sizes=None, detrend="auto", cell="repeat", spikes="keep",
                      spike_threshold=None, fill=None, n_cols=None, names=None):
    """The periodic cell of a measured surface in metres (:func:`bem.rough.read_surface`,
    :func:`bem.rough.patch_cell`).

    Parameters
    ----------
    file : path-like
        An instrument or data file SurfaceTopography reads (``bem.rough.formats()``).
    scale : float, optional
        Metres per length unit of a file that states none (npy, plain text matrices); the unit
        a file states is always the one used (a ``scale`` that disagrees with it is refused).
    physical_sizes : (float, float), optional
        ``(Lx, Ly)`` in the file's length unit, for a file that does not state its size.
    detrend, cell, spikes, spike_threshold
        As :func:`bem.rough.patch_cell` (``spike_threshold`` ``None``: its default).
    fill : str or None
        As :func:`bem.rough.read_surface`.
    n_cols : int, optional
        The lattice nodes along x the cell will be solved on (default: the cell's own,
        ``Lx / max(dx, dy)``): the cell is refused before it is made when it would hold more
        than :func:`bem.checks.max_nodes` nodes (:func:`bem.rough.patch.check_cell_size`; a
        mirrored cell counts ``2 x 2`` patches).
    names : dict, optional
        The names of the arguments in messages (:func:`bem.rough.read_surface`; ``cell`` and
        ``n_cols`` too).

    Returns
    -------
    bem.rough.PatchCell
        The cell in metres and what was done to make it; the one warning about its seam is in metres.

    Raises
    ------
    bem.InputError
        A file that cannot be read (:func:`bem.rough.read_surface`), no ``scale`` for a file
        that states no length unit, or a cell too large.
    """
    from bem import rough
    from bem.rough.patch import check_cell_size, quiet_seam

    names = {"unit": "scale", **(names or {})}
    with quiet_seam():  # the seam is that of the cell made below, in metres
        surface = rough.read_surface(file, physical_sizes=physical_sizes, unit=scale, detrend=None, fill=fill,
                                     names=names)  # in metres already
    check_cell_size(surface, cell=cell, n_cols=n_cols, names=names)
    return rough.patch_cell(surface, detrend=detrend, cell=cell, spikes=spikes, **_threshold(spike_threshold))


def _threshold(spike_threshold):
    return {} if spike_threshold is None else {"spike_threshold": spike_threshold}


def synthetic_surface(*, hurst, size, grid, rms_height=None, rms_slope=None, long_cutoff=None, short_cutoff=None,
                      rolloff=1.0, seed=0, spikes="keep", spike_threshold=None):
    """A seeded self-affine square cell (:func:`bem.rough.self_affine`): ``size`` [m] across,
    ``grid`` points across; the other arguments as there (lengths in m). Returns its
    :class:`bem.rough.PatchCell` (periodic: no detrending; ``spikes`` as :func:`bem.rough.patch_cell`)."""
    from bem import rough

    grid = check_int("grid", grid)
    size = check_positive("size", size)
    surface = rough.self_affine((grid, grid), (size, size), hurst=hurst, rms_height=rms_height, rms_slope=rms_slope,
                                long_cutoff=long_cutoff, short_cutoff=short_cutoff, rolloff=rolloff,
                                seed=check_int("seed", seed, minimum=0))
    return rough.patch_cell(surface, spikes=spikes, **_threshold(spike_threshold))


def ladder(surface, E_star, *, pressures=None, relative=DEFAULT_RANGE, n=12):
    """The geometric ladder of ``n`` mean pressures [Pa].

    ``pressures = (low, high)`` [Pa] gives its ends; otherwise ``relative = (low, high)`` does,
    in units of ``E* h'_rms`` (``h'_rms = surface.stats.rms_slope``; ``surface`` a
    :class:`bem.rough.RoughSurface` or :class:`bem.rough.PatchCell`).
    """
    surface, _ = _surface_and_record(surface)
    n = check_int("n", n, minimum=2)
    E_star = check_positive("E_star", E_star)
    if pressures is not None:
        name, (low, high), unit = "pressures", pressures, 1.0
    else:
        name, (low, high), unit = "relative", relative, E_star * surface.stats.rms_slope
        if not 0 < unit < math.inf:
            fail(name, relative, f"used with a surface of rms slope > 0 (this one's is {surface.stats.rms_slope!r}: "
                                 "it is flat); give the pressures themselves")
    low, high = check_positive(f"{name}[0]", low), check_positive(f"{name}[1]", high)
    if high <= low:
        fail(name, (low, high), "increasing: (low, high) with low < high")
    return np.geomspace(low, high, n) * unit


def _surface_and_record(surface):
    """``(RoughSurface, what was done to it)`` of a surface or a :class:`bem.rough.PatchCell`."""
    from bem.rough import PatchCell

    return (surface.surface, surface.record()) if isinstance(surface, PatchCell) else (surface, None)


def _check_figures(figures):
    if figures:
        from ..extras import require

        require("report", "the figures of a layer law (or no figures: contactlab layer-law --no-figures)")


def make_layer_law(surface, out_dir, *, E_star, pressures, n_cols=None, method="newton", rtol=1e-8, figures=True,
                   progress=None, what="out_dir", max_interpolated=MAX_INTERPOLATED, hardness=None):
    """Solve the layer law of ``surface`` and write its folder ``out_dir`` (module docstring).

    Parameters
    ----------
    surface : bem.rough.PatchCell or bem.rough.RoughSurface
        In metres; a :class:`~bem.rough.PatchCell` (:func:`surface_from_file`,
        :func:`synthetic_surface`) records what was done to the surface in the law file.
    out_dir : path-like
        The folder written: new, empty, or a layer-law folder contactlab wrote (replaced whole).
    E_star : float
        Effective modulus of the pair [Pa].
    pressures : array_like
        The ladder of mean pressures [Pa] (:func:`ladder`).
    n_cols : int, optional
        Lattice nodes across the cell (default: the surface's grid points along x).
    method, rtol
        As :func:`bem.rough.layer_from_topography`.
    progress : callable, optional
        ``progress(label, done, total)`` (:mod:`validation.progress`) after each step of the ladder,
        the label giving the step's contact fraction and iterations.
    figures : bool
        Draw the figures (needs the ``report`` extra).
    what : str
        The argument named in messages about ``out_dir`` (``"--out"``).
    max_interpolated : float or None
        As :func:`bem.rough.layer_from_topography` (default :data:`MAX_INTERPOLATED`: the
        ladder is extended downwards until at most 1 % of its closure lies below its first
        pressure).
    hardness : float, optional
        The hardness ``H`` [Pa] of plastic asperities, above the ladder (as
        :func:`bem.rough.layer_from_topography`); ``None``: elastic.

    Returns
    -------
    LayerLawFolder

    Raises
    ------
    bem.InputError
        A bad argument, a missing extra, a ladder whose mean gap rises (checked before any solve
        where possible).
    validation.io.OutputError
        ``out_dir`` may not be written (checked before the ladder is solved).
    bem.rough.LadderNotConverged
        A step of the ladder did not converge; nothing is written.
    """
    from bem import rough

    _check_figures(figures)
    out_dir = Path(out_dir)
    with output_errors(out_dir.absolute(), what):
        recover_output_dir(out_dir)
        check_output_dir(out_dir, KIND, NAMES, what=what)
    surface, record = _surface_and_record(surface)
    n_cols = surface.default_n_cols() if n_cols is None else n_cols
    step = None if progress is None else (
        lambda k, n, res: progress(f"A/A0 {res.contact_fraction:.3g}, {res.iterations} iterations", k, n))
    law = rough.layer_from_topography(surface, E_star, pressures=pressures, n_cols=n_cols, method=method, rtol=rtol,
                                      progress=step, max_interpolated=max_interpolated, preparation=record,
                                      hardness=hardness)
    drawn = {}
    with atomic_directory(out_dir, KIND, NAMES, what=what) as tmp:
        law.save(tmp / LAW_FILE)
        if figures:
            from .figures import draw_all

            drawn = draw_all(law, tmp)
    return LayerLawFolder(out_dir, law, out_dir / LAW_FILE, drawn)

