"""``contactlab surface FILE``: what a measured surface holds, before a law is made of it.

Prints the statistics in SI units (rms height, slope, curvature), the grid and pixel size, the
missing points filled, the spikes, the seam of the periodic cell and the default lattice of
``layer-law`` and of a scene (:func:`bem.rough.summary`); ``--out DIR`` writes
``surface.json`` (those numbers), ``heights.png`` (the height map, its colour scale from the
0.5th to the 99.5th percentile of the heights) and ``psd.png`` (the radially averaged power
spectrum, SurfaceTopography's).
"""

from __future__ import annotations

from pathlib import Path

from bem.checks import InputError, check_positive

PARSER = {
    "help": "statistics, spikes, seam and lattice of a measured surface file (PSD and height map with --out)",
    "description": (
        "Read a surface file as layer-law and scenes read it (bem.rough.read_surface) and print what it holds:\n"
        "rms height, rms slope and rms curvature in SI units, the grid and pixel size, the missing points\n"
        "(refused unless --fill; above 5 % of the points refused in any case), the spikes (regions reaching\n"
        "beyond --spike-threshold robust standard deviations of the median), the seam of the periodic cell\n"
        "(edge jump against a grid step) and the default lattice cell of layer-law and [bem] cell_nodes.\n"
        "A file's lengths are converted to m by the unit it states; --scale (m per unit) and --size are\n"
        "for a file that states none (npy, plain text matrices).\n"
        "--out DIR writes surface.json, heights.png and psd.png (the figures need the report extra); DIR\n"
        "must be new, empty or a surface folder contactlab wrote (marked by DIR/.contactlab)."),
    "epilog": (
        "examples:\n"
        "  contactlab surface patch.x3p\n"
        "  contactlab surface scan.sur --fill harmonic --out surfaces/scan\n"
        "  contactlab surface heights.npy --size 100,100 --scale 1e-6"),
}

KIND = "surface"
#: the percentiles of the heights at the ends of the height map's colour scale
CLIP = (0.5, 99.5)
NAMES = ("surface.json", "heights.png", "psd.png")
#: the names of read_surface's arguments as this command's options
OPTION_NAMES = {"file": "FILE", "unit": "--scale", "physical_sizes": "--size", "fill": "--fill",
                "format": "--format", "channel": "--channel", "detrend": "--detrend",
                "physical_sizes_rule": "--size LX,LY",
                "unit_rule": "--scale M, metres per length unit of the file (e.g. --scale 1e-6 for micrometres)"}


def add_file_args(p):
    """The options of reading a surface file, shared with ``layer-law``."""
    p.add_argument("--scale", type=float, metavar="M",
                   help="metres per length unit of a file that states none (a file's own unit is always used)")
    p.add_argument("--size", metavar="LX,LY", help="size of a file that does not state it, in its length unit")
    p.add_argument("--fill", choices=("harmonic",),
                   help="fill missing points (at most 5 %% of them) by harmonic interpolation; default: refused")


def pair(option, text, sep):
    """Two numbers of an option, ``LX,LY`` or ``LOW:HIGH``."""
    parts = str(text).split(sep)
    try:
        values = tuple(float(v) for v in parts)
    except ValueError:
        values = ()
    if len(values) != 2:
        raise InputError(f"{option} = {text!r} is not allowed: it must be two numbers separated by '{sep}'.")
    return values


def add_args(p):
    p.add_argument("file", metavar="FILE", help="a surface file SurfaceTopography reads (x3p, sur, opd, mi, ...)")
    add_file_args(p)
    p.add_argument("--format", metavar="NAME", help="the file's format (default: from its extension or contents)")
    p.add_argument("--channel", type=int, metavar="N", help="data channel of a multi-channel file")
    p.add_argument("--detrend", default="height", choices=("height", "center", "slope", "curvature", "none"),
                   help="what is taken off before the statistics (default: the plane of least rms height)")
    p.add_argument("--spike-threshold", dest="spike_threshold", type=float, default=10.0, metavar="K",
                   help="robust standard deviations (1.4826 MAD) beyond which a point is a spike (default 10)")
    p.add_argument("--out", metavar="DIR", help="write surface.json, heights.png and psd.png into DIR")


def size_of(args):
    """``--size LX,LY`` as a pair of physical scales (:func:`bem.checks.check_scale`), or ``None``."""
    from bem.checks import check_scale

    if args.size is None:
        return None
    lx, ly = pair("--size", args.size, ",")
    return check_scale("--size LX", lx), check_scale("--size LY", ly)


def read(args):
    """The surface of ``args`` in metres (:func:`bem.rough.read_surface`), its options named in messages."""
    from bem import rough

    kw = {k: getattr(args, k) for k in ("format", "channel") if getattr(args, k, None) is not None}
    return rough.read_surface(Path(args.file), unit=args.scale, physical_sizes=size_of(args),
                              detrend=None if args.detrend == "none" else args.detrend, fill=args.fill,
                              names=OPTION_NAMES, **kw)


