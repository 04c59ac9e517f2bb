"""The report of a result directory written by ``contactlab run``: :data:`SECTIONS`, one function per section.

:data:`SECTIONS` maps the names a scene's ``[report] sections`` may list to
``function(results, work) -> Section or None`` (``None``: the results do not support the
section; ``work``: the folder figure files go to). The figures :data:`validation.report.figures.FIGURES`
registers for a section follow its tables; a section left without text and items is dropped.
A report contains the sections ``result.json["report"]["sections"]`` lists (the scene's
``[report]``), in that order; without it, every section the results support, in the order of
:data:`SECTIONS`. A new section is one function and one line in :data:`SECTIONS`.
"""

from __future__ import annotations

from pathlib import Path

from bem.checks import InputError

from ...provenance import display_path
from ..figures import FIGURES
from ..figures.run import stress_view
from ..render import Progress, Section, Table, draw_and_build, fmt
from ..render.content import fmt_distinct
from ..render.style import method_text
from .periodic import rough_section
from .problem import scene_section
from .sweep import sweep_section

__all__ = ["SECTIONS", "STAGES", "run_sections", "report_results_dir", "results_rows"]

#: the stages of :func:`report_results_dir`, as reported to its ``progress``
STAGES = ("reading", "figures", "writing")

#: rows of the results table: (field of the result / FEM / closed form, label, unit kind); the FEM's radius
#: is its interpolated edge (``edge_radius``), a row of its own
_QUANTITIES = (("p_max", "peak pressure p_max", "pressure"), ("force", "total force P", "force"),
               ("approach", "approach delta", "length"), ("contact_area", "contact area A", "area"),
               ("contact_radius", "contact radius r_c", "length"),
               ("edge_radius", "edge radius of the loaded zone r_edge", "length"))
#: ratio rows: (key, label, field of result.scales)
_RATIOS = (("p_max", "p_max / p_H (Hertz peak)", "p_hertz"), ("contact_radius", "r_c / a_H (Hertz radius)", "a_hertz"),
           ("approach", "delta / delta_H (Hertz approach)", "approach_hertz"))
_BEM_COUNTS = (("n_nodes", "candidate nodes"), ("n_contact", "nodes in contact"),
               ("nodes_across_contact", "nodes across the contact, 2 sqrt(A / pi) / c"))
_TIMES = (("layer_reference", "reference solve of the layer"), ("bem", "BEM"), ("fem", "FEM"),
          ("stress", "subsurface stresses"), ("total", "whole run"))
_FEM_TIMES = (("mesh", "mesh generation"), ("assembly", "assembly"), ("factorize", "factorisation"),
              ("compliance", "contact-node compliance"), ("newton", "contact iterations"),
              ("recover", "stress recovery"), ("total", "total"))
_METRICS = {"l2_rel": "relative L2 error of p", "max_rel": "max |p - p_ref| / max p_ref",
            "peak_rel": "peak pressure (a - b) / b", "contact_radius_rel": "contact radius (a - b) / b",
            "edge_radius_rel": "radius (a - b) / b: BEM sqrt(A/pi) vs FEM interpolated edge",
            "approach_rel": "approach (a - b) / b", "force_rel": "force (a - b) / b",
            "n_points": "nodes compared (union of contacts)"}


def _timed(times, names, prefix="wall time: "):
    """``(label, seconds, "s")`` rows of the parts of ``times`` that ran (``None``: did not run)."""
    return [(prefix + label, fmt(times[key], 3), "s") for key, label in names if times.get(key) is not None]


def _value(part, key):
    """Field ``key`` of a part of the results table; ``None`` where the part has no such quantity (the FEM
    gives no area and no ``sqrt(A / pi)`` radius, only the FEM gives an edge radius)."""
    return getattr(part, key, None)


