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
    "BYTES_PER_NODE",
    "machine_memory",
    "bytes_per_node",
    "max_nodes",
]

#: Loosest tolerance on the KKT residual (:func:`bem.kkt.kkt_residual`) that :func:`bem.solve`
#: accepts: the residual is relative (gap violations over the largest surface closure, force
#: balance over ``P``), so 1e-2 already admits a 1 % error in the contact conditions.
RTOL_MAX = 1e-2
#: Range of the physical scales (moduli, loads, lengths of a gap shape) in any consistent units:
#: the problem multiplies and divides them (``P R / E*``, ``C = c / (pi E*)``, ...), and beyond
#: this range float64 overflows or underflows before an answer is reached.
SCALE_RANGE = (1e-60, 1e60)
#: Peak memory of a solve per node [bytes], by what holds the nodes (the ``what`` of
#: :func:`check_node_count`): the largest peak of the resident set of ``bem.solve`` per node
#: measured on that domain at 1M-4M nodes (``python benchmarks/memory.py``: spheres on a region
#: with contacts of 4 % and 28 % of it and with a root layer; the rough periodic cell, smooth and
#: with a root layer; the peak per node falls or stays level as the nodes grow) plus the gap
#: (8 bytes a node), times 1.1. A gap callable's own temporaries come on top. A surface grid
#: becomes the gap of a periodic cell of as many nodes. Keys: how the ``what`` of
#: :func:`check_node_count` ends (``"the mirrored periodic cell"`` is a periodic cell).
BYTES_PER_NODE = {"candidate region": 210, "periodic cell": 190, "surface grid": 190}


def machine_memory():
    """Memory this process may use [bytes]: the machine's physical memory, or the control group's
    limit where one is set and smaller (``/sys/fs/cgroup``)."""
    memory = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    for path in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            with open(path) as f:
                text = f.read().strip()
        except OSError:
            continue
        if text.isdigit():
            memory = min(memory, int(text))
    return memory


def bytes_per_node(what="the candidate region"):
    """:data:`BYTES_PER_NODE` of ``what``, the key it ends with (``"the periodic cell"``: 190)."""
    for key, value in BYTES_PER_NODE.items():
        if what.endswith(key):
            return value
    raise ValueError(f"what = {what!r}: it must end with one of {list(BYTES_PER_NODE)}")


def max_nodes(what="the candidate region"):
    """Largest number of nodes that ``what`` may hold on this machine: :func:`machine_memory` over
    :func:`bytes_per_node` of ``what`` (the rule of :func:`check_node_count`)."""
    return machine_memory() // bytes_per_node(what)


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
    """Return ``n_nodes``; raise unless it is at most :func:`max_nodes` of ``what``: the memory guard
    of :func:`bem.solve` and :func:`bem.solve_periodic`, checked before anything is built.

    The rule: ``n_nodes`` times the peak memory a solve needs per node (:data:`BYTES_PER_NODE`)
    must fit in the memory of the machine (:func:`machine_memory`); the refusal states the nodes,
    the memory they would need and the memory the machine has.

    Parameters
    ----------
    name, value
        The argument blamed, as the caller's user wrote it (``"step"``, ``"--n-cols"``,
        ``"bem.cell_nodes"``), and its value.
    n_nodes : int
        The nodes that ``value`` gives, counted without building them.
    what : str
        What holds the nodes, ending with a key of :data:`BYTES_PER_NODE` (``"the candidate
        region"``, ``"the periodic cell"``, ``"the mirrored surface grid"``, ...; also named in
        the message).
    """
    per_node = bytes_per_node(what)
    memory = machine_memory()
    limit = memory // per_node
    if n_nodes > limit:
        raise InputError(f"{name} = {value!r} is not allowed: {what} would hold {float(n_nodes):.3g} nodes "
                         f"(limit {float(limit):.3g} on this machine), which need about "
                         f"{float(n_nodes) * per_node / 1e9:.3g} GB of memory at {per_node} bytes a node; the "
                         f"machine has {memory / 1e9:.3g} GB. Make the lattice coarser or {what} smaller.")
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
