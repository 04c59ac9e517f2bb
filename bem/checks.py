"""Public argument checks with uniform messages.

Every check raises :class:`InputError` (a ``ValueError``) whose message names
the argument, shows the value and states the rule, e.g.::

    E1 = -2.0e11 is not allowed: it must be > 0.
"""

from __future__ import annotations

import math
from numbers import Real

import numpy as np

from .errors import InputError

__all__ = [
    "InputError",
    "fail",
    "check_positive",
    "check_nonnegative",
    "check_range",
    "check_finite_array",
    "check_choice",
    "check_callable",
    "check_int",
    "check_bool",
    "check_load",
]


def fail(name, value, rule):
    raise InputError(f"{name} = {value!r} is not allowed: it must be {rule}.")


def _real(name, value):
    if isinstance(value, bool) or not isinstance(value, (Real, np.floating, np.integer)):
        fail(name, value, "a real number")
    value = float(value)
    if not math.isfinite(value):
        fail(name, value, "finite")
    return value


def check_positive(name, value):
    """Return ``float(value)``; raise unless it is a finite real ``> 0``."""
    value = _real(name, value)
    if value <= 0:
        fail(name, value, "> 0")
    return value


def check_nonnegative(name, value):
    """Return ``float(value)``; raise unless it is a finite real ``>= 0``."""
    value = _real(name, value)
    if value < 0:
        fail(name, value, ">= 0")
    return value


def check_range(name, value, low, high, *, low_open=False, high_open=False):
    """Return ``float(value)``; raise unless ``low <(=) value <(=) high``."""
    value = _real(name, value)
    below = value <= low if low_open else value < low
    above = value >= high if high_open else value > high
    if below or above:
        lo = "(" if low_open else "["
        hi = ")" if high_open else "]"
        fail(name, value, f"in {lo}{low}, {high}{hi}")
    return value


def check_finite_array(name, value, *, ndim=None, min_size=1):
    """Return ``value`` as a float array; raise on NaN/inf, wrong ``ndim`` or too few entries."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} = {value!r} is not allowed: it must be an array of real numbers.") from None
    if ndim is not None and arr.ndim != ndim:
        raise InputError(f"{name} has shape {arr.shape} which is not allowed: it must be {ndim}-dimensional.")
    if arr.size < min_size:
        raise InputError(f"{name} has {arr.size} entries which is not allowed: it must have at least {min_size}.")
    bad = ~np.isfinite(arr)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        raise InputError(
            f"{name} is not allowed to contain NaN or inf: entry {idx} is {arr[idx]!r}."
        )
    return arr


def check_choice(name, value, choices):
    """Return ``value``; raise unless it is one of ``choices``."""
    if value not in choices:
        fail(name, value, "one of " + ", ".join(repr(c) for c in choices))
    return value


def check_callable(name, value):
    """Return ``value``; raise unless it is callable."""
    if not callable(value):
        fail(name, value, "callable")
    return value


def check_int(name, value, *, minimum=1):
    """Return ``int(value)``; raise unless it is an integer ``>= minimum`` (not a bool)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        fail(name, value, f"an integer >= {minimum}")
    if value < minimum:
        fail(name, value, f">= {minimum}")
    return int(value)


def check_bool(name, value):
    """Return ``value``; raise unless it is ``True`` or ``False``."""
    if not isinstance(value, (bool, np.bool_)):
        fail(name, value, "True or False")
    return bool(value)


def check_load(force, approach):
    """Return ``(force, approach)`` with exactly one given, as a float ``> 0``, the other ``None``.

    Force control gives the total force ``P`` [force], approach control the approach
    ``delta`` [length].
    """
    if (force is None) == (approach is None):
        fail("(force, approach)", (force, approach), "exactly one given (force control or approach control)")
    if force is not None:
        return check_positive("force", force), None
    return None, check_positive("approach", approach)
