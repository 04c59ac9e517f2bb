"""Rough surfaces as the gap of a periodic scene: ``[gap] type = "self_affine"`` or ``"surface"``, ``[bem] periodic``.

A rough scene solves the periodic cell of a rough surface pressed by a rigid flat
(:func:`bem.solve_periodic`; docs/scenes.md, "Rough surfaces"). Keys of the ``[gap]`` table
(lengths in the scene's length unit)::

    type = "self_affine"     # a seeded synthetic surface (bem.rough.self_affine)
    size = 1e-3              # cell (Lx, Ly): a number or a pair
    grid = 256               # points (nx, ny): an integer or a pair
    hurst = 0.8              # Hurst exponent, 0 < H <= 1
    rms_height = 1e-6        # or rms_slope [-]; exactly one
    long_cutoff = 2.5e-4     # roll-off wavelength (optional)
    short_cutoff = 2e-5      # short cut-off wavelength (optional)
    rolloff = 1.0            # PSD below the roll-off relative to C(q_L) (optional)
    seed = 1                 # required: the same seed gives the same surface

    type = "surface"         # a measured topography
    file = "patch.x3p"       # relative to the scene file's folder (validation.scene.trust)
    reader = "surfacetopography" | "core"   # bem.rough.read_surface (default) or bem.gaps.measured
    format, channel, physical_sizes         # read_surface's (physical_sizes in the file's unit)
    spacing, nodata                         # the core reader's (read_heights)
    length_unit = "um"       # the file's length unit ("m", "mm", "um", "nm") or a factor, for a file
                             # that states none; the unit a file states is always the one used
    fill = "harmonic"        # fill missing points (at most 5 % of them; default: refused)
    detrend = "auto"         # bem.rough.DETREND_CHOICES: none for a periodic file, height for a patch
    cell = "repeat"          # or "mirror": the patch and its mirror images, 2 x 2 patches, no seam
    spikes = "keep"          # or "remove": fill the spikes (bem.rough.find_spikes) from their neighbours
    spike_threshold = 10     # robust standard deviations beyond which a point is a spike

The cell of a measured surface is made by :func:`bem.rough.patch_cell` (as ``contactlab
layer-law`` makes it): the file is read as measured, detrended, its spikes found (and removed),
the patch repeated or mirrored; ``result.json`` records what was done. The seam is stated
once, by the run (a note of its result), in the scene's length unit (a mirrored cell has none); a mirrored
grid of more than :func:`bem.checks.max_nodes` points is refused before it is made.

Both need SurfaceTopography (the ``rough`` extra, statistics and synthesis): without it the
scene stops before any work with :class:`validation.extras.MissingExtraError`. ``[bem]``
takes ``periodic = true`` (required with a rough gap, refused without one) and
``cell_nodes``, the lattice nodes along x (default: ``Lx / max(dx, dy)``, the data's ``nx``
on square pixels, :meth:`bem.rough.RoughSurface.default_n_cols`); the cell is the surface's.
The statistics name the file as the scene does (relative to the scene file's folder).
``[load]`` takes ``mean_pressure`` [pressure], ``force`` (the force on one cell,
``mean_pressure Lx Ly``) or ``approach``.
"""

from __future__ import annotations

import os
from functools import partial

import numpy as np

from bem import InputError
from bem.checks import check_node_count
from bem.rough.lattice_heights import cell_shape
from bem.rough.patch import quiet_seam

from ..extras import require as require_extra
from . import checks as ck
from .measured import LENGTH_UNITS
from .measured import _factor as length_factor
from .paper import is_paper_law
from .sizing import solver_options

__all__ = ["RoughGap", "ROUGH_TYPES", "GAP_KEYS", "GAP_UNITS", "PERIODIC_KEYS", "rough_gap", "bem_section"]

#: gap type -> its keys besides ``type``
GAP_KEYS = {"self_affine": ("size", "grid", "hurst", "rms_height", "rms_slope", "long_cutoff", "short_cutoff",
                            "rolloff", "seed"),
            "surface": ("file", "reader", "format", "channel", "physical_sizes", "spacing", "nodata", "length_unit",
                        "fill", "detrend", "cell", "spikes", "spike_threshold")}
