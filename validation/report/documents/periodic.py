"""The report section of a periodic run (a rough surface on a flat): ``rough`` in :data:`SECTIONS`.

A table of the cell's results and the surface's statistics (result.json: ``mean_pressure``,
``contact_fraction``, ``mean_gap``, ``spots``, ``surface``); the maps are the figures
:func:`validation.report.figures.periodic.cell_maps` registers for this section.
"""

from __future__ import annotations

from ..render import Section, Table, fmt
from .results import is_number

__all__ = ["rough_section"]


def rough_section(res, work):
    """The cell's contact and the surface (``None`` for a result that is not periodic)."""
    d = res.data
    if not d.get("periodic"):
        return None
    L, P = res.units.of("length"), res.units.of("pressure")
    s, sp, b = res.get("surface", {}), res.get("spots", {}), res.bem
    rows = [("mean pressure", fmt(d.get("mean_pressure")), P),
            ("force on one cell", fmt(d.get("force")), res.units.of("force")),
            ("real contact fraction A/A0", fmt(d.get("contact_fraction")), "-"),
            ("mean gap (mean-plane separation)", fmt(d.get("mean_gap")), L),
            ("approach", fmt(d.get("approach")), L),
            ("peak pressure", fmt(d.get("p_max")), P),
            ("contact spots", fmt(sp.get("count")), "-"),
            ("largest spot area", fmt(sp.get("largest_area")), f"{L}^2"),
            ("mean spot area", fmt(sp.get("mean_area")), f"{L}^2"),
            ("spots of a single node", fmt(sp.get("single_node")), "-")]
    cell = b.get("cell") or ["-", "-"]
    surface = [("source", str(s.get("source", "-")), "-"),
               ("cell Lx, Ly", ", ".join(map(fmt, s.get("size") or [])), L),
               ("data grid nx, ny", ", ".join(map(str, s.get("grid") or [])), "-"),
               ("lattice nodes n_cols x n_rows", f"{cell[0]} x {cell[1]}", "-"),
               ("lattice step c", fmt(b.get("step")), L),
               ("rms height Sq", fmt(s.get("rms_height")), L),
               ("rms slope", fmt(s.get("rms_slope")), "-"),
               ("rms curvature", fmt(s.get("rms_curvature")), f"1/{L}"),
               ("edge jump (rms, opposite edges)", fmt(s.get("edge_jump")), L),
               ("grid step (rms, neighbours)", fmt(s.get("grid_step")), L),
               ("edge jump flagged large", "yes" if s.get("edge_jump_large") else "no", "-"),
               ("stretch along y, Ly / Ly of the data", fmt(s.get("stretch_y")), "-")]
    text = ["The rough surface is pressed by a rigid flat; the cell repeats in the plane (bem.solve_periodic). "
            "A contact spot is a cluster of nodes in contact connected through the lattice's six nearest "
            "neighbours, across the cell's edges."]
    if s.get("edge_jump_large"):
        text.append("WARNING: the surface's cell has a large edge jump; its repetition has a step at the edges.")
    if is_number(s.get("stretch_y")) and abs(s["stretch_y"] - 1) > 0.01:
        text.append("WARNING: the lattice stretches the surface along y by more than 1 %.")
    return Section("Rough surface on a flat: the periodic cell", kind="results", text=tuple(text), items=(
        Table(("quantity", "value", "unit"), tuple(rows), caption="Contact of the periodic cell (result.json)."),
        Table(("quantity", "value", "unit"), tuple(surface),
              caption="The surface (SurfaceTopography's statistics, of the data before the lattice) and its cell.")))
