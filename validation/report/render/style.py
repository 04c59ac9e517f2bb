"""Shared look of the report figures and the atomic writing of image files.

Every 2-D figure is a bare :class:`matplotlib.figure.Figure` drawn with the Agg
canvas (no ``pyplot``, so no global state and no GUI backend is ever touched)
and saved by :func:`save_figure`: rendered to a temporary file in the target
directory, then ``os.replace``-d, so a reader never sees a half-written PNG.

Colours are fixed per layer law, per method and per solver so that a law keeps
its colour from one figure of a report to the next.
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import os

from bem.checks import check_choice
from bem.files import atomic_path

__all__ = ["NORMALISED_LABELS", "axis_labels", "DPI", "FORMATS", "LAW_COLORS", "METHOD_COLORS", "SOLVER_COLORS",
           "color_for", "new_figure", "figure_format", "save_figure", "vector_copy", "vector_name", "METHOD_LABELS",
           "method_label", "method_text", "display_unit", "report_unit", "REPORT_UNITS"]

DPI = 300  #: resolution of every PNG (and of the rasterised colour fields of SVG/PDF) [dots per inch]
#: figure file formats: PNG only, SVG only (vector, shown by browsers), or PDF (vector) beside a PNG
FORMATS = ("png", "svg", "pdf")
_FORMAT = contextvars.ContextVar("contactlab_figure_format", default="png")

#: colour of each layer law (``Layer.law``; ``"smooth"`` for no layer)
LAW_COLORS = {
    "smooth": "#222222",
    "linear": "#1f77b4",
    "elastic_rigid": "#d62728",
    "root": "#2ca02c",
    "bilinear": "#9467bd",
    "power": "#ff7f0e",
    "tabulated": "#8c564b",
    "custom": "#7f7f7f",
    "series": "#17becf",
}

#: colour of each BEM method
METHOD_COLORS = {
    "newton": "#1f77b4",
    "augmented_gap": "#ff7f0e",
    "variable_compliance": "#2ca02c",
    "kalker": "#9467bd",
}

METHOD_LABELS = {
    "newton": "Newton (eq. 15)",
    "augmented_gap": "augmented gap (eq. 17-20)",
    "variable_compliance": "variable compliance (eq. 21-23)",
    "kalker": "Kalker QP (eq. 11)",
}

#: colour of each solver in comparisons
SOLVER_COLORS = {"analytic": "#222222", "bem": "#1f77b4", "fem": "#ff7f0e"}

_RC = {
    "font.size": 9.5,
    "axes.titlesize": 10.5,
    "axes.labelsize": 10,
    "legend.fontsize": 8.5,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.6,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "lines.linewidth": 1.7,
    "figure.dpi": DPI,
    "savefig.dpi": DPI,
    "mathtext.fontset": "dejavusans",
    "pdf.fonttype": 42,
    "svg.hashsalt": "contactlab",
}


#: default axis labels of pressure plots: lengths over the Hertz radius, pressures over the Hertz peak
NORMALISED_LABELS = {
    "x": r"$x\,/\,a_H$",
    "y": r"$y\,/\,a_H$",
    "r": r"$r\,/\,a_H$",
    "z": r"$z\,/\,a_H$",
    "p": r"contact pressure $p\,/\,p_0$",
}


def axis_labels(labels=None):
    """Axis labels: :data:`NORMALISED_LABELS` updated by ``labels`` (e.g. ``{"x": "$x$ [mm]"}``)."""
    return {**NORMALISED_LABELS, **(labels or {})}


_METHOD_TEXT = {
    "newton": "direct minimisation of the generalised Kalker functional with the layer's energy",
    "augmented_gap": "the paper's fixed-point iteration on the gap augmented by the layer closure",
    "variable_compliance": "the paper's fixed-point iteration with a pressure-dependent layer compliance",
}


_PREFIXES = {"m": (("", 1.0), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9)),
             "Pa": (("GPa", 1e9), ("MPa", 1e6), ("kPa", 1e3), ("", 1.0)),
             "N": (("MN", 1e6), ("kN", 1e3), ("", 1.0), ("mN", 1e-3))}
#: how a report draws values in an SI base unit: lengths in mm, pressures and stresses in MPa
REPORT_UNITS = {"m": ("mm", 1e-3), "Pa": ("MPa", 1e6)}


def display_unit(unit, magnitude):
    """``(symbol, factor)`` to draw values of size ``magnitude`` [unit] as ``value / factor``.

    SI base units (m, Pa, N) get the prefix that puts ``magnitude`` in [1, 1000)
    (e.g. 1.9e-4 m -> ("µm", 1e-6)); any other unit is kept (factor 1, "" when unknown).
    """
    if unit not in _PREFIXES or not (magnitude > 0 and math.isfinite(magnitude)):
        return (unit or ""), 1.0
    prefix, factor = next((c for c in _PREFIXES[unit] if magnitude >= c[1]), _PREFIXES[unit][-1])
    return (prefix or unit), factor


def report_unit(unit):
    """``(symbol, factor)`` to draw values in ``unit`` as ``value / factor``: m as mm and Pa as MPa
    (:data:`REPORT_UNITS`), any other unit as it is ("" when unknown)."""
    return REPORT_UNITS.get(unit, (unit or "", 1.0))


def method_label(method):
    """Readable name of a BEM method (the key itself when unknown)."""
    return METHOD_LABELS.get(method, str(method))


def method_text(method, law=None, *, short=False):
    """What the BEM solved, in words.

    ``method`` is the method that ran (``result.method``): a quadratic problem (no layer or a linear
    one) runs as Kalker's QP whatever was asked (:func:`bem.options.solver_for`); ``law`` is the
    layer's law (``None`` or ``"none"``: no layer), which the long text names as the reason.
    """
    if method == "kalker":
        if short:
            return "Kalker QP (eq. 11, projected conjugate gradients)"
        why = "no layer" if law in (None, "none") else f"{law} layer"
        return ("Kalker's quadratic programme (eq. 11), solved by projected conjugate gradients "
                f"(the functional is quadratic: {why})")
    if short or method not in _METHOD_TEXT:
        return method_label(method)
    return f"{method_label(method)}: {_METHOD_TEXT[method]}"


def color_for(key, index=0):
    """Colour of a law, method or solver key; the ``index``-th colour of ``tab10`` otherwise."""
    for table in (LAW_COLORS, METHOD_COLORS, SOLVER_COLORS):
        if key in table:
            return table[key]
    palette = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
               "#7f7f7f", "#bcbd22", "#17becf")
    return palette[index % len(palette)]


@contextlib.contextmanager
def new_figure(figsize=(6.4, 4.0), *, title=None, **subplots):
    """A fresh Agg figure with the report style; yields ``(fig, axes)``.

    ``title`` (optional) is set on the first axes; ``subplots`` are passed to
    :meth:`matplotlib.figure.Figure.subplots` (``nrows``, ``ncols``, ``sharex``, ``gridspec_kw``, ...).
    """
    import matplotlib

    with matplotlib.rc_context(_RC):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(figsize=figsize, layout="constrained")
        FigureCanvasAgg(fig)
        axes = fig.subplots(**subplots)
        if title:
            fig.axes[0].set_title(title)
        yield fig, axes


@contextlib.contextmanager
def figure_format(fmt):
    """Within the block, :func:`save_figure` writes ``fmt`` (one of :data:`FORMATS`).

    ``"png"``: a PNG at :data:`DPI`; ``"svg"``: an SVG instead (vector text and lines,
    colour fields rasterised at :data:`DPI`); ``"pdf"``: a PDF (idem) and the PNG beside it,
    which HTML and Markdown show.
    """
    token = _FORMAT.set(check_choice("format", fmt, FORMATS))
    try:
        yield fmt
    finally:
        _FORMAT.reset(token)


def vector_name(name):
    """The name of the PDF that ``"pdf"`` format writes beside the PNG ``name`` (``x.png``: ``x.pdf``)."""
    return os.path.splitext(os.fspath(name))[0] + ".pdf"


def vector_copy(path):
    """The PDF written beside the PNG ``path`` in ``"pdf"`` format, or ``None``."""
    pdf = vector_name(path)
    return pdf if os.path.splitext(os.fspath(path))[1].lower() == ".png" and os.path.isfile(pdf) else None


def _save_vector(fig, path, fmt):
    with atomic_path(path, suffix=f".{fmt}") as tmp:
        fig.savefig(tmp, format=fmt, dpi=DPI, facecolor="white",
                    metadata={"Date": None} if fmt == "svg" else {"CreationDate": None})
    return path


def save_figure(fig, path, *, colors=256):
    """Write ``fig`` atomically in the current :func:`figure_format`; returns the file shown in reports.

    ``path`` names the PNG (``x.png``). In ``"svg"`` format ``x.svg`` is written instead
    and returned; in ``"pdf"`` format ``x.pdf`` is written as well and ``x.png`` returned
    (:func:`vector_copy` finds the PDF). The PNG's RGBA rendering is reduced to an adaptive
    palette of ``colors`` colours (maximum coverage: no channel off by more than a few
    levels in 255 on a colour map), which makes the files about three times smaller;
    ``colors=None`` keeps full RGB.
    """
    import io

    from PIL import Image

    fmt = _FORMAT.get()
    path = os.fspath(path)
    root = os.path.splitext(path)[0]
    if fmt == "svg":
        return _save_vector(fig, root + ".svg", "svg")
    buf = io.BytesIO()  # uncompressed: the one compression is that of the palette image below
    fig.savefig(buf, format="png", dpi=DPI, facecolor="white", pil_kwargs={"compress_level": 0})
    buf.seek(0)
    with Image.open(buf) as img:
        rgb = img.convert("RGB")
    out = rgb if colors is None else rgb.quantize(colors, method=Image.Quantize.MAXCOVERAGE)
    with atomic_path(path) as tmp:
        out.save(tmp, format="PNG", optimize=True, dpi=(DPI, DPI))
    if fmt == "pdf":
        _save_vector(fig, vector_name(path), "pdf")
    return path