def results_rows(res):
    """``(columns, rows)`` of the results table: one column per solver that ran, then the unit."""
    r = res.result
    parts = [("BEM", r)] + ([("FEM", r.fem)] if r.fem is not None else []) + (
        [("closed form", r.analytic)] if r.analytic is not None else [])

    def cells(key, scale=1.0):
        """The solvers' values of ``key``, with the digits that tell them apart (:func:`fmt_distinct`)."""
        return fmt_distinct([float(v) / scale if (v := _value(p, key)) is not None else "-" for _, p in parts])

    rows = [(label, *cells(key, res.display(kind).factor), res.display(kind).name) for key, label, kind in _QUANTITIES
            if any(_value(p, key) is not None for _, p in parts)]
    ext = r.contact_extent
    if ext and not res.axisymmetric:
        ref = r.analytic

        def pair(a, b):
            return f"{fmt(res.shown(a, 'length'))}, {fmt(res.shown(b, 'length'))}"

        closed = {"closed form": pair(ref.a, ref.b)} if ref is not None and ref.a is not None else {}
        rows.append(("contact half-widths along x, y", pair(ext["x"], ext["y"]),
                     *(closed.get(name, "-") for name, _ in parts[1:]), res.display("length").name))
    scales = r.scales
    drawn_over = {"p_hertz": res.display("pressure").name == res.hertz_peak,  # a ratio the table shows already
                  "a_hertz": res.display("length").name == "a_H", "approach_hertz": False}
    rows += [(label, *cells(key, getattr(scales, skey)), "-") for key, label, skey in _RATIOS
             if scales is not None and getattr(scales, skey) > 0 and not drawn_over[skey]]
    if r.alpha_b is not None:
        rows.append(("alpha_b = p_max / p_max^lambda", fmt(r.alpha_b), *("-" for _ in parts[1:]), "-"))
    return ("quantity", *(name for name, _ in parts), "unit"), tuple(rows)


def summary(res, work):
    """The key results of every solver that ran, and their ratios to Hertz's."""
    columns, rows = results_rows(res)
    text = [f"Computed: {', '.join(columns[1:-1])}. "
            + ("The run converged." if res.result.converged else "The run did NOT converge.")]
    if res.result.messages:
        text.append("Run messages: " + "; ".join(map(str, res.result.messages)) + ".")
    caption = "Key results, in the report's units (problem statement)."
    if res.axisymmetric:
        caption += " r_c = sqrt(A / pi), A = loaded node count times the node area" + (
            "; r_edge (FEM): edge of the loaded zone, interpolated between the interface nodes."
            if res.fem is not None else ".")
    else:
        caption += " Half-widths: the farthest loaded node along each axis."
    if res.result.scales is not None:
        caption += (" Ratios: to Hertz's peak, radius and approach of the smooth paraboloid at the same load "
                    "(the scale of the figures).")
    return Section("Results", kind="results", text=tuple(text), items=(Table(columns, rows, caption=caption),))


def timings(res, work):
    """How the BEM ran: method, lattice, iterations, residual, wall times."""
    d, b, length = res.result, res.bem, res.display("length")
    rows = [("method", method_text(d.method, res.law), "-"),
            ("status", d.bem.status, "-"),
            ("solver message", str(d.message), "-"),
            ("iterations (finest lattice)", fmt(d.iterations), "-"),
            ("KKT residual", fmt(d.kkt_residual), "-"),
            ("lattice step c", fmt(b.step / length.factor), length.name)]
    if b.extent is not None:
        rows.append(("candidate region |x| <= X, |y| <= Y (X, Y)",
                     ", ".join(fmt(v / length.factor) for v in b.extent), length.name))
    rows += [(label, fmt(getattr(b, key), 3), "-") for key, label in _BEM_COUNTS if getattr(b, key) is not None]
    rows += _timed(d.wall_time_s_by_part, _TIMES)
    return Section("Solver and timings", kind="results", items=(
        Table(("quantity", "value", "unit"), tuple(rows), caption="How the BEM solution was computed."),))


