"""Measured surfaces as the gap of a scene: ``[gap] type = "measured"`` reads a file of heights.

Keys of the ``[gap]`` table (every length of the file, and ``spacing``, in ``length_unit``)::

    type        = "measured"
    file        = "surface.npy"   # required; relative to the scene file's folder
    format      = "npy" | "grid" | "asc" | "xyz"   # default from the extension
    kind        = "gap" | "topography"             # default "gap"
    length_unit = "um"            # "m", "mm", "um" (or "µm"), "nm", or a factor to the scene's length unit
    spacing     = [dx, dy]        # grid step of .npy and grid files (a number when dx = dy)
    center      = "grid" | "minimum" | "file"      # default "grid"
    method      = "cubic"         # interpolation onto the lattice: linear, cubic, quintic, pchip
    nodata      = -9999.0         # value marking missing points (.asc: its NODATA_value)

The file's formats, ``kind`` and ``center`` are those of :mod:`bem.gaps.measured`, which reads
the file (:meth:`bem.gaps.Measured.from_file`); its errors come back here naming the key
(``gap.file = ...``, ``gap.spacing = ...``). In short: ``npy`` and ``grid`` files hold
``z[i, j]`` at ``x = j dx``, ``y = i dy``; ``.asc`` is an ESRI ASCII grid; ``xyz`` three
columns ``x, y, z``, on a grid or scattered (then interpolated onto a grid of step
``spacing``). ``kind = "topography"``: heights of one surface towards the other, flat, body;
the gap is ``max z - z`` over the candidate region. ``center``: ``"grid"`` (the middle of the
data), ``"minimum"`` (the lowest gap point) or ``"file"`` (the file's coordinates) at
``x = y = 0``. The BEM candidate region ``|x| <= X``, ``|y| <= Y`` (``bem.extent``,
required with ``bem.step`` since there is no estimate of the contact size) must lie inside
the data and hold no missing point; the gap is interpolated (:class:`bem.gaps.Table`) on the
part of the grid that covers it (:meth:`bem.gaps.Measured.region`).
"""

from __future__ import annotations

from pathlib import Path

from bem.gaps import Measured

from ..units import METRES
from . import checks as ck

__all__ = ["measured_gap", "measured_region", "KEYS", "LENGTH_UNITS"]

KEYS = ("type", "file", "format", "kind", "length_unit", "spacing", "center", "method", "nodata")
#: metres per unit of the length units a measured file may name
LENGTH_UNITS = {k: METRES[k] for k in ("m", "mm", "um", "µm", "nm")}
_FILE_KEYS = ("format", "spacing", "nodata", "kind", "center", "method")  # passed on to Measured.from_file


def _fail(key, value, rule):
    raise ck.SceneError(f"gap.{key} = {value!r} is not allowed: {rule}.")


def _factor(d, units):
    """Scene length units per length unit of the file (``gap.length_unit``)."""
    value = d.get("length_unit")
    if value is None:
        return 1.0
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return ck.positive("gap.length_unit", value)
    if not isinstance(value, str) or value not in LENGTH_UNITS:
        _fail("length_unit", value, f"it must be one of {', '.join(map(repr, LENGTH_UNITS))} or a positive "
                                    "factor from the file's numbers to the scene's length unit")
    scene = None if units is None else units.metres
    if scene is None:
        label = None if units is None else units.label
        _fail("length_unit", value, f"the scene's units label {label!r} names no length unit (m, mm, um, "
                                    "nm) to convert to; give the factor as a number instead")
    return LENGTH_UNITS[value] / scene


def measured_gap(d, *, units=None):
    """``(spec, bem.gaps.Measured)`` of a ``[gap] type = "measured"`` table (see the module docstring).

    ``units`` is the scene's :class:`validation.units.Units` (for ``length_unit``). The spec
    holds the resolved ``format``, ``kind``, ``center`` and ``method``.

    Raises
    ------
    validation.scene.SceneError
        Missing or unreadable file, wrong shape, too few points, a grid that is not evenly
        spaced, or bad keys; the message names the key (``gap.file``, ``gap.spacing``, ...).
    """
    ck.unknown_keys("gap", d, KEYS)
    file = ck.string("gap.file", ck.require("gap", d, "file", 'give the measured surface, e.g. file = "z.npy"'))
    if not Path(file).is_file():
        _fail("file", file, "there is no such file (a relative name starts from the scene file's folder)")
    scale = _factor(d, units)
    with ck.scene_errors("gap."):
        surface = Measured.from_file(file, scale=scale, **{k: d[k] for k in _FILE_KEYS if k in d})
    spec = dict(d, format=surface.format, kind=surface.kind, center=surface.center, method=surface.method)
    return spec, surface


def measured_region(gap, extent):
    """The gap over the candidate region ``extent`` (``bem.extent``): the table of
    :meth:`bem.gaps.Measured.region` for a measured gap; other gaps as they are.

    Raises
    ------
    validation.scene.SceneError
        Missing data at a node of the region, too few nodes for ``gap.method``, or negative
        values of ``kind = "gap"``, as ``gap.file = ...``.
    """
    if not isinstance(gap, Measured):
        return gap
    with ck.scene_errors("gap."):
        return gap.region(extent, name="bem.extent")
