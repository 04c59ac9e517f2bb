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

__all__ = ["Units", "parse_units", "DEFAULT_LABEL", "METRES"]

DEFAULT_LABEL = "SI (m, Pa, N)"
#: metres per length unit that a label or a measured file may name
METRES = {"nm": 1e-9, "um": 1e-6, "µm": 1e-6, "mm": 1e-3, "cm": 1e-2, "m": 1.0, "km": 1e3, "in": 0.0254,
          "ft": 0.3048}
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
