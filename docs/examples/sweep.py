"""A sweep: the peak pressure of a steel ball on a flat for several loads, with resumable storage.

:func:`validation.run.sweep.run_sweep` runs one scene for each value of a parameter (here
``load.force``), saves each finished point as it comes (``points/point-*.json``, keyed by
the point's scene; a rerun reuses them, other values extend the folder) and writes
``summary.json`` and ``summary.csv``. The same from the command line::

    contactlab sweep hertz --param load.force --values 50,100,200,400

Hertz's theory says ``p_max ~ P^(1/3)``; the script checks it. Run::

    python docs/examples/sweep.py [OUT_DIR]
"""

from __future__ import annotations

import sys
import tempfile

from validation.run.sweep import run_sweep

#: the scene as a dict (the same keys as a TOML scene file, docs/scenes.md)
SCENE = {
    "scene": {"name": "ball", "title": "Steel ball R = 10 mm on a steel flat", "units": "SI (m, Pa, N)"},
    "bodies": {"E1": 210e9, "nu1": 0.3, "E2": 210e9, "nu2": 0.3},   # Pa, -
    "gap": {"type": "paraboloid", "R": 0.01},                     # m
    "load": {"force": 100.0},                                     # N (swept)
    "bem": {"nodes_across": 24},
}
FORCES = [50.0, 100.0, 200.0, 400.0]  # N


def main(out_dir=None):
    """Run the sweep into ``out_dir`` (default: a temporary directory); return the summary."""
    with tempfile.TemporaryDirectory(prefix="contactlab-sweep-") as tmp:
        summary = run_sweep(SCENE, out_dir or tmp, parameter="load.force", values=FORCES, workers=1)
    rows = summary["points"]
    base = rows[0]
    for row in rows:
        expected = base["p_max"] * (row["value"] / base["value"]) ** (1 / 3)
        print(f"P = {row['value']:6.1f} N: p_max {row['p_max'] / 1e9:.4f} GPa (P^(1/3) scaling from "
              f"{base['value']:g} N: {expected / 1e9:.4f} GPa), status {row['status']}")
    return summary


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
