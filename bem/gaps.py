"""Initial gap shapes ``h(x, y) >= 0`` between the two bodies.

The gap is the initial separation ``h = z1 + z2`` of the two surfaces when
they first touch (paper section 4, docs/method.md section 1); lengths are in the
user's units. For the symmetric shapes ``h = 0`` at the origin, the first
touching point, which lies on the line of the force.

Every shape is a small object with

- ``shape(x, y)``: vectorised evaluation over broadcastable arrays; the inputs
  are never modified; returns a new float array of the broadcast shape;
- ``to_dict()``: a plain ``dict`` (JSON/TOML friendly) with a ``"type"`` key,
  rebuilt (and validated) by :func:`gap_from_dict`;
- ``is_axisymmetric`` and, for axisymmetric shapes, the radial profile
  ``h_r(r)``;
- ``domain``: ``((xmin, xmax), (ymin, ymax))``, the region where the shape is
  defined (``inf`` where unbounded). A candidate region must stay inside it.
"""

from __future__ import annotations

import importlib
import inspect
import math
from collections.abc import Mapping

import numpy as np

from bem.checks import InputError, fail, check_callable, check_choice, check_positive

__all__ = ["Gap", "Paraboloid", "EllipticParaboloid", "CrownedRoller", "FlatPunch", "Callable",
           "Table", "gap_from_dict", "lundberg_coefficient"]

_UNBOUNDED = ((-math.inf, math.inf), (-math.inf, math.inf))


def _points(x, y):
    """Broadcast ``x, y`` to float arrays (read-only views; inputs untouched)."""
    return np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))


class Gap:
    """Base of all gap shapes: ``h(x, y) >= 0`` [length]."""

    type_name = ""
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

    def __repr__(self):
        args = ", ".join(f"{k}={v!r}" for k, v in self._params().items() if not isinstance(v, list))
        return f"{type(self).__name__}({args})"


class _Axisymmetric(Gap):
    is_axisymmetric = True

    def _evaluate(self, x, y):
        return self._profile(np.hypot(x, y))

    def h_r(self, r):
        """Radial profile ``h(r)`` [length] at radii ``r >= 0`` [length]."""
        return self._profile(np.asarray(r, dtype=float))


class Paraboloid(_Axisymmetric):
    """Sphere on a flat (or two spheres): ``h = (x**2 + y**2) / (2 R)``.

    Parameters
    ----------
    R : float
        Effective radius [length], ``> 0``; for two spheres
        ``1/R = 1/R1 + 1/R2``.
    """

    type_name = "paraboloid"

    def __init__(self, R):
        self.R = check_positive("R", R)

    def _profile(self, r):
        return r * r / (2.0 * self.R)

    def _params(self):
        return {"R": self.R}


class EllipticParaboloid(Gap):
    """Elliptic paraboloid ``h = x**2 / (2 Rx) + y**2 / (2 Ry)``.

    Parameters
    ----------
    Rx, Ry : float
        Effective radii of relative curvature [length] in the x-z and y-z
        planes, ``> 0``. Axisymmetric (with ``h_r``) only when ``Rx == Ry``.
    """

    type_name = "elliptic_paraboloid"

    def __init__(self, Rx, Ry):
        self.Rx = check_positive("Rx", Rx)
        self.Ry = check_positive("Ry", Ry)

    @property
    def is_axisymmetric(self):
        return self.Rx == self.Ry

    def _evaluate(self, x, y):
        return x * x / (2.0 * self.Rx) + y * y / (2.0 * self.Ry)

    def h_r(self, r):
        if not self.is_axisymmetric:
            return super().h_r(r)
        r = np.asarray(r, dtype=float)
        return r * r / (2.0 * self.Rx)

    def _params(self):
        return {"Rx": self.Rx, "Ry": self.Ry}


def lundberg_coefficient(force, length, E_star):
    """Lundberg's logarithmic-crown coefficient ``A = P / (pi l E*)`` [length].

    A line load of intensity ``q = P / l`` on ``|x| < l/2`` lowers the surface
    on the axis by ``(q / (pi E*)) ln(1 - (2x/l)**2)`` relative to the centre
    (far-field of the Boussinesq kernel, paper eq. 3); the crown
    ``-A ln(1 - (2x/l)**2)`` compensates it, so the design load ``P`` is
    carried without edge peaks (G. Lundberg, Forsch. Ing.-Wes. 10 (1939)
    201-211; with ``E' = 2 E*`` this is the usual ``2P / (pi l E')``).

    Parameters
    ----------
    force : float
        Design load ``P`` [force], ``> 0``.
    length : float
        Effective roller length ``l`` [length], ``> 0``.
    E_star : float
        Johnson's effective modulus [pressure], ``> 0``.
    """
    force = check_positive("design_force", force)
    length = check_positive("length", length)
    E_star = check_positive("E_star", E_star)
    return force / (math.pi * length * E_star)


