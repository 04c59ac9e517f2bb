"""Public argument checks with uniform messages.

Every check raises :class:`InputError` (a ``ValueError``) whose message names
the argument, shows the value and states the rule, e.g.::

    E1 = -2.0e11 is not allowed: it must be > 0.
"""

from __future__ import annotations

import math
import os
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
    "check_scale",
    "check_rtol",
    "check_file_name",
    "check_node_count",
    "check_layer",
    "check_gap_values",
    "RTOL_MAX",
    "SCALE_RANGE",
    "MAX_NODES",
    "BYTES_PER_NODE",
]

#: Loosest tolerance on the KKT residual (:func:`bem.kkt.kkt_residual`) that :func:`bem.solve`
#: accepts: the residual is relative (gap violations over the largest surface closure, force
#: balance over ``P``), so 1e-2 already admits a 1 % error in the contact conditions.
RTOL_MAX = 1e-2
#: Range of the physical scales (moduli, loads, lengths of a gap shape) in any consistent units:
#: the problem multiplies and divides them (``P R / E*``, ``C = c / (pi E*)``, ...), and beyond
#: this range float64 overflows or underflows before an answer is reached.
SCALE_RANGE = (1e-60, 1e60)
#: Largest lattice, in nodes (a memory guard): a solve holds about :data:`BYTES_PER_NODE` per
#: node at its peak (``python benchmarks/bem_hertz.py`` reports the peak RSS), so the limit is
#: about 6.4 GB. The one limit of :func:`bem.solve` (the candidate region) and
#: :func:`bem.solve_periodic` (the cell), checked by :func:`check_node_count`.
MAX_NODES = 16_000_000
#: Peak memory of a solve per lattice node [bytes] (:data:`MAX_NODES`).
BYTES_PER_NODE = 400


def fail(name, value, rule):
    """Raise :class:`InputError` with the message ``"{name} = {value!r} is not allowed: it must be {rule}."``."""
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


def check_scale(name, value):
    """Return ``float(value)``; raise unless it is a physical scale in :data:`SCALE_RANGE`."""
    value = check_positive(name, value)
    low, high = SCALE_RANGE
    if not low <= value <= high:
        fail(name, value, f"in [{low:g}, {high:g}] (a physical scale in any consistent units; beyond "
                          "that float64 overflows in the products of the problem)")
    return value


def check_rtol(name, value):
    """Return ``float(value)``; raise unless ``0 < value <= RTOL_MAX``: the tolerance of every solver
    (BEM, periodic cell, FEM) on its relative residual of the contact conditions."""
    value = check_positive(name, value)
    if value > RTOL_MAX:
        fail(name, value, f"in (0, {RTOL_MAX:g}]: it bounds the relative residual of the contact conditions "
                          "(gap violations, force balance over P), and a larger one accepts a wrong answer as "
                          "converged")
    return value


def check_file_name(name, value):
    """Return ``value``; raise unless it is a file name (``str`` or ``os.PathLike``), not empty, without a
    NUL byte."""
    if not isinstance(value, (str, os.PathLike)):
        fail(name, value, "a file name (str or os.PathLike)")
    text = os.fspath(value)
    if not text:
        fail(name, text, "a file name, not empty")
    if ("\x00" if isinstance(text, str) else b"\x00") in text:
        fail(name, text, "a file name without a NUL byte (no file system accepts one)")
    return value


def check_node_count(name, value, n_nodes, *, what="the candidate region"):
    """Return ``n_nodes``; raise unless it is at most :data:`MAX_NODES`: the memory guard of
    :func:`bem.solve` and :func:`bem.solve_periodic`, checked before anything is built.

    Parameters
    ----------
    name, value
        The argument blamed, as the caller's user wrote it (``"step"``, ``"--n-cols"``,
        ``"bem.cell_nodes"``), and its value.
    n_nodes : int
        The nodes that ``value`` gives, counted without building them.
    what : str
        What holds the nodes, for the message (``"the periodic cell"``).
    """
    if n_nodes > MAX_NODES:
        need, limit = (n * BYTES_PER_NODE / 1e9 for n in (float(n_nodes), MAX_NODES))
        raise InputError(f"{name} = {value!r} is not allowed: {what} would hold {float(n_nodes):.3g} nodes "
                         f"(limit {MAX_NODES:.3g}, about {BYTES_PER_NODE / 1e3:g} kB each), which need about "
                         f"{need:.3g} GB of memory ({limit:.2g} GB at the limit); make the lattice coarser or "
                         f"{what} smaller.")
    return n_nodes


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
        return check_scale("force", force), None
    return None, check_scale("approach", approach)


def check_layer(name, value):
    """Return ``value``; raise unless it is ``None`` or a law of :mod:`bem.layers` (a ``Layer``)."""
    if value is None:
        return None
    from .layers.base import Layer

    if not isinstance(value, Layer):
        fail(name, value, "a bem.layers law or None")
    return value


def check_gap_values(h, points, *, region, mask=None):
    """Return the values ``h`` of a gap function as a float array; raise unless they have the
    shape of the points it was evaluated at and are finite (where ``mask`` is true).

    Parameters
    ----------
    h : array_like
        What the gap function returned [length].
    points : dict
        ``{argument name: coordinates}`` of the call, in order (``{"x": x, "y": y}``) [length];
        the message names the call ``gap(x, y)`` and the first point where ``h`` is not finite.
    region : str
        Where the gap must be finite, completing "the gap must be finite ..." (``"over the
        candidate region"``).
    mask : ndarray of bool, optional
        The points that count (default: all).
    """
    coords = [np.asarray(c) for c in points.values()]
    h = np.asarray(h, dtype=float)
    if h.shape != coords[0].shape:
        raise InputError(f"gap returned shape {h.shape} which is not allowed: it must return the shape of "
                         f"{next(iter(points))} ({coords[0].shape}).")
    bad = ~np.isfinite(h) if mask is None else mask & ~np.isfinite(h)
    if bad.any():
        i = tuple(int(k) for k in np.argwhere(bad)[0])
        names = ", ".join(points)
        at = ", ".join(f"{float(c[i]):.6g}" for c in coords)
        raise InputError(f"gap({names}) = {float(h[i])!r} at ({names}) = ({at}) is not allowed: the gap must be finite "
                         f"{region}.")
    return h