def fem_field(res, work):
    """The FEM reference: mesh, solver and time split (its von Mises field is a figure)."""
    fem, length = res.fem, res.display("length")
    if fem is None:
        return None
    rows = [("status", fem.status, "-"),
            ("stopping reason", str(fem.message), "-"),
            ("contact iterations", fmt(fem.iterations), "-"),
            ("degrees of freedom", fmt(fem.n_dofs), "-"),
            ("elements", fmt(fem.n_elements), "-"),
            ("elements across the contact radius", fmt(fem.n_elements_across_contact, 3), "-"),
            ("element size at the contact", fmt(fem.mesh.h_fine / length.factor), length.name),
            ("mesh half-size / estimated contact radius", fmt(fem.mesh.domain_factor), "-")]
    if fem.penalty["relative_penetration"] is not None:
        rows.append(("penalty: largest penetration / approach", fmt(fem.penalty["relative_penetration"]), "-"))
    rows.append(("far-field (truncation) correction applied", fmt(bool(fem.truncation["applied"])), "-"))
    rows += _timed(fem.timings, _FEM_TIMES)
    return Section("FEM reference", kind="fem", items=(Table(
        ("quantity", "value", "unit"), tuple(rows),
        caption="FEM reference (fem_reference, axisymmetric, quadratic triangles): mesh, solver and time split. "
                "Its pressure, force, approach and radius are in the results table."),))


def stress(res, work):
    """The subsurface stresses of a scene with ``[stress]``: maxima per body, and against the FEM."""
    block = res.result.stress
    if block is None or not block.bodies:
        return None
    a, s, l_name, s_name, _ = stress_view(res)
    rows = [(name, fmt(b.nu), fmt(b.max_von_mises / s), fmt(b.depth_of_max / a),
             f"{fmt(b.location_of_max[0] / a)}, {fmt(b.location_of_max[1] / a)}", fmt(b.max_tresca / s),
             fmt(b.depth_of_max_tresca / a)) for name, b in block.bodies.items()]
    coated_rows = _coated_rows(block, a, s)
    items = [Table(("body", "nu", f"max von Mises / {s_name}", f"its depth / {l_name}", f"at x, y / {l_name}",
                    f"max shear / {s_name}", f"its depth / {l_name}"), tuple(rows),
                   caption="Largest von Mises stress and largest maximum shear (s1 - s3)/2 of each body over all "
                           "candidate nodes and depths, refined in depth by a parabola through the largest sample and "
                           "its neighbours" + ("; of a coated body (nu: its substrate's), in each material apart, its "
                                               "interface from both sides" if coated_rows else "")
                           + f".{_scales_text(res, a, s, l_name, s_name)}")]
    if coated_rows:
        items.append(Table(("body", "quantity", f"value / {s_name}", f"at x, y, z / {l_name}"), tuple(coated_rows),
                           caption="A coated body (bem.coated_stress): the largest von Mises stress in its coating and "
                                   "in its substrate, and the extreme tractions on the coating/substrate interface "
                                   "(depth t; sigma_zz < 0 is compression, shear = sqrt(sigma_xz^2 + sigma_yz^2)); "
                                   "over all candidate nodes and depths, the interface from both sides."))
    fem_rows = [(name, fmt(f.max_von_mises / s), f"{100 * f.max_von_mises_rel:+.2f} %", fmt(f.max_tresca / s),
                 f"{100 * f.max_tresca_rel:+.2f} %", fmt(f.axis_depth_of_max / a),
                 fmt(f.bem_axis_depth_of_max / a), f"{100 * f.axis_depth_of_max_rel:+.2f} %",
                 "yes" if f.on_axis else "no")
                for name, b in block.bodies.items() if (f := b.fem) is not None]
    if fem_rows:
        items.append(Table(
            ("body", f"FEM max von Mises / {s_name}", "BEM - FEM", f"FEM max shear / {s_name}", "BEM - FEM",
             f"FEM depth of the axis max / {l_name}", f"BEM depth of the axis max / {l_name}", "BEM - FEM",
             "largest value on the axis"), tuple(fem_rows),
            caption="BEM against the FEM reference: largest values over the body (FEM: recovered nodal stresses), "
                    "relative differences (BEM - FEM) / FEM. Depth of the largest von Mises stress on the axis from "
                    "a least-squares parabola through the axis values within 4 % of the largest, the BEM evaluated "
                    "at the FEM's axis nodes (the maximum is flat, so the depth of the largest nodal value alone "
                    "scatters with the nodes); it is the depth of the body's largest value where the last column "
                    "says yes."))
    text = ("The contact pressure matters for the strength of the parts through the stresses it causes below the "
            "surface: yielding starts where the von Mises stress (or the maximum shear) is largest, below the "
            "surface for a smooth contact.")
    text += f" Computed in {fmt(float(block.wall_time_s), 3)} s."
    return Section("Subsurface stresses", kind="results", text=(text,), items=tuple(items))