def _lines(info):
    s, sp, lat = info["stats"], info["spikes"], info["lattice"]
    filled = (f"{s['filled']} points filled ({s['fill']}), "
              f"{100 * s['filled'] / info['data_points']:.3g} % of the grid" if s["filled"] else "none")
    seam = "flagged: the repeated cell has a step at its edges" if s["edge_jump_large"] else "within a grid step"
    return [f"file           {s['source']} (unit {s['unit'] or 'none stated, --scale'}, detrend {s['detrend'] or 'none'})",
            f"grid           {s['grid'][0]} x {s['grid'][1]} points, size {s['size'][0]:.4g} x {s['size'][1]:.4g} m, "
            f"pixel {info['pixel'][0]:.4g} x {info['pixel'][1]:.4g} m",
            f"missing        {filled}",
            f"rms height     {s['rms_height']:.4g} m",
            f"rms slope      {s['rms_slope']:.4g}",
            f"rms curvature  {s['rms_curvature']:.4g} 1/m",
            f"spikes         {sp['count']} points in {sp['n_spikes_high']} spikes above and {sp['n_spikes_low']} below "
            f"the median ({sp['n_high']} and {sp['n_low']} points) beyond {sp['threshold']:g} sigma_r = "
            f"{sp['robust_sigma']:.4g} m; the highest point {sp['top_score']:.3g} sigma_r above the median",
            f"seam           edge jump {s['edge_jump']:.4g} m against a grid step of {s['grid_step']:.4g} m: {seam}",
            f"lattice        {lat['n_cols']} x {lat['n_rows']} nodes, step {lat['step']:.4g} m (the default of "
            "layer-law --n-cols and [bem] cell_nodes)"]


def draw(surface, folder):
    """Write ``heights.png`` and ``psd.png`` into ``folder``; returns ``{name: matplotlib Figure}``."""
    import numpy as np

    from ..report.render.style import display_unit, new_figure, save_figure

    z, (lx, ly) = np.asarray(surface.heights), surface.size
    low, high = np.percentile(z, CLIP)  # a few spikes would take the whole colour scale
    lu, lf = display_unit("m", max(lx, ly))
    hu, hf = display_unit("m", max(abs(low), abs(high)) or 1.0)
    name = surface.stats.source if len(surface.stats.source) <= 60 else "..." + surface.stats.source[-57:]
    out = {}
    with new_figure((6.4, 5.0)) as (fig, ax):
        image = ax.imshow(z.T / hf, origin="lower", extent=(0, lx / lf, 0, ly / lf), cmap="viridis",
                          interpolation="nearest", vmin=low / hf, vmax=high / hf)
        fig.colorbar(image, ax=ax, extend="both",
                     label=f"height [{hu}] ({CLIP[0]:g}-{CLIP[1]:g} percentile; beyond: the end colours)")
        ax.set_xlabel(f"x [{lu}]")
        ax.set_ylabel(f"y [{lu}]")
        ax.grid(False)
        ax.set_title(f"Height map of {name}")
        save_figure(fig, folder / "heights.png")
        out["heights.png"] = fig
    q, c = surface.power_spectrum()
    with new_figure() as (fig, ax):
        ax.loglog(q, c, color="#1f77b4", linewidth=1.2)
        ax.set_xlabel("wave number $q$ [1/m]")
        ax.set_ylabel(r"PSD $C(q)$ [m$^4$]")
        ax.grid(True, which="both", alpha=0.3)
        ax.set_title(f"Radially averaged power spectrum of {name}")
        save_figure(fig, folder / "psd.png")
        out["psd.png"] = fig
    return out


def run(args):
    from bem.rough import summary

    from ..extras import require as require_extra
    from ..io import atomic_directory, atomic_write_json, check_output_dir, output_errors, recover_output_dir

    if args.out is not None:
        out = Path(args.out)
        with output_errors(out.absolute(), "--out"):
            recover_output_dir(out)
            check_output_dir(out, KIND, NAMES, what="--out")
        require_extra("report", "the figures of contactlab surface --out")
    if not Path(args.file).is_file():  # before SurfaceTopography is imported
        raise InputError(f"FILE = {args.file!r} is not allowed: there is no such file.")
    require_extra("rough", "contactlab surface (SurfaceTopography reads the file)")
    threshold = check_positive("--spike-threshold", args.spike_threshold)
    surface = read(args)
    info = summary(surface, threshold=threshold)
    print("\n".join(_lines(info)))
    if args.out is not None:
        with atomic_directory(out, KIND, NAMES, what="--out") as tmp:
            atomic_write_json(tmp / "surface.json", info)
            draw(surface, tmp)
        print(f"files          {out}/ ({', '.join(NAMES)})")
    return 0
