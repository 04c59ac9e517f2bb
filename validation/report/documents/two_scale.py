"""Section of the two-scale check (``two_scale.json``, :mod:`validation.studies.two_scale`) in the studies report."""

from __future__ import annotations

from ..render import Figure, Section, Table

__all__ = ["two_scale_sections"]


def two_scale_sections(data, work=None):
    """The errors table, the refinement table and, with a figures folder ``work``, the pressure map
    and the windowed profile of the first case, drawn from the file's ``figure``."""
    from validation.studies.two_scale import WIDE, table

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
    if work is not None and data.get("figure"):
        from ..figures.two_scale import plot_two_scale_data

        map_png, profile_png = plot_two_scale_data(data["figure"], work)
        items += [Figure(map_png, "The resolved rough sphere's pressure (mean over square pixels) with the nominal "
                                  "contact circles (99 % of the force) of the resolved solution and of the layer "
                                  "model."),
                  Figure(profile_png, "Along y = 0: the resolved pressure averaged over windows of lambda_L (and "
                                      f"of {WIDE} lambda_L), the layer model's nodal pressure and its window "
                                      "means, and Greenwood-Tripp's nodal pressure.")]
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