ROUGH_TYPES = tuple(GAP_KEYS)
#: unit kind of the ``[gap]`` keys of a rough type that carry one (the others are dimensionless or in the file's unit)
GAP_UNITS = dict.fromkeys(("size", "rms_height", "long_cutoff", "short_cutoff"), "length")
#: ``[bem]`` keys of a periodic scene besides the solver options
PERIODIC_KEYS = ("periodic", "cell_nodes")
_LATTICE_KEYS = ("step", "nodes_across", "extent", "extent_factor")
_READERS = ("surfacetopography", "core")


class RoughGap:
    """The gap of a rough scene: a :class:`bem.rough.RoughSurface` against a rigid flat.

    ``cell`` is the :class:`bem.rough.PatchCell` the surface was made by (what was done to it);
    ``lattice`` (:class:`bem.rough.LatticeHeights`) is set by :func:`bem_section`, the initial
    gap of the cell is ``lattice.gap()``.
    """

    is_axisymmetric = False

    def __init__(self, type_name, cell):
        self.type_name, self.cell, self.surface, self.lattice = type_name, cell, cell.surface, None

    def nodal_gap(self):
        """The initial gap at the cell's nodes [length], flattened in the order of the result arrays."""
        return self.lattice.gap().ravel()


def _pair(path, value, check):
    """A number (both axes) or a pair, each checked by ``check(path, v)``."""
    items = value if isinstance(value, list) and len(value) == 2 else [value, value]
    if isinstance(value, list) and len(value) != 2:
        raise ck.SceneError(f"{path} = {value!r} is not allowed: it must be a number or a pair [x, y].")
    return tuple(check(path, v) for v in items)


def _self_affine(d):
    from bem import rough

    for key in ("size", "grid", "hurst", "seed"):
        ck.require("gap", d, key, "a self_affine gap needs size, grid, hurst, seed and rms_height or rms_slope")
    ck.exactly_one("gap", d, ("rms_height", "rms_slope"), "rms height [length] or rms slope [-]")
    kw = {"size": _pair("gap.size", d["size"], ck.scale),
          "grid": _pair("gap.grid", d["grid"], partial(ck.integer, minimum=rough.MIN_POINTS, maximum=8192)),
          "seed": ck.integer("gap.seed", d["seed"], 0)}
    with ck.scene_errors():  # bem's memory guard, before the surface is made
        check_node_count("gap.grid", d["grid"], kw["grid"][0] * kw["grid"][1], what="the surface grid")
    kw.update({k: d[k] for k in ("hurst", "rms_height", "rms_slope", "long_cutoff", "short_cutoff", "rolloff")
               if k in d})
    with ck.scene_errors("gap."):
        return rough.self_affine(**kw)


def _shown(file, base_dir):
    """The file's name as the scene gives it: relative to the scene file's folder when inside it."""
    if base_dir is None:
        return file
    rel = os.path.relpath(file, base_dir)
    return file if rel.startswith(os.pardir) else rel


def _read_surface(file, d, units, source):
    """A file read by SurfaceTopography in the scene's length unit (module docstring, ``length_unit``)."""
    from bem import rough

    given = d.get("length_unit")
    if isinstance(given, str) and given in LENGTH_UNITS:
        given = "um" if given == "µm" else given
    elif given is not None:
        given = length_factor(d, None)
    scene = None if units is None else units.metres
    kw = {k: d[k] for k in ("format", "channel", "physical_sizes", "fill") if k in d}
    names = {"unit": "gap.length_unit", "fill": "gap.fill"}
    with ck.scene_errors("gap."):
        if isinstance(given, str) and scene is None:
            length_factor(d, units)  # the error: no scene length unit to convert to
        named = units.length if scene is not None and units.length in LENGTH_UNITS else None
        with quiet_seam():  # the seam is that of the cell patch_cell makes
            surface = rough.read_surface(file, unit=given, length_unit=named or scene or 1.0, detrend=None,
                                         source=source, names=names, unit_default=1.0, **kw)
    if scene is None and surface.stats.unit is not None:
        raise ck.SceneError(f"gap.file = {source!r} is not allowed: it states its lengths in {surface.stats.unit} "
                            f"and the scene's units label {units.label!r} names no length unit (m, mm, um, nm) to "
                            "convert them to; name one in [scene] units.")
    return surface


