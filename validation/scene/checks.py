"""Scene-file checks: every failure names the dotted key, shows the value and states the rule.

Thin wrappers over :mod:`bem.checks` that raise :class:`SceneError` (an
:class:`bem.InputError`, hence a ``ValueError``) with the key written as a dotted
path into the scene file (``layer.lam``, ``bem.nodes_across``).
"""

from __future__ import annotations

import contextlib
import difflib
import math
from collections.abc import Mapping

import bem.checks
from bem.checks import InputError

__all__ = ["SceneError", "scene_errors", "unknown_keys", "closest", "require", "exactly_one", "positive",
           "nonnegative", "scale", "rtol", "in_range", "integer", "boolean", "string", "choice", "table",
           "number_or_pair", "options", "names", "MAX_SWEEP_POINTS", "sweep_size"]

#: the most values one sweep may hold (each is a complete run; split a larger study into several sweeps)
MAX_SWEEP_POINTS = 10_000


class SceneError(InputError):
    """A scene (file, overrides or sweep) is invalid; the message names the dotted key.

    ``errors`` holds every message when a scene had several independent errors
    (:meth:`of`); empty for a single error (the message is ``str(exc)``).
    """

    errors = ()

    @classmethod
    def of(cls, messages):
        """One error reporting every message of ``messages`` (each naming its key)."""
        messages = list(messages)
        if len(messages) == 1:
            return cls(messages[0])
        exc = cls(f"{len(messages)} errors in the scene:\n" + "\n".join(f"  {m}" for m in messages))
        exc.errors = tuple(messages)
        return exc


@contextlib.contextmanager
def scene_errors(prefix=""):
    """Re-raise :class:`InputError` from library checks as :class:`SceneError`.

    ``prefix`` (e.g. ``"gap."``) is prepended to the message unless it already starts with a
    dotted scene key, so ``R = -1.0 is not allowed ...`` from :mod:`bem.gaps` becomes
    ``gap.R = -1.0 is not allowed ...``.
    """
    try:
        yield
    except SceneError:
        raise
    except InputError as exc:
        msg = str(exc)
        if prefix and not msg.startswith(prefix):
            msg = prefix + msg
        raise SceneError(msg) from None


def _wrap(check, name, *args, **kw):
    with scene_errors():
        return check(name, *args, **kw)


def table(path, value):
    """``value`` must be a TOML table (a mapping)."""
    if not isinstance(value, Mapping):
        raise SceneError(f"{path} = {value!r} is not allowed: it must be a table ([{path}] section "
                         "or {key = value, ...}).")
    return value


def closest(name, choices):
    """`` Did you mean 'x'?`` for the choice closest to a misspelled ``name`` (difflib), or ``""``."""
    match = difflib.get_close_matches(str(name), [str(c) for c in choices], n=1, cutoff=0.6)
    return f" Did you mean {match[0]!r}?" if match else ""


def unknown_keys(path, d, allowed):
    """Refuse keys of ``d`` not in ``allowed``: one message per unknown key, each with the closest
    known key and the list of known keys, all raised at once (:meth:`SceneError.of`)."""
    messages = []
    for key, value in d.items():
        if key not in allowed:
            shown = value if not isinstance(value, Mapping) else "{...}"
            hint = closest(key, allowed) or " Check the spelling."
            messages.append(f"{path}.{key} = {shown!r} is not allowed: [{path}] has no key {key!r} "
                            f"(known keys: {', '.join(allowed)}).{hint}")
    if messages:
        raise SceneError.of(messages)


def require(path, d, key, hint):
    """Refuse a missing ``key``; ``hint`` says what to give."""
    if key not in d:
        raise SceneError(f"{path}.{key} is missing: {hint}.")
    return d[key]


def exactly_one(path, d, keys, hint):
    """Exactly one of ``keys`` present in ``d``; returns it."""
    present = [k for k in keys if k in d]
    if len(present) == 1:
        return present[0]
    names = " or ".join(f"{path}.{k}" for k in keys)
    if not present:
        raise SceneError(f"{names} is missing: give exactly one of them ({hint}).")
    shown = ", ".join(f"{path}.{k} = {d[k]!r}" for k in present)
    raise SceneError(f"{shown} is not allowed: give exactly one of them, not several ({hint}).")


def positive(path, value):
    return _wrap(bem.checks.check_positive, path, value)


def nonnegative(path, value):
    return _wrap(bem.checks.check_nonnegative, path, value)


def scale(path, value):
    """A physical scale (modulus, load, length) in :data:`bem.checks.SCALE_RANGE`."""
    return _wrap(bem.checks.check_scale, path, value)


def rtol(path, value):
    """A KKT tolerance of the BEM (:func:`bem.checks.check_rtol`)."""
    return _wrap(bem.checks.check_rtol, path, value)


def in_range(path, value, low, high, **kw):
    return _wrap(bem.checks.check_range, path, value, low, high, **kw)


def integer(path, value, minimum, maximum=math.inf):
    """An integer (not a bool, not a float) in ``[minimum, maximum]``."""
    if isinstance(value, bool) or not isinstance(value, int) or not minimum <= value <= maximum:
        rule = f"an integer >= {minimum}" + (f" and <= {maximum}" if maximum < math.inf else "")
        raise SceneError(f"{path} = {value!r} is not allowed: it must be {rule}.")
    return value


def boolean(path, value):
    if not isinstance(value, bool):
        raise SceneError(f"{path} = {value!r} is not allowed: it must be true or false.")
    return value


def string(path, value):
    if not isinstance(value, str):
        raise SceneError(f"{path} = {value!r} is not allowed: it must be a string (in quotes).")
    return value


def choice(path, value, choices):
    string(path, value)
    return _wrap(bem.checks.check_choice, path, value, tuple(choices))


def options(path, d, rules):
    """The keys of ``rules`` that ``d`` holds, in the order of ``rules``, each checked by its
    rule ``check(dotted key, value)``."""
    return {key: check(f"{path}.{key}", d[key]) for key, check in rules.items() if key in d}


def names(path, value, choices, rule):
    """A non-empty list of names, each one of ``choices``; ``rule`` says what the list holds."""
    if not isinstance(value, list) or not value:
        raise SceneError(f"{path} = {value!r} is not allowed: it must be a non-empty list of {rule}.")
    for i, name in enumerate(value):
        choice(f"{path}[{i}]", name, choices)
    return list(value)


def number_or_pair(path, value, check):
    """A number, or a pair ``[x, y]`` of numbers, each passed through ``check(path, value)``."""
    if isinstance(value, (list, tuple)):
        if len(value) != 2:
            raise SceneError(f"{path} = {value!r} is not allowed: it must be a number or a pair [x, y].")
        return (check(f"{path}[0]", value[0]), check(f"{path}[1]", value[1]))
    x = check(path, value)
    return (x, x)


def sweep_size(name, value, n):
    """Refuse a sweep of ``n`` points beyond :data:`MAX_SWEEP_POINTS`; ``value`` is shown (shortened)."""
    if n > MAX_SWEEP_POINTS:
        shown = repr(value)
        shown = shown if len(shown) <= 60 else shown[:57] + "..."
        raise SceneError(f"{name} = {shown} is not allowed: it gives {n} points, more than the "
                         f"{MAX_SWEEP_POINTS} points a sweep may hold (split it into several sweeps).")