def _coated_rows(block, a, s):
    """Rows of the coated bodies' table of :func:`stress`: quantity, value, location."""
    rows = []
    for name, b in block.bodies.items():
        if (c := b.coated) is None:
            continue
        t = c.thickness
        where = [("largest von Mises stress in the coating", c.max_von_mises_coating, c.location_of_max_coating),
                 ("largest von Mises stress in the substrate", c.max_von_mises_substrate, c.location_of_max_substrate),
                 ("interface: most compressive sigma_zz", c.interface_min_sigma_zz,
                  [*c.location_of_interface_min_sigma_zz, t]),
                 ("interface: largest sigma_zz", c.interface_max_sigma_zz, [*c.location_of_interface_max_sigma_zz, t]),
                 ("interface: largest shear traction", c.interface_max_shear, [*c.location_of_interface_max_shear, t])]
        rows += [(name, what, fmt(None if v is None else v / s),
                  "-" if at is None else ", ".join(fmt(u / a) for u in at)) for what, v, at in where]
    return rows


def _scales_text(res, a, s, l_name, s_name):
    """Caption sentence of the stress table: the scales of a dimensionless report, else nothing (the
    headers name the units)."""
    if not res.display("length").normalised:
        return ""
    (lf, lu), (pf, pu) = res.engineering("length"), res.engineering("pressure")
    return f" Scales: {s_name} = {fmt(s / pf)} {pu}".rstrip() + f", {l_name} = {fmt(a / lf)} {lu}".rstrip() + "."


def _metric_cell(key, value):
    if value is None:
        return "-"
    return str(value) if key == "n_points" or isinstance(value, int) else f"{100.0 * value:.3g} %"


def comparison(res, work):
    """The comparison metrics the run recorded: one column per compared pair (per cent), then the force balance."""
    names = {"bem": "BEM", "fem": "FEM", "analytic": "closed form"}
    metrics = res.result.comparison
    if metrics is None:
        return None
    pairs = metrics.pairs()
    tables = []
    if pairs:
        # a radius row only where a pair compares that radius (the FEM's is its interpolated edge)
        keys = [k for k in _METRICS if k not in ("contact_radius_rel", "edge_radius_rel")
                or any(getattr(v, k) is not None for v in pairs.values())]
        tables.append(Table(
            ("metric", *(" vs ".join(names[p] for p in k.split("_vs_")) for k in pairs)),
            tuple((_METRICS[k], *(_metric_cell(k, getattr(v, k)) for v in pairs.values())) for k in keys),
            caption="Comparison metrics of the run (candidate vs reference at the candidate's nodes; signed "
                    "differences are (candidate - reference) / reference)."))
    balance = metrics.force_balance
    rows = [] if balance is None else [("target force P", fmt(res.shown(balance.target, "force")),
                                        res.display("force").name)]
    rows += [(f"force balance |F - P| / P ({k.upper()})", _metric_cell(k, v), "-")
             for k, v in (("bem", None if balance is None else balance.bem),
                          ("fem", None if balance is None else balance.fem)) if v is not None]
    if rows:
        tables.append(Table(("quantity", "value", "unit"), tuple(rows), caption="Force balance of the solvers."))
    return Section("Comparison metrics", kind="validation", items=tuple(tables)) if tables else None