def _surface(d, units, base_dir=None):
    from bem import rough
    from bem.gaps.heights import read_heights

    file = ck.string("gap.file", ck.require("gap", d, "file", 'give the topography file, e.g. file = "patch.x3p"'))
    reader = ck.choice("gap.reader", d.get("reader", "surfacetopography"), _READERS)
    own = {"surfacetopography": ("format", "channel", "physical_sizes", "fill"),
           "core": ("format", "spacing", "nodata")}
    for key in GAP_KEYS["surface"][2:9]:
        if key in d and key not in own[reader] and key != "length_unit":
            raise ck.SceneError(f"gap.{key} = {d[key]!r} is not allowed with gap.reader = {reader!r}: that reader "
                                f"takes {', '.join(own[reader])}.")
    source = _shown(file, base_dir)
    if reader == "surfacetopography":
        return _read_surface(file, d, units, source)
    scale = length_factor(d, units)
    with ck.scene_errors("gap."):
        x, y, z = read_heights(file, **{k: d[k] for k in ("format", "spacing", "nodata") if k in d})
    holes = int(np.count_nonzero(~np.isfinite(z)))
    if holes:
        raise ck.SceneError(f"gap.file = {file!r} is not allowed: it has {holes} points without data (NaN holes or "
                            "nodata); the periodic cell needs every point: fill or crop them first.")
    with ck.scene_errors("gap."):
        size = (x.size * (x[1] - x[0]) * scale, y.size * (y[1] - y[0]) * scale)
        return rough.from_heights(z * scale, size, source=source)


def rough_gap(d, *, units=None, base_dir=None):
    """``(spec, RoughGap)`` of a ``[gap]`` of a rough type (module docstring).

    ``base_dir``: the scene file's folder, from which the statistics name the file.

    Raises
    ------
    validation.extras.MissingExtraError
        SurfaceTopography cannot be imported ("install contactlab[rough]"); nothing has run.
    validation.scene.SceneError
        A bad key or value; the message names it (``gap.hurst = ...``).
    """
    kind = d["type"]
    ck.unknown_keys("gap", d, ("type", *GAP_KEYS[kind]))
    if kind == "surface" and isinstance(d.get("file"), str) and not os.path.isfile(d["file"]):
        raise ck.SceneError(f"gap.file = {_shown(d['file'], base_dir)!r} is not allowed: there is no such file "
                            "(a relative name starts from the scene file's folder).")
    options = _cell_options(d) if kind == "surface" else {}
    require_extra("rough", f"gap.type = {kind!r} (a rough surface)")
    surface = _self_affine(d) if kind == "self_affine" else _surface(d, units, base_dir)
    return dict(d), RoughGap(kind, _cell(surface, options, units))


def _cell_options(d):
    """The keys of :func:`bem.rough.patch_cell` of a ``type = "surface"`` gap, checked before the file is read."""
    from bem.rough.outliers import SPIKE_THRESHOLD
    from bem.rough.patch import CELLS, DETREND_CHOICES, SPIKE_ACTIONS

    return {"detrend": ck.choice("gap.detrend", d.get("detrend", "auto"), DETREND_CHOICES),
            "cell": ck.choice("gap.cell", d.get("cell", "repeat"), CELLS),
            "spikes": ck.choice("gap.spikes", d.get("spikes", "keep"), SPIKE_ACTIONS),
            "spike_threshold": ck.positive("gap.spike_threshold", d.get("spike_threshold", SPIKE_THRESHOLD))}


def _cell(surface, options, units):
    """The :class:`bem.rough.PatchCell` of the surface (a synthetic one: itself, its spikes found); a mirrored
    grid counted before it is made (:func:`bem.checks.check_node_count`)."""
    from bem import rough
    from bem.rough.patch import cell_grid

    cell = options.get("cell", "repeat")
    (nx, ny), _, mirrored = cell_grid(surface, cell=cell, name="gap.cell")
    with ck.scene_errors("gap."):
        if mirrored:
            check_node_count("gap.cell", cell, nx * ny, what="the mirrored surface grid")
        unit = getattr(units, "length", None) if getattr(units, "metres", None) is not None else None
        with quiet_seam():  # the run states the seam of the cell solved, once (validation.run.periodic)
            return rough.patch_cell(surface, unit=unit or "length units", **options)


