"""The figures: drawing functions (plain data in, one file out) and :data:`FIGURES`, the figures
of a run's report.

Drawing functions, by subject: :mod:`.profiles` (pressure along a line, solvers against a
reference, layer laws), :mod:`.iterations` (iterates and convergence), :mod:`.sweeps`
(families of curves, the transition line), :mod:`.surfaces` (3-D surfaces and contact maps),
:mod:`.fields` (stress fields and depth profiles), :mod:`.coated` (a coated body's interface),
:mod:`.precision` (work-precision);
:mod:`.run` draws them from a run's results. Their conventions: ``path`` names the file to
write, in the format of :func:`validation.report.render.style.figure_format` (a PNG at
:data:`~validation.report.render.style.DPI`, an SVG, or a PDF beside the PNG: the one rule of
the figure formats, :data:`~validation.report.render.style.FORMATS`), written atomically and
returned; ``p0`` [pressure] and ``a`` [length] are the scales pressures and lengths are divided
by (Hertz's peak and radius, or ``1`` and ``1`` with ``labels`` naming the units); ``labels``
overrides the axis labels (mathtext); ``title`` is the axes title; bad input raises
:class:`bem.InputError` before anything is written. Matplotlib is imported inside the functions.

:data:`FIGURES` maps a figure's name to ``(section, function)``: ``function(results, work)``
returns a :class:`validation.report.render.Figure` (or a list of them, or ``None`` when the
results do not support it), drawn into the folder ``work``; the run report places it in the
section ``section`` of :data:`validation.report.documents.sections.SECTIONS`, after that
section's tables. A new figure is one function and one line here.
"""

from . import coated, periodic, run

__all__ = ["FIGURES"]

FIGURES = {
    "layer_law": ("layer_law", run.layer_law),
    "profile": ("profile", run.profiles),
    "pressure_map": ("pressure_map", run.pressure_map),
    "convergence": ("convergence", run.convergence),
    "fem_von_mises": ("fem_field", run.fem_von_mises),
    "stress": ("stress", run.stress_figures),
    "stress_interface": ("stress", coated.interface_tractions),
    "cell_maps": ("rough", periodic.cell_maps),
}
