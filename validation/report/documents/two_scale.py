"""Section of the two-scale check (``two_scale.json``, :mod:`validation.studies.two_scale`) in the studies report."""

from __future__ import annotations

from ..render import Section, Table

__all__ = ["two_scale_sections"]


def two_scale_sections(data, work=None):
    """The errors table and the refinement table of a ``two_scale.json``; no figures (``contactlab
    study two-scale`` draws them beside the file)."""
    from validation.studies.two_scale import table

    heads, rows = table(data)
    s = data.get("settings", {})
    text = [f"A sphere with a seeded self-affine roughness (Hurst {s.get('hurst')}, rms height "
            f"{s.get('rms_height')} m, roll-off lambda_L = {s.get('roll_off')} m, cut-off lambda_L/"
            f"{s.get('cutoff_ratio')}, periodic cell of {s.get('cell_roll_offs')} lambda_L tiled), solved "
            f"fully resolved ({s.get('nodes_per_roll_off')} nodes per lambda_L), against the smooth sphere with "
            "the layer law of the same roughness and Greenwood-Tripp (GT). Errors relative to the resolved "
            "solution: approach (both from the flat touching the highest summit's plane at the apex), nominal "
            "radius (99 % of the force), pressure averaged over windows of lambda_L (L2 over the windows, peak)."]
    items = [Table(heads, tuple(rows), caption="Two-scale errors of the layer model and of Greenwood-Tripp.")]
    ref = data.get("refinement")
    if ref:
        items.append(Table(
            ("nodes per lambda_L", "nodes", "approach [m]", "radius [m]", "time [s]"),
            tuple((lv["nodes_per_roll_off"], lv["nodes"], lv["approach"], lv["radius"], lv["wall_time_s"])
                  for lv in ref["levels"]),
            caption=f"The resolved sphere under refinement (a_H/lambda_L = {ref['ratio']}): observed order "
                    f"{ref['order_approach']:.2f} of the approach, {ref['order_windows']:.2f} of the windowed "
                    "pressure."))
    return [Section("Two-scale check: resolved rough sphere against the layer model", "validation", text,
                    tuple(items))]
