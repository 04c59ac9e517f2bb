"""The units of a scene, read once from its ``[scene] units`` label.

A scene's numbers are in one consistent set of units that its label names, e.g.
``"SI (m, Pa, N)"`` or ``"mm, MPa, N"``. :func:`parse_units` reads the label once, when the
scene is loaded (:class:`validation.scene.load.Scene` keeps the :class:`Units`); the result file
records the symbols (``result.json["unit_symbols"]``), and the reports and the command line
read them from there.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

__all__ = ["Units", "parse_units", "DEFAULT_LABEL", "METRES", "PASCALS", "pressure_in_pa"]

DEFAULT_LABEL = "SI (m, Pa, N)"
#: metres per length unit that a label or a measured file may name
METRES = {"nm": 1e-9, "um": 1e-6, "µm": 1e-6, "mm": 1e-3, "cm": 1e-2, "m": 1.0, "km": 1e3, "in": 0.0254,
          "ft": 0.3048}
#: pascals per pressure unit that a label or a command-line value may name
PASCALS = {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9, "bar": 1e5, "psi": 6894.757293168361,
           "ksi": 6894757.293168361}
_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?(?:nan|inf))\s*([A-Za-z]*)\s*$",
                       re.IGNORECASE)
_KINDS = {  # unit kind -> regular expression of a unit token of that kind
    "pressure": re.compile(r"^(?:[kMG]?Pa|psi|ksi|bar)$"),
    "force": re.compile(r"^(?:[mkM]?N|lbf|kgf)$"),
    "length": re.compile(r"^(?:[nuµcmk]?m|in|ft)$"),
}


@dataclass(frozen=True)
class Units:
    """Units of a scene, parsed from its ``[scene] units`` label.

    Attributes
    ----------
    label : str
        The label as written in the scene (e.g. ``"SI (m, Pa, N)"``).
    length, pressure, force : str or None
        Unit symbols; ``None`` when the label does not name them.
    """

    label: str
    length: str | None = None
    pressure: str | None = None
    force: str | None = None

    @property
    def known(self):
        """Whether all three units were recognised."""
        return None not in (self.length, self.pressure, self.force)

    @property
    def metres(self):
        """Metres per length unit, or ``None`` when the label names no length unit."""
        return METRES.get(self.length)

    def of(self, kind):
        """Unit of a quantity kind: ``length``, ``pressure``, ``force``, ``area``,
        ``compliance`` (length/pressure), ``s`` or ``-``; ``"-"`` when unknown."""
        if kind in ("-", "s"):
            return kind
        if kind == "area":
            return f"{self.length}^2" if self.length else "-"
        if kind == "compliance":
            return f"{self.length}/{self.pressure}" if self.length and self.pressure else "-"
        return getattr(self, kind, None) or "-"

    def as_dict(self):
        """``{"length", "pressure", "force"}`` of the known units (``result.json["unit_symbols"]``)."""
        return {k: v for k, v in (("length", self.length), ("pressure", self.pressure), ("force", self.force)) if v}

    @classmethod
    def from_dict(cls, label, symbols):
        """The :class:`Units` that :meth:`as_dict` wrote (no parsing)."""
        symbols = symbols if isinstance(symbols, dict) else {}
        return cls(str(label or ""), **{k: symbols.get(k) for k in ("length", "pressure", "force")})


def parse_units(label):
    """Units named by a scene's units label.

    ``"SI (m, Pa, N)"`` and ``"SI"`` give m, Pa, N; ``"mm, MPa, N"`` gives mm, MPa, N; the
    tokens may come in any order (each is recognised by its form). A label naming none
    (e.g. ``"normalised: R = E* = P = 1"``) gives unknown units.
    """
    label = str(label or DEFAULT_LABEL)
    inner = re.search(r"\(([^)]*)\)", label)
    tokens = re.split(r"[\s,;/]+", inner.group(1) if inner else label)
    found = {}
    for token in (t.strip() for t in tokens if t.strip()):
        for kind, rx in _KINDS.items():
            if rx.match(token):
                found.setdefault(kind, token)
    if not found and re.match(r"^\s*SI\b", label):
        found = {"length": "m", "pressure": "Pa", "force": "N"}
    return Units(label, **found)


def pressure_in_pa(name, text):
    """A pressure written as a number with an optional unit of :data:`PASCALS` (``"2.5GPa"``,
    ``"300 MPa"``, ``"1e9"``: Pa), in Pa: finite and ``> 0``.

    Raises
    ------
    bem.InputError
        Not a number, an unknown unit, or not finite and ``> 0``; the message names ``name``.
    """
    import math

    from bem.checks import InputError

    match = _QUANTITY.match(str(text))
    if match is None or (match.group(2) and match.group(2) not in PASCALS):
        raise InputError(f"{name} = {text!r} is not allowed: it must be a number with an optional pressure unit ("
                         + ", ".join(PASCALS) + "; none: Pa), e.g. 2.5GPa.")
    value = float(match.group(1)) * PASCALS[match.group(2) or "Pa"]
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"{name} = {text!r} is not allowed: it must be finite and > 0 (a pressure).")
    return value
