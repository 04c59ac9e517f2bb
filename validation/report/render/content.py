"""The content of a report: sections holding paragraphs, figures and tables.

A report is a list of :class:`Section`; :func:`validation.report.render.build_report` renders
it to HTML and Markdown. Sections are plain data, so a document builds exactly the sections
its results support (no FEM section without an FEM result).
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field

from bem.checks import InputError
from validation.labels import fmt

__all__ = ["Figure", "Table", "Section", "KINDS", "status_class", "fmt", "fmt_distinct", "problem_section",
           "table_from_rows"]

#: kinds of section; ``"fem"`` marks anything that needs an FEM result
KINDS = ("problem", "results", "iterations", "sweeps", "validation", "fem", "stability", "notes")

#: the CSS class of every status word a table shows: the solvers' ``status``
#: (:data:`bem.STATUSES`, :data:`fem_reference.STATUSES`), the studies' outcomes
#: (:data:`validation.studies.STATUSES`), a sweep point's status and the reports' own
#: "converged" / "not converged" / "failed"; compared whole, never searched in a message
_STATUS = {
    "ok": ("converged",),
    "warn": ("maxiter", "stalled"),
    "bad": ("diverged", "nonfinite", "singular", "boundary", "error", "reported failure", "wrong"),
}


def status_class(status):
    """CSS class of a status word (the whole cell, see ``_STATUS``): ``"ok"``, ``"warn"``,
    ``"bad"``, or ``"other"`` for anything else, messages included."""
    text = str(status).strip()
    for cls, words in _STATUS.items():
        if text in words:
            return cls
    return "other"


def fmt_distinct(values, digits=4, most=9):
    """Cells of values compared side by side (one row of solvers): :func:`validation.labels.fmt`
    with the fewest significant digits, from ``digits`` up to ``most``, at which values that
    differ print differently (``1.3713e+09`` and ``1.3708e+09``, not ``1.371e+09`` twice); not
    numbers and ``None`` as :func:`validation.labels.fmt`."""
    numbers = sorted({float(v) for v in values if isinstance(v, (int, float)) and not isinstance(v, bool)
                      and math.isfinite(v)})
    for n in range(digits, most + 1):
        if len({fmt(v, n) for v in numbers}) == len(numbers):
            break
    return [fmt(v, n) if isinstance(v, float) else fmt(v) for v in values]


@dataclass(frozen=True)
class Figure:
    """A figure file and its caption.

    Attributes
    ----------
    path : str
        The PNG or SVG file (copied into the report; a PDF beside a PNG is copied too).
    caption : str
        What was computed and how (method, mesh step, nodes, tolerance).
    alt : str
        Short text alternative; default: the caption's first sentence.
    """

    path: str
    caption: str
    alt: str = ""

    def __post_init__(self):
        if not os.path.isfile(self.path):
            raise InputError(f"Figure path = {self.path!r} is not allowed: it must be an existing PNG file "
                             "(or SVG file).")

    @property
    def alt_text(self):
        """``alt``, or the caption's first sentence (a period followed by a capital)."""
        return self.alt or re.split(r"(?<=[a-z0-9)])\. (?=[A-Z])", self.caption, maxsplit=1)[0].strip().rstrip(".")


@dataclass(frozen=True)
class Table:
    """A table; cells are formatted with :func:`validation.labels.fmt`.

    Attributes
    ----------
    columns : tuple of str
        Column headers (with units, e.g. ``"p_max [MPa]"``).
    rows : tuple of tuple
        Cells, one tuple per row, as many as ``columns``.
    caption : str
        What the table shows.
    status_column : str, optional
        Header of the column whose value (see :func:`status_class`) colours the row.
    """

    columns: tuple
    rows: tuple
    caption: str = ""
    status_column: str | None = None

    def __post_init__(self):
        object.__setattr__(self, "columns", tuple(str(c) for c in self.columns))
        object.__setattr__(self, "rows", tuple(tuple(fmt(v) for v in r) for r in self.rows))
        bad = [r for r in self.rows if len(r) != len(self.columns)]
        if bad:
            raise InputError(f"Table row {bad[0]!r} is not allowed: it must have {len(self.columns)} cells.")
        if self.status_column is not None and self.status_column not in self.columns:
            raise InputError(f"status_column = {self.status_column!r} is not allowed: it must be one of "
                             f"{list(self.columns)}.")

    def status(self, row):
        """Status class of a row (``"other"`` without a status column)."""
        if self.status_column is None:
            return "other"
        return status_class(row[self.columns.index(self.status_column)])