class CrownedRoller(Gap):
    """Roller with its axis along x: ``h = y**2 / (2 R) + h_x(x)``.

    Axial crown ``h_x``:

    - ``"log"`` (Lundberg): ``h_x = -A ln(1 - (2x/l)**2)``, with ``A`` given
      directly or from a design load, ``A = design_force / (pi l E_star)``
      (:func:`lundberg_coefficient`);
    - ``"circular"``: ``h_x = x**2 / (2 crown_radius)``;
    - ``"none"``: a straight roller, ``h_x = 0``.

    The roller ends at ``|x| = l/2``. There, and beyond, the gap is the finite
    value ``end_gap = 1e3 * l`` (the gap is also capped at it inside), so the
    field stays finite; ``domain`` says where the shape is real, and a
    candidate region must lie strictly inside ``|x| < l/2``.

    Parameters
    ----------
    length : float
        Roller length ``l`` [length], ``> 0``.
    R : float
        Effective transverse radius [length], ``> 0``.
    crown : {"log", "circular", "none"}
    A : float, keyword-only
        Log-crown coefficient [length], ``> 0`` (``"log"`` only; give either
        ``A`` or ``design_force`` with ``E_star``).
    design_force, E_star : float, keyword-only
        Design load [force] and effective modulus [pressure] for ``A``.
    crown_radius : float, keyword-only
        Crown radius [length], ``> 0`` (``"circular"`` only).
    """

    type_name = "crowned_roller"
    CROWN_KEYS = {"log": ("A", "design_force", "E_star"), "circular": ("crown_radius",), "none": ()}

    def __init__(self, length, R, crown="log", *, A=None, crown_radius=None,
                 design_force=None, E_star=None):
        self.length = check_positive("length", length)
        self.R = check_positive("R", R)
        self.crown = check_choice("crown", crown, tuple(self.CROWN_KEYS))
        given = {"A": A, "crown_radius": crown_radius, "design_force": design_force, "E_star": E_star}
        for name, value in given.items():
            if value is not None and name not in self.CROWN_KEYS[self.crown]:
                fail(name, value, f'left out for crown="{self.crown}"')
        self.A = self.crown_radius = None
        if self.crown == "log":
            if (A is None) == (design_force is None):
                fail("(A, design_force)", (A, design_force), 'exactly one given for crown="log"')
            if A is not None:
                if E_star is not None:
                    fail("E_star", E_star, "left out when A is given (it only sets A from design_force)")
                self.A = check_positive("A", A)
            elif E_star is None:
                fail("E_star", E_star, "given with design_force (A = design_force / (pi length E_star))")
            else:
                self.A = lundberg_coefficient(design_force, self.length, E_star)
        elif self.crown == "circular":
            self.crown_radius = check_positive("crown_radius", crown_radius)
        self.end_gap = 1e3 * self.length
        self.domain = ((-self.length / 2, self.length / 2), (-math.inf, math.inf))

    def _evaluate(self, x, y):
        u2 = (2.0 * x / self.length) ** 2
        inside = u2 < 1.0
        if self.crown == "log":
            hx = -self.A * np.log1p(-np.where(inside, u2, 0.0))
        elif self.crown == "circular":
            hx = x * x / (2.0 * self.crown_radius)
        else:
            hx = np.zeros_like(x)
        h = np.minimum(y * y / (2.0 * self.R) + hx, self.end_gap)
        return np.where(inside, h, self.end_gap)

    def _params(self):
        extra = {"A": self.A, "crown_radius": self.crown_radius}
        return {"length": self.length, "R": self.R, "crown": self.crown,
                **{k: v for k, v in extra.items() if v is not None}}


