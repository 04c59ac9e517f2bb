"""The protocol every gap shape follows, and the base classes.

A gap is the initial separation ``h = z1 + z2 >= 0`` of the two surfaces when they first
touch [length]. Every shape is a small object with

- ``shape(x, y)``: vectorised evaluation over broadcastable arrays; the inputs are never
  modified; returns a new float array of the broadcast shape;
- ``to_dict()``: a plain ``dict`` (JSON/TOML friendly) with a ``"type"`` key, rebuilt (and
  validated) by :func:`bem.gaps.gap_from_dict`; the keys are the constructor's arguments;
- ``is_axisymmetric`` and, for axisymmetric shapes, the radial profile ``h_r(r)``;
- ``domain``: ``((xmin, xmax), (ymin, ymax))``, the region where the shape is defined
  (``inf`` where unbounded). A candidate region must stay inside it;
- :meth:`Gap.expected_semi_axes`: the expected contact semi-axes before any solve (they size
  the candidate region), or ``None`` when the shape has no estimate.
"""

from __future__ import annotations

import functools
import math

import numpy as np

__all__ = ["Gap", "AxisymmetricGap"]

_UNBOUNDED = ((-math.inf, math.inf), (-math.inf, math.inf))


def _points(x, y):
    """Broadcast ``x, y`` to float arrays (read-only views; inputs untouched)."""
    return np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))


class Gap:
    """Base of all gap shapes: ``h(x, y) >= 0`` [length].

    A subclass sets ``type_name`` (its ``[gap] type`` in a scene), takes its parameters as
    constructor arguments (checked there), and implements ``_evaluate(x, y)`` and
    ``_params()`` (the constructor arguments as a dict).
    """

    type_name = ""
    #: the kind of quantity of each constructor argument ("length", "force", "pressure"); the
    #: reports print its unit from the scene's units (an argument not named here has none)
    units = {}
    is_axisymmetric = False
    domain = _UNBOUNDED

    def __call__(self, x, y):
        """Gap ``h`` [length] at the points ``(x, y)`` [length] (broadcast)."""
        return self._evaluate(*_points(x, y))

    def _evaluate(self, x, y):  # pragma: no cover - abstract
        raise NotImplementedError

    def h_r(self, r):
        """Radial profile ``h(r)``; only for axisymmetric shapes."""
        raise TypeError(f"{type(self).__name__} is not axisymmetric: it has no radial profile h_r(r).")

    def _params(self):  # pragma: no cover - abstract
        raise NotImplementedError

    def to_dict(self):
        """Plain-dict description; ``gap_from_dict(g.to_dict())`` rebuilds ``g``."""
        return {"type": self.type_name, **self._params()}

    @classmethod
    def describe(cls):
        """One line saying what the shape is: the first line of the class docstring, without markup."""
        return (cls.__doc__ or cls.__name__).strip().splitlines()[0].rstrip(".").replace("``", "")

    def expected_semi_axes(self, *, E_star, force=None, approach=None, layer=None):
        """Expected contact semi-axes ``(ax, ay)`` [length] before any solve, or ``None``.

        Only sizes the candidate region (an automatic region grows when the contact reaches
        its border). The base class has no estimate.

        Parameters
        ----------
        E_star : float
            Effective modulus [pressure].
        force, approach : float
            Exactly one: total force [force] or approach [length].
        layer : bem.layers.Layer, optional
            The interface law.
        """
        return None

    def __repr__(self):
        args = ", ".join(f"{k}={v!r}" for k, v in self._params().items() if not isinstance(v, list))
        return f"{type(self).__name__}({args})"


class AxisymmetricGap(Gap):
    """Base of the axisymmetric shapes: implement ``_profile(r)``."""

    is_axisymmetric = True

    def _evaluate(self, x, y):
        return self._profile(np.hypot(x, y))

    def h_r(self, r):
        """Radial profile ``h(r)`` [length] at radii ``r >= 0`` [length]."""
        return self._profile(np.asarray(r, dtype=float))

    @functools.cached_property
    def _sampled_profile(self):
        from ..reference.estimate import RadialProfile

        return RadialProfile(self)

    def expected_semi_axes(self, *, E_star, force=None, approach=None, layer=None):
        """``(a, a)`` with ``a`` from :func:`bem.reference.estimate_contact_radius`.

        The profile is sampled once per shape (one vectorised evaluation) and kept.
        """
        from ..reference.estimate import estimate_contact_radius

        a = estimate_contact_radius(self._sampled_profile, E_star=E_star, force=force, approach=approach,
                                    layer=layer)
        return a, a