@dataclass(frozen=True)
class Section:
    """One section of a report.

    Attributes
    ----------
    title : str
        Heading.
    kind : str
        One of :data:`KINDS`; ``"fem"`` for content that needs an FEM solution.
    text : tuple of str
        Paragraphs (plain text).
    items : tuple of Figure or Table
        In display order.
    """

    title: str
    kind: str = "results"
    text: tuple = ()
    items: tuple = field(default_factory=tuple)

    def __post_init__(self):
        if self.kind not in KINDS:
            raise InputError(f"Section kind = {self.kind!r} is not allowed: it must be one of {list(KINDS)}.")
        object.__setattr__(self, "text", (self.text,) if isinstance(self.text, str) else tuple(self.text))
        object.__setattr__(self, "items", tuple(self.items))
        for item in self.items:
            if not isinstance(item, (Figure, Table)):
                raise InputError(f"Section item {item!r} is not allowed: it must be a Figure or a Table.")

    @property
    def anchor(self):
        """HTML id of the section."""
        slug = "".join(ch if ch.isalnum() else "-" for ch in self.title.lower())
        return "-".join(part for part in slug.split("-") if part)


def table_from_rows(rows, *, columns=None, caption="", status="status", max_columns=12):
    """A :class:`Table` from row dicts (e.g. a stability study), coloured by ``status``.

    Parameters
    ----------
    rows : sequence of dict
        One dict per row; missing cells show "-", nested values are left out.
    columns : sequence of str, optional
        Keys to show, in order; default: every scalar key in order of appearance (at most
        ``max_columns``).
    caption : str
        Table caption.
    status : str
        Key whose value colours the row (:func:`status_class`), used when present.
    """
    if columns is None:
        keys = (k for row in rows for k, v in row.items() if not isinstance(v, (Mapping, list, tuple)))
        columns = list(dict.fromkeys(keys))[:max_columns]
    columns = tuple(columns)
    return Table(columns, tuple(tuple(row.get(c, "-") for c in columns) for row in rows), caption=caption,
                 status_column=status if status in columns else None)


def _params(obj):
    if obj is None:
        return "none (smooth bodies)"
    d = obj.to_dict() if hasattr(obj, "to_dict") else dict(obj)
    kind = d.get("type", d.get("law", ""))
    rest = ", ".join(f"{k} = {fmt(v)}" for k, v in d.items() if k not in ("type", "law") and not isinstance(v, list))
    return f"{kind}: {rest}" if kind else rest


def problem_section(*, gap, materials, load, units, layers=(), figure=None, text=(), title="Problem statement"):
    """The problem statement of several layer laws on one gap: gap, materials, laws, load, units.

    Parameters
    ----------
    gap : bem.gaps.Gap or dict
        The initial gap ``h(x, y)``.
    materials : dict
        ``{"E_star": ...}`` or ``{"E1", "nu1", "E2", "nu2"}`` (any of them) [pressure].
    load : dict
        ``{"force": P}`` [force] or ``{"approach": delta}`` [length].
    units : dict
        ``{"length": ..., "pressure": ..., "force": ...}``: the unit column of the table.
    layers : sequence of (str, bem.layers.Layer or None)
        The layer law(s) studied.
    figure : Figure, optional
        The ``w(p)`` plot (:func:`validation.report.figures.profiles.plot_layer_laws`).
    text : sequence of str
        Paragraphs before the table.
    """
    rows = [("gap h(x, y)", _params(gap), units.get("length", "-"))]
    rows += [(f"material {k}", fmt(v), "-" if k.startswith("nu") else units.get("pressure", "-"))
             for k, v in materials.items()]
    rows += [(f"load: {k}", fmt(v), units.get("force" if k == "force" else "length", "-")) for k, v in load.items()]
    rows += [(f"layer: {label}", _params(layer), f"w in {units.get('length', 'length units')}, p in "
              f"{units.get('pressure', 'pressure units')}") for label, layer in layers]
    table = Table(("quantity", "value", "unit"), tuple(rows), caption="Input data of the problem.")
    text = tuple(text) + ("Units: " + ", ".join(f"{k} [{v}]" for k, v in units.items()) + ".",)
    return Section(title, kind="problem", text=text, items=(table,) + ((figure,) if figure is not None else ()))