class FlatPunch(_Axisymmetric):
    """Flat of radius ``a`` with a rounded edge (axisymmetric).

    ``h(r) = 0`` for ``r <= a`` and ``(r - a)**2 / (2 edge_radius)`` for
    ``r > a``: the flat blends tangentially into a torus of meridian radius
    ``edge_radius`` (parabolic approximation).

    Parameters
    ----------
    a : float
        Radius of the flat [length], ``> 0``.
    edge_radius : float
        Edge (blend) radius [length], ``> 0``.
    """

    type_name = "flat_punch"

    def __init__(self, a, edge_radius):
        self.a = check_positive("a", a)
        self.edge_radius = check_positive("edge_radius", edge_radius)

    def _profile(self, r):
        d = np.maximum(r - self.a, 0.0)
        return d * d / (2.0 * self.edge_radius)

    def _params(self):
        return {"a": self.a, "edge_radius": self.edge_radius}


def _function_path(f):
    module, qualname = getattr(f, "__module__", None), getattr(f, "__qualname__", "")
    if not module or "<" in qualname or module == "__main__":
        fail("function", f, "a module-level function (importable as 'module:name') to be written to a dict")
    return f"{module}:{qualname}"


def _import_function(path):
    if not isinstance(path, str) or path.count(":") != 1:
        fail("function", path, "a string 'module:name'")
    module, qualname = path.split(":")
    try:
        obj = importlib.import_module(module)
        for part in qualname.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError) as exc:
        fail("function", path, f"importable ({exc})")
    return obj


class Callable(Gap):
    """Any user gap ``h = f(x, y)``, checked on every call.

    ``function`` receives copies of the broadcast coordinate arrays and must
    return one finite value ``>= 0`` per point (same shape). It is tried at
    construction on a 5 x 5 grid over ``[-scale, scale]**2``; ``to_dict``
    needs it importable, as ``"module:name"``.

    Parameters
    ----------
    function : callable or str
        Vectorised ``f(x, y)`` [length], or ``"module:name"`` of one.
    scale : float, keyword-only
        Half-width [length] of the validation sample, ``> 0``.
    """

    type_name = "callable"

    def __init__(self, function, *, scale=1.0):
        if isinstance(function, str):
            function = _import_function(function)
        self.function = check_callable("function", function)
        self.scale = check_positive("scale", scale)
        s = np.linspace(-self.scale, self.scale, 5)
        self(*np.meshgrid(s, s, indexing="ij"))

    def _evaluate(self, x, y):
        try:
            h = np.asarray(self.function(x.copy(), y.copy()), dtype=float)
        except (TypeError, ValueError) as exc:
            raise InputError(f"function = {self.function!r} failed on an array of points: {exc}") from exc
        if h.shape != x.shape:
            raise InputError(
                f"function returned shape {h.shape} for points of shape {x.shape}, which is not allowed: "
                "it must return one value per point (vectorised)."
            )
        bad = ~(np.isfinite(h) & (h >= 0.0))
        if bad.any():
            i = np.unravel_index(np.argmax(bad), bad.shape)
            raise InputError(
                f"f(x, y) = {float(h[i])!r} at (x, y) = ({float(x[i])!r}, {float(y[i])!r}) is not allowed: "
                "a gap must be finite and >= 0."
            )
        return h

    def _params(self):
        return {"function": _function_path(self.function), "scale": self.scale}

    def __repr__(self):
        return f"Callable({self.function!r}, scale={self.scale!r})"


from .gap_table import Table  # noqa: E402  (Table subclasses Gap)

_TYPES = {cls.type_name: cls for cls in (Paraboloid, EllipticParaboloid, CrownedRoller, FlatPunch, Callable, Table)}


def gap_from_dict(d):
    """Build a gap shape from its ``to_dict()`` form, validating every key.

    Parameters
    ----------
    d : Mapping
        ``{"type": name, **parameters}``; ``name`` is one of ``"paraboloid"``,
        ``"elliptic_paraboloid"``, ``"crowned_roller"``, ``"flat_punch"``,
        ``"callable"`` (with ``"function": "module:name"``), ``"table"``.
        Parameters are the constructor's argument names.

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
    kind = check_choice("gap['type']", params.pop("type", None), tuple(_TYPES))
    cls = _TYPES[kind]
    sig = inspect.signature(cls.__init__)
    allowed = [p for p in sig.parameters if p != "self"]
    for key in params:
        if key not in allowed:
            fail(f"gap key {key!r}", params[key],
                  f"left out: a {kind!r} gap takes only " + ", ".join(map(repr, allowed)))
    for name, p in sig.parameters.items():
        if name != "self" and p.default is inspect.Parameter.empty and name not in params:
            fail(f"gap[{name!r}]", None, f"given for a {kind!r} gap")
    return cls(**params)
