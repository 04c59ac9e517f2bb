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
    (lf, L), (pf, P) = res.engineering("length"), res.engineering("pressure")  # the report's units, never scales
    L, P, F = L or "-", P or "-", res.display("force").name
    area = f"{L}^2" if L != "-" else "-"

    def num(value, factor=1.0):
        return fmt(value / factor if is_number(value) else value)

    s, sp, b = res.get("surface", {}), res.get("spots", {}), res.bem
    rows = [("mean pressure", num(d.get("mean_pressure"), pf), P),
            ("force on one cell", num(d.get("force"), res.display("force").factor), F),
            ("real contact fraction A/A0", fmt(d.get("contact_fraction")), "-"),
            ("mean gap (mean-plane separation)", num(d.get("mean_gap"), lf), L),
            ("approach", num(d.get("approach"), lf), L),
            ("peak pressure", num(d.get("p_max"), pf), P),
            ("contact spots", fmt(sp.get("count")), "-"),
            ("largest spot area", num(sp.get("largest_area"), lf * lf), area),
            ("mean spot area", num(sp.get("mean_area"), lf * lf), area),
            ("spots of a single node", fmt(sp.get("single_node")), "-")]
    cell = b.get("cell") or ["-", "-"]
    surface = [("source", str(s.get("source", "-")), "-"),
               ("cell Lx, Ly", ", ".join(num(v, lf) for v in s.get("size") or []), L),
               ("data grid nx, ny", ", ".join(map(str, s.get("grid") or [])), "-"),
               ("lattice nodes n_cols x n_rows", f"{cell[0]} x {cell[1]}", "-"),
               ("lattice step c", num(b.get("step"), lf), L),
               ("rms height Sq", num(s.get("rms_height"), lf), L),
               ("rms slope", fmt(s.get("rms_slope")), "-"),
               ("rms curvature", num(s.get("rms_curvature"), 1.0 / lf), f"1/{L}"),
               ("edge jump (rms, opposite edges)", num(s.get("edge_jump"), lf), L),
               ("grid step (rms, neighbours)", num(s.get("grid_step"), lf), L),
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
