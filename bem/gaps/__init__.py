"""Initial gap shapes ``h(x, y) >= 0`` between the two bodies, and their registry.

The gap is the initial separation ``h = z1 + z2`` of the two surfaces when they first
touch (paper section 4, docs/method.md section 1); lengths are in the user's units. For the
symmetric shapes ``h = 0`` at the origin, the first touching point, which lies on the line
of the force. The protocol every shape follows is in :mod:`bem.gaps.base`.

A new gap type is one module here (a :class:`Gap` subclass with a ``type_name``) and one
line in :data:`GAPS`; user code registers its own with :func:`register`. Scenes
(``[gap] type = ...``), their checks, the sizing of the candidate region and the reports
read everything else from the class: its constructor arguments, its docstring and its
:meth:`Gap.expected_semi_axes`.

Measured surfaces (:mod:`bem.gaps.measured`): :func:`read_heights` reads a height map from a
file, and :class:`Measured` gives the gap over a candidate region as a :class:`Table` (it is
not in :data:`GAPS`: its gap exists only over a region; see its docstring).
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping

from ..checks import check_choice, fail
from .base import AxisymmetricGap, Gap
from .callable import Callable
from .elliptic import EllipticParaboloid
from .heights import MAX_FILE_BYTES, MAX_GRID_VALUES
from .measured import Measured, read_heights
from .paraboloid import Paraboloid
from .punch import FlatPunch
from .roller import CrownedRoller, lundberg_coefficient
from .table import Table

__all__ = ["Gap", "AxisymmetricGap", "Paraboloid", "EllipticParaboloid", "CrownedRoller", "FlatPunch",
           "Callable", "Table", "Measured", "read_heights", "MAX_FILE_BYTES", "MAX_GRID_VALUES", "GAPS", "register",
           "parameters", "gap_from_dict", "lundberg_coefficient"]

#: The registry: ``type_name`` -> class, one line per gap type.
GAPS = {
    "paraboloid": Paraboloid,
    "elliptic_paraboloid": EllipticParaboloid,
    "crowned_roller": CrownedRoller,
    "flat_punch": FlatPunch,
    "callable": Callable,
    "table": Table,
}


def register(cls):
    """Add a gap type to :data:`GAPS` (usable as a class decorator); returns ``cls``.

    ``cls`` must subclass :class:`Gap` and name a new ``type_name``.
    """
    if not (isinstance(cls, type) and issubclass(cls, Gap)):
        fail("cls", cls, "a subclass of bem.gaps.Gap")
    name = cls.type_name
    if not isinstance(name, str) or not name.isidentifier() or name in GAPS:
        fail(f"{cls.__name__}.type_name", name, "a new identifier (not one of " + ", ".join(GAPS) + ")")
    GAPS[name] = cls
    return cls


def parameters(kind):
    """``{name: required}`` of the constructor arguments of the gap type ``kind``."""
    sig = inspect.signature(GAPS[kind].__init__)
    return {name: p.default is inspect.Parameter.empty for name, p in sig.parameters.items() if name != "self"}


def gap_from_dict(d):
    """Build a gap shape from its ``to_dict()`` form, validating every key.

    Parameters
    ----------
    d : Mapping
        ``{"type": name, **parameters}``; ``name`` is a key of :data:`GAPS`
        (``"paraboloid"``, ``"elliptic_paraboloid"``, ``"crowned_roller"``, ``"flat_punch"``,
        ``"callable"`` with ``"function": "module:name"``, ``"table"``, or a registered
        one). Parameters are the constructor's argument names.

    Returns
    -------
    Gap

    Raises
    ------
    bem.InputError
        Unknown type, unknown or missing key (the message names it), or a bad
        parameter value.
    """
    if not isinstance(d, Mapping):
        fail("gap", d, "a mapping with a 'type' key")
    params = dict(d)
    kind = check_choice("gap['type']", params.pop("type", None), tuple(GAPS))
    allowed = parameters(kind)
    for key in params:
        if key not in allowed:
            fail(f"gap key {key!r}", params[key],
                 f"left out: a {kind!r} gap takes only " + ", ".join(map(repr, allowed)))
    for name, required in allowed.items():
        if required and name not in params:
            fail(f"gap[{name!r}]", None, f"given for a {kind!r} gap")
    return GAPS[kind](**params)
