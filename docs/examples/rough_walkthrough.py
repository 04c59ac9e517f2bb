"""A measured surface from its file to a macro contact: the walk-through of docs/rough.md.

The AFM scan ``spot_1-1000nm.ibw`` (tests/data/instrument: SurfaceTopography's test data, MIT)
is read (``contactlab surface``), its layer law made with its spikes removed and kept
(``contactlab layer-law``), and a steel ball pressed on the flat that carries it, through each
law (``contactlab run``). :data:`COMMANDS` are the commands of docs/rough.md ("A walk-through"),
run in ``work``; the figures of the page are copied from their output and drawn from it into
``figures``. Needs the ``rough`` and ``report`` extras. Run from the repository root::

    python docs/examples/rough_walkthrough.py      # writes walkthrough/ and docs/figures/rough/
"""

from __future__ import annotations

import contextlib
import io
import json
import lzma
import os
import shlex
import shutil
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
FILE = "spot_1-1000nm.ibw"
#: the scene of the macro contact, written as ``work/ball.toml``
SCENE = """\
# a steel ball (R = 1 m: a lens or a crowned face) on a steel flat that carries the AFM scan's roughness
[scene]
name = "ball"
units = "SI (m, Pa, N)"

[bodies]
E_star = 115.4e9        # Pa, steel on steel: the E* the law was made with

[gap]
type = "paraboloid"
R = 1.0                 # m

[layer]
law = "tabulated"
file = "law/layer_law.toml"

[load]
force = 1.0             # N

[bem]
nodes_across = 40
"""
#: the commands of the walk-through, run in ``work`` in this order
COMMANDS = [
    f"contactlab surface {FILE} --out surface",
    f"contactlab layer-law {FILE} --E-star 115.4e9 --n-cols 64 --spikes remove --out law",
    f"contactlab layer-law {FILE} --E-star 115.4e9 --n-cols 64 --out law_spikes",
    "contactlab run ball.toml --out ball",
    "contactlab run ball.toml --set layer.file='\"law_spikes/layer_law.toml\"' --out ball_spikes",
]
#: figures copied from the commands' folders: (folder, name) -> name in ``figures``
COPIED = {("surface", "heights.png"): "heights.png", ("surface", "psd.png"): "psd.png",
          ("law", "persson.png"): "persson.png"}


def run(command, work):
    """Run one ``contactlab`` command line in ``work`` (this process); returns what it printed."""
    from validation.cli import main

    out, here = io.StringIO(), os.getcwd()
    os.chdir(work)
    try:
        with contextlib.redirect_stdout(out):
            code = main(["--no-progress", *shlex.split(command)[1:]])
    finally:
        os.chdir(here)
    if code != 0:
        raise RuntimeError(f"{command!r} stopped with exit code {code}")
    print(f"$ {command}\n{out.getvalue()}")
    return out.getvalue()


def _spikes_figure(work, path):
    """The detrended height map with the spikes that find_spikes marks outlined."""
    import matplotlib.pyplot as plt

    from bem import rough
    from bem.rough.patch import quiet_seam

    with quiet_seam():  # contactlab surface has reported the seam
        surface = rough.read_surface(work / FILE, detrend="height")
    spikes = rough.find_spikes(surface.heights)
    z, (lx, ly) = surface.heights * 1e9, surface.size
    fig, ax = plt.subplots(figsize=(6.4, 5.2), dpi=150)
    extent = (0, lx * 1e6, 0, ly * 1e6)
    low, high = np.percentile(z, (0.5, 99.5))
    image = ax.imshow(z.T, origin="lower", extent=extent, vmin=low, vmax=high, cmap="gray")
    ax.contour(spikes.mask.T.astype(float), levels=[0.5], colors="red", linewidths=0.8, extent=extent)
    ax.set(xlabel=r"x [$\mu$m]", ylabel=r"y [$\mu$m]",
           title=f"{spikes.count} points in {spikes.n_spikes_high} spikes above and {spikes.n_spikes_low} below\n"
                 f"the median, beyond {spikes.threshold:g} robust standard deviations (red outlines)")
    fig.colorbar(image, ax=ax, label="height [nm] (0.5-99.5 percentile)")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return spikes