def _figures_only(title, kind):
    """A section that holds only its figures (dropped when none can be drawn)."""
    return lambda res, work: Section(title, kind=kind)


#: section name -> function(results, work) -> Section or None, in the default order of a report; the
#: names are those a scene may list (:data:`validation.scene.schema.REPORT_SECTIONS`)
SECTIONS = {
    "scene": scene_section,
    "layer_law": _figures_only("Interface layer law", "problem"),
    "summary": summary,
    "timings": timings,
    "profile": _figures_only("Pressure profiles", "results"),
    "pressure_map": _figures_only("Pressure over the contact plane", "results"),
    "convergence": _figures_only("Convergence of the BEM", "iterations"),
    "fem_field": fem_field,
    "stress": stress,
    "comparison": comparison,
    "sweep": sweep_section,
    "rough": rough_section,
}


def build_section(name, res, work):
    """Section ``name`` of :data:`SECTIONS` with the figures registered for it, or None."""
    if name not in SECTIONS:
        raise InputError(f"section = {name!r} is not allowed: it must be one of {list(SECTIONS)}.")
    sec = SECTIONS[name](res, work)
    if sec is None:
        return None
    drawn = []
    for where, draw in FIGURES.values():
        out = draw(res, work) if where == name else None
        drawn += out if isinstance(out, list) else [out] if out is not None else []
    sec = Section(sec.title, kind=sec.kind, text=sec.text, items=sec.items + tuple(drawn))
    return sec if sec.items or sec.text else None


def run_sections(res, work, names=None):
    """The sections of a run's report; figures go to ``work``.

    ``names``: the sections to build, in order; default: those of ``result.json["report"]``
    (the scene's ``[report] sections``) when present, else every name of :data:`SECTIONS`.
    """
    if names is None:
        names = tuple(SECTIONS) if res.result.report is None else res.result.report["sections"]
    return [sec for name in names if (sec := build_section(name, res, Path(work))) is not None]


def report_results_dir(directory, out_dir=None, *, title=None, units="auto", fmt="png", progress=None):
    """Report of a result directory (:func:`run_sections`); default ``out_dir``: ``directory/report``.

    Parameters
    ----------
    directory : path-like
        Written by ``contactlab run`` (``result.json``, ``scene.toml``, fields).
    out_dir : path-like, optional
        Report directory (``report.html``, ``report.md``, ``figures/``).
    title : str, optional
        Default: the scene's title.
    units : {"auto", "scene", "dimensionless"}
        One unit per quantity in every table, caption and figure: readable units (mm, MPa, N for
        SI scenes), the scene's own, or lengths and pressures divided by the contact's scales
        (:meth:`validation.report.documents.results.RunResults.display`).
    fmt : {"png", "svg", "pdf"}
        Figure files (:func:`validation.report.render.style.figure_format`).
    progress : callable, optional
        ``progress(stage, done, total)`` (:class:`validation.progress.Progress`).

    Returns
    -------
    validation.report.render.BuiltReport
    """
    from .results import load_results

    notify = Progress(STAGES, progress)
    notify("reading")
    res = load_results(directory, units=units)
    source = res.result.source
    subtitle = (f"Scene '{res.name}'" + (f" ({source})" if source else "")
                + f"; results read from {display_path(directory)}")
    return draw_and_build(lambda work: run_sections(res, work), Path(directory) / "report" if out_dir is None
                          else out_dir, title=title or res.title, subtitle=subtitle, fmt=fmt, notify=notify)
