"""The report section of a periodic run (a rough surface on a flat): ``rough`` in :data:`SECTIONS`.

A table of the cell's results and the surface's statistics (the ``periodic`` part of the
:class:`validation.run.record.RunResult`: ``mean_pressure``, ``contact_fraction``, ``mean_gap``,
``spots``, ``surface``); the maps are the figures
:func:`validation.report.figures.periodic.cell_maps` registers for this section.
"""

from __future__ import annotations

from ..render import Section, Table, fmt

__all__ = ["rough_section"]


def rough_section(res, work):
    """The cell's contact and the surface (``None`` for a result that is not periodic)."""
    d, c = res.result, res.result.periodic
    if c is None:
        return None
    (lf, L), (pf, P) = res.engineering("length"), res.engineering("pressure")  # the report's units, never scales
    L, P, F = L or "-", P or "-", res.display("force").name
    area = f"{L}^2" if L != "-" else "-"

    def num(value, factor=1.0):
        return fmt(None if value is None else value / factor)

    s, sp, b = c.surface, c.spots, res.bem
    rows = [("mean pressure", num(c.mean_pressure, pf), P),
            ("force on one cell", num(d.force, res.display("force").factor), F),
            ("real contact fraction A/A0", fmt(c.contact_fraction), "-"),
            ("mean gap (mean-plane separation)", num(c.mean_gap, lf), L),
            ("approach", num(d.approach, lf), L),
            ("peak pressure", num(d.p_max, pf), P),
            ("contact spots", fmt(sp.count), "-"),
            ("largest spot area", num(sp.largest_area, lf * lf), area),
            ("mean spot area", num(sp.mean_area, lf * lf), area),
            ("spots of a single node", fmt(sp.single_node), "-")]
    surface = [("source", str(s["source"]), "-"),
               ("cell Lx, Ly", ", ".join(num(v, lf) for v in s["size"]), L),
               ("data grid nx, ny", ", ".join(map(str, s["grid"])), "-"),
               ("lattice nodes n_cols x n_rows", f"{b.cell[0]} x {b.cell[1]}", "-"),
               ("lattice step c", num(b.step, lf), L),
               ("rms height Sq", num(s["rms_height"], lf), L),
               ("rms slope", fmt(s["rms_slope"]), "-"),
               ("rms curvature", num(s["rms_curvature"], 1.0 / lf), f"1/{L}"),
               ("edge jump (rms, opposite edges)", num(s["edge_jump"], lf), L),
               ("grid step (rms, neighbours)", num(s["grid_step"], lf), L),
               ("edge jump flagged large", "yes" if s["edge_jump_large"] else "no", "-"),
               ("stretch along y, Ly / Ly of the data", fmt(s["stretch_y"]), "-")]
    text = ["The rough surface is pressed by a rigid flat; the cell repeats in the plane (bem.solve_periodic). "
            "A contact spot is a cluster of nodes in contact connected through the lattice's six nearest "
            "neighbours, across the cell's edges."]
    if s["edge_jump_large"]:
        text.append("WARNING: the surface's cell has a large edge jump; its repetition has a step at the edges.")
    if abs(s["stretch_y"] - 1) > 0.01:
        text.append("WARNING: the lattice stretches the surface along y by more than 1 %.")
    return Section("Rough surface on a flat: the periodic cell", kind="results", text=tuple(text), items=(
        Table(("quantity", "value", "unit"), tuple(rows), caption="Contact of the periodic cell (result.json)."),
        Table(("quantity", "value", "unit"), tuple(surface),
              caption="The surface (SurfaceTopography's statistics, of the data before the lattice) and its cell.")))