def _laws_figure(work, path):
    """The closure w(p) of the two laws, spikes removed and kept."""
    import matplotlib.pyplot as plt

    from bem import rough

    fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=150)
    laws = {}
    for folder, label, style in (("law", "spikes removed", "-o"), ("law_spikes", "spikes kept", "--s")):
        law = laws[folder] = rough.read_layer_law(work / folder / "layer_law.toml")
        ax.plot(law.mean_pressure / 1e6, law.closure * 1e9, style, ms=3, label=label)
    ax.set(xscale="log", xlabel="mean pressure p [MPa]", ylabel="closure w [nm]",
           title="Layer law of spot_1-1000nm.ibw (E* = 115.4 GPa, 64 nodes across)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return laws


def _ball_figure(work, path):
    """The pressure along y = 0 of the ball through each law, and Hertz's smooth ball."""
    import matplotlib.pyplot as plt

    from bem.reference import hertz_sphere

    results = {k: json.loads((work / k / "result.json").read_text()) for k in ("ball", "ball_spikes")}
    hertz = hertz_sphere(1.0, 115.4e9, force=1.0)
    a = hertz.contact_radius
    r = np.linspace(-1.6 * a, 1.6 * a, 401)
    fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=150)
    ax.plot(r * 1e6, hertz.pressure(r) / 1e6, "k:",
            label=f"smooth (Hertz): a = {a * 1e6:.0f} $\\mu$m")
    for key, label in (("ball", "law, spikes removed"), ("ball_spikes", "law, spikes kept")):
        profile, res = results[key]["profile"], results[key]
        ax.plot(np.array(profile["x"]) * 1e6, np.array(profile["p"]) / 1e6,
                label=f"{label}: a = {res['contact_radius'] * 1e6:.0f} $\\mu$m")
    ax.set(xlabel=r"x [$\mu$m] (y = 0)", ylabel="contact pressure p [MPa]",
           title="Steel ball R = 1 m, P = 1 N on the scanned surface (BEM)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return results, hertz


def main(work="walkthrough", figures=ROOT / "docs" / "figures" / "rough"):
    """Run :data:`COMMANDS` in ``work`` and write the page's figures into ``figures``.

    Returns
    -------
    dict
        ``printed`` (command -> what it printed), ``spikes`` (:class:`bem.rough.Spikes`),
        ``laws`` (folder -> :class:`bem.rough.TopographyLaw`), ``results`` (the two runs'
        result.json), ``hertz`` (the smooth ball), ``figures`` (the files written).
    """
    import matplotlib

    matplotlib.use("Agg")
    work, figures = Path(work), Path(figures)
    work.mkdir(parents=True, exist_ok=True)
    figures.mkdir(parents=True, exist_ok=True)
    with lzma.open(ROOT / "tests" / "data" / "instrument" / f"{FILE}.xz") as src, open(work / FILE, "wb") as dst:
        shutil.copyfileobj(src, dst)
    (work / "ball.toml").write_text(SCENE)
    printed = {command: run(command, work) for command in COMMANDS}
    written = []
    for (folder, name), target in COPIED.items():
        shutil.copyfile(work / folder / name, figures / target)
        written.append(figures / target)
    spikes = _spikes_figure(work, figures / "spikes.png")
    laws = _laws_figure(work, figures / "laws.png")
    results, hertz = _ball_figure(work, figures / "ball.png")
    written += [figures / n for n in ("spikes.png", "laws.png", "ball.png")]
    return {"printed": printed, "spikes": spikes, "laws": laws, "results": results, "hertz": hertz,
            "figures": written}


if __name__ == "__main__":
    main(*sys.argv[1:2])