def _periodic(d, gap, layer_spec, layer, load):
    for key in _LATTICE_KEYS:
        if key in d:
            raise ck.SceneError(f"bem.{key} = {d[key]!r} is not allowed with bem.periodic = true: the cell is the "
                                "surface's; give bem.cell_nodes (lattice nodes along x).")
    if layer_spec is not None and is_paper_law(layer_spec):
        raise ck.SceneError(f"layer.law = {layer_spec['law']!r} given by the paper's parameters is not allowed with "
                            "bem.periodic = true: give the law's own parameters (e.g. lam).")
    out = solver_options(d, layer_spec)
    name = "bem.cell_nodes" if "cell_nodes" in d else "bem.cell_nodes (default: Lx / max(dx, dy) of the surface)"
    n_cols = ck.integer(name, d.get("cell_nodes", gap.surface.default_n_cols()), 8, 8192)
    with ck.scene_errors():  # bem's memory guard, before the cell is made
        n_rows, _ = cell_shape(gap.surface.size, n_cols)
        check_node_count(name, n_cols, n_rows * n_cols, what="the periodic cell")
    try:
        lattice = gap.surface.to_lattice(n_cols)
    except InputError as exc:
        raise ck.SceneError(f"bem.cell_nodes = {n_cols!r} is not allowed: {exc}") from None
    gap.lattice = lattice
    h = lattice.gap()
    if load.get("approach") is not None and layer is None and not load["approach"] < float(h.mean()):
        raise ck.SceneError(f"load.approach = {load['approach']!r} is not allowed: without a layer it must be below "
                            f"the cell's mean initial gap {float(h.mean()):.6g} (a full contact leaves the mean "
                            "pressure undetermined: give load.mean_pressure).")
    lx, ly = lattice.size
    out.update(periodic=True, cell_nodes=n_cols, step=lattice.step, cell=[lattice.n_cols, lattice.n_rows],
               size=[lx, ly], extent=(lx / 2, ly / 2), extent_auto=False, expected=None, nodes_across=None,
               n_nodes=lattice.n_rows * lattice.n_cols)
    return out


def bem_section(d, gap, layer_spec, layer, E_star, load, stress=None):
    """``[bem]`` of any scene: the periodic cell of a rough gap, else :func:`validation.scene.sizing.bem_options`.

    ``stress`` is the raw ``[stress]`` table (refused with a periodic cell).
    """
    from .sizing import bem_options

    d = {} if d is None else ck.table("bem", d)
    periodic = ck.boolean("bem.periodic", d.get("periodic", False))
    rough = isinstance(gap, RoughGap)
    if rough and not periodic:
        raise ck.SceneError(f"gap.type = {gap.type_name!r} needs bem.periodic = true: a rough surface is solved on "
                            "its periodic cell.")
    if periodic and not rough:
        raise ck.SceneError(f"bem.periodic = true is not allowed with gap.type = {gap.type_name!r}: the periodic "
                            f"cell needs a rough surface (gap.type = {' or '.join(map(repr, ROUGH_TYPES))}).")
    if not periodic:
        if "cell_nodes" in d:
            raise ck.SceneError(f"bem.cell_nodes = {d['cell_nodes']!r} is not allowed without bem.periodic = true: "
                                "give bem.step or bem.nodes_across.")
        if load.get("mean_pressure") is not None:
            raise ck.SceneError(f"load.mean_pressure = {load['mean_pressure']!r} is not allowed without "
                                "bem.periodic = true: give load.force or load.approach.")
        return bem_options({k: v for k, v in d.items() if k != "periodic"}, gap, layer_spec, layer, E_star, load)
    if stress is not None:
        raise ck.SceneError("stress = {...} is not allowed with bem.periodic = true: the subsurface stresses are "
                            "computed for a bounded contact.")
    ck.unknown_keys("bem", d, (*_LATTICE_KEYS, *PERIODIC_KEYS, *_solver_keys()))
    return _periodic(d, gap, layer_spec, layer, load)


def _solver_keys():
    from .sizing import SOLVER_KEYS

    return SOLVER_KEYS
