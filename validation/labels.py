"""How a number prints in a table cell or a message, the same in the studies and the reports.

:func:`fmt` is the one cell formatter: ``-`` for ``None`` (a value a run did not produce),
``yes``/``no`` for booleans, a float with a format spec (a number of significant digits or any
:func:`format` spec), anything else as :class:`str`.
"""

from __future__ import annotations

import math

__all__ = ["fmt"]


def fmt(value, spec=4):
    """A table cell of ``value``.

    Parameters
    ----------
    value : float, int, bool, str or None
        What to print.
    spec : int or str
        For a finite float: an int ``n`` prints ``n`` significant digits (``format(value, ".ng")``),
        a str is the :func:`format` spec itself (``".2e"``, ``".3f"``). Ints, non-finite floats
        and strings print as :class:`str`.

    Returns
    -------
    str
        ``"-"`` for ``None``, ``"yes"``/``"no"`` for booleans, else the formatted value.
    """
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float) and math.isfinite(value):
        return format(value, f".{spec}g" if isinstance(spec, int) else spec)
    return str(value)
