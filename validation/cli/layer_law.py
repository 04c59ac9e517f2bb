"""``contactlab layer-law SURFACE --out DIR``: a rough surface's layer law file and its figures
(:mod:`validation.layer_law`)."""

from __future__ import annotations

import sys
from pathlib import Path

from bem.checks import InputError, check_positive, check_rtol
from bem.rough.patch import CELLS, DETREND_CHOICES, SPIKE_ACTIONS

from .common import ProgressBar, option_names
from .surface import OPTION_NAMES, add_file_args, pair, size_of

PARSER = {
    "help": "the layer law w(p) of a rough surface: law file and figures",
    "description": (
        "Solve the periodic contact of a rough surface against a flat on a ladder of mean pressures\n"
        "(bem.rough.layer_from_topography) and write DIR: layer_law.toml, whose [layer] a scene names by\n"
        "  [layer] law = \"tabulated\"\n  file = \"layer_law.toml\"\n"
        "(the file beside the scene), and the figures closure.png (w(p), linear and log axes),\n"
        "contact_fraction.png (A/A0 against p/(E* h'_rms)), stiffness.png (K = dp/dw) and persson.png\n"
        "(A/A0 and the mean gap beside Persson's theory for the cell's spectrum).\n"
        "A measured surface becomes a periodic cell by --detrend, --spikes and --cell (bem.rough.patch_cell);\n"
        "spikes and a seam are reported once, in metres, and the law file records what was done. The ladder\n"
        "is extended downwards until at most --max-interpolated of its closure lies below its first pressure.\n"
        "Units are SI: lengths in m, E* and pressures in Pa. A surface file's lengths are converted to m by\n"
        "the unit it states (--scale and --size for a file that states neither unit nor size; --fill harmonic\n"
        "fills missing points, at most 5 % of them). The ladder's last pressure must exceed the largest local\n"
        "pressure of the problems the law is used in: beyond it the law holds no data (a solve there warns).\n"
        "The law file needs the rough extra, the figures the report extra (or --no-figures).\n"
        "--out DIR must be new, empty or a layer-law folder contactlab wrote (marked by DIR/.contactlab)."),
    "epilog": (
        "examples:\n"
        "  contactlab layer-law patch.x3p --E-star 115e9 --out laws/patch\n"
        "  contactlab layer-law heights.npy --size 100,100 --scale 1e-6 --E-star 115e9 --out laws/npy\n"
        "                       (a file without units: size in its unit, --scale m per unit)\n"
        "  contactlab layer-law --synthetic hurst=0.8,rms_height=0.5e-6,size=1e-4,grid=256,"
        "long_cutoff=25e-6,short_cutoff=6.25e-6,seed=1 \\\n"
        "                       --E-star 115e9 --p-range-rel 1e-3:0.5 --n-pressures 20 --out laws/synthetic\n"
        "  contactlab layer-law patch.x3p --E-star 115e9 --p-range 1e6:3e9 --n-cols 512 --rtol 1e-10 --out laws/fine\n"
        "  contactlab layer-law scan.ibw --E-star 115e9 --spikes remove --cell mirror --out laws/scan\n"
        "Timings: benchmarks/layer_from_topography.py."),
}

#: keys of --synthetic and their types (bem.rough.self_affine; lengths in m)
SYNTHETIC = {"hurst": float, "rms_height": float, "rms_slope": float, "size": float, "grid": int,
             "long_cutoff": float, "short_cutoff": float, "rolloff": float, "seed": int}

#: the library's arguments -> the options that set them, for the messages (:func:`.common.option_names`)
_LADDER_OPTIONS = {"n": "--n-pressures", "pressures": "--p-range", "pressures[0]": "--p-range LOW",
                   "pressures[1]": "--p-range HIGH", "relative": "--p-range-rel", "relative[0]": "--p-range-rel LOW",
                   "relative[1]": "--p-range-rel HIGH"}


def add_args(p):
    p.add_argument("surface", nargs="?", metavar="SURFACE",
                   help="a surface file SurfaceTopography reads (x3p, sur, opd, datx, gwy, nc, npy, text, ...)")
    p.add_argument("--synthetic", metavar="KEY=VALUE,...",
                   help="instead of SURFACE, a seeded self-affine square cell: " + ", ".join(SYNTHETIC)
                        + " (hurst, size [m], grid and rms_height or rms_slope required; lengths in m)")
    p.add_argument("--out", metavar="DIR", required=True,
                   help="the layer-law directory written: layer_law.toml and the figures")
    p.add_argument("--E-star", dest="E_star", type=float, metavar="PA", required=True,
                   help="effective modulus of the pair [Pa], e.g. 115e9 for steel on steel")
    rng = p.add_mutually_exclusive_group()
    rng.add_argument("--p-range", metavar="LOW:HIGH", help="first and last mean pressure of the ladder [Pa]")
    rng.add_argument("--p-range-rel", metavar="LOW:HIGH", default="3e-3:0.3",
                     help="the same in units of E* h'_rms, h'_rms the surface's rms slope (default 3e-3:0.3)")
    p.add_argument("--n-pressures", type=int, default=12, metavar="N",
                   help="mean pressures in the ladder, geometrically spaced (default 12)")
    p.add_argument("--n-cols", type=int, metavar="N",
                   help="lattice nodes across the cell (default: Lx / max(dx, dy), the grid points along x of "
                        "square pixels)")
    p.add_argument("--rtol", type=float, default=1e-8,
                   help="the solver's KKT tolerance, in (0, 1e-2] as for every solve (default 1e-8)")
    add_file_args(p)
    p.add_argument("--no-figures", action="store_true", help="write the law file only (no report extra needed)")
    cell = p.add_argument_group("the periodic cell of a measured surface (bem.rough.patch_cell; recorded in the law "
                                "file)")
    cell.add_argument("--detrend", default="auto", choices=DETREND_CHOICES,
                      help="auto (default): none for a periodic surface, height for a patch; none keeps the heights "
                           "as they are; height: the plane of least rms height; curvature: the second-order "
                           "polynomial (a measured form)")
    cell.add_argument("--cell", default="repeat", choices=CELLS,
                      help="repeat (default): the patch repeated, with a seam at its edges; mirror: the patch and "
                           "its mirror images, a cell of 2 x 2 patches without a seam (four times the nodes)")
    cell.add_argument("--spikes", default="keep", choices=SPIKE_ACTIONS,
                      help="spikes are points beyond --spike-threshold robust standard deviations (1.4826 MAD) of "
                           "the median, with their flanks; they are always reported; remove fills them by harmonic "
                           "interpolation (default keep)")
    cell.add_argument("--spike-threshold", type=float, metavar="K",
                      help="robust standard deviations beyond which a point is a spike (default 10)")
    p.add_argument("--max-interpolated", default="0.01", metavar="SHARE",
                   help="the largest share of the closure w(p_n) left below the first pressure, where the law is a "
                        "straight line through (0, 0): the ladder is extended downwards until it holds "
                        "(default 0.01; none: the ladder as given)")


def _synthetic(text):
    out = {}
    for item in str(text).split(","):
        key, eq, value = (s.strip() for s in item.partition("="))
        if not eq or key not in SYNTHETIC:
            raise InputError(f"--synthetic {item!r} is not allowed: it must be key=value with key one of "
                             + ", ".join(SYNTHETIC) + ".")
        try:
            out[key] = SYNTHETIC[key](value)
        except ValueError:
            raise InputError(f"--synthetic {key} = {value!r} is not allowed: it must be "
                             f"{'an integer' if SYNTHETIC[key] is int else 'a number'}.") from None
    for key in ("hurst", "size", "grid"):
        if key not in out:
            raise InputError(f"--synthetic {key} is missing: give at least hurst, size [m], grid and rms_height "
                             "or rms_slope.")
    return out


def _check_size(args, synthetic):
    """bem's memory guard (:func:`bem.checks.check_node_count`) on ``--synthetic grid`` and its lattice cell
    (``--n-cols``), named as the command line names them, before the surface is made (``synthetic``, the
    parsed ``--synthetic``). A surface file's cell is counted by :func:`validation.layer_law.surface_from_file`
    after the file is read and before the cell (a mirrored one too) is made."""
    from bem.checks import check_int, check_node_count, check_positive
    from bem.rough import MIN_POINTS
    from bem.rough.lattice_heights import cell_shape

    nx = check_int("--synthetic grid", synthetic["grid"], minimum=MIN_POINTS)
    size = (check_positive("--synthetic size", synthetic["size"]),) * 2
    check_node_count("--synthetic grid", nx, nx * nx, what="the surface grid")
    name = "--synthetic grid" if args.n_cols is None else "--n-cols"
    n_cols = check_int(name, nx if args.n_cols is None else args.n_cols, minimum=2)
    n_rows, n_cols = cell_shape(size, n_cols)
    check_node_count(name, n_cols, n_rows * n_cols, what="the periodic cell")


def _summary(folder):
    law, stats = folder.law, folder.law.stats
    p, w = law.mean_pressure, law.closure
    lines = [f"surface    {stats.source}: rms height {stats.rms_height:.4g} m, rms slope {stats.rms_slope:.4g}, "
             f"{law.cell['n_cols']} x {law.cell['n_rows']} lattice nodes",
             f"ladder     {p.size} mean pressures {p[0]:.4g} .. {p[-1]:.4g} Pa (E* = {law.E_star:.4g} Pa), "
             f"{int(law.iterations.sum())} iterations",
             f"closure    w = {w[0]:.4g} .. {w[-1]:.4g} m of the first-touch mean gap {law.first_touch_gap:.4g} m",
             f"contact    A/A0 = {law.contact_fraction[0]:.3g} .. {law.contact_fraction[-1]:.3g}",
             f"range      the law holds data up to p = {p[-1]:.4g} Pa; a solve beyond it warns",
             f"start      {100 * law.ladder_start['interpolated_share']:.3g} % of the closure lies below "
             f"p = {p[0]:.4g} "
             f"Pa (a straight line to 0)" + (f", {law.ladder_start['added']} pressures added below the ladder"
                                             if law.ladder_start.get("added") else ""),
             f"scene      [layer] law = \"tabulated\", file = \"{folder.law_file.name}\" (the file beside the scene)"]
    prep = law.preparation
    if prep:
        spikes = prep["spikes"]
        lines.insert(1, f"cell       detrend {prep['detrend']}, {prep['cell']}"
                     + (", the seam is large (--cell mirror has none)" if prep["edge_jump_large"] else "")
                     + f"; {prep['spike_points']} points in spikes beyond {spikes['threshold']:g} sigma_r"
                     + (" filled" if prep["spikes_removed"] else (" kept" if prep["spike_points"] else "")))
    names = [folder.law_file.name, *folder.figures]
    lines.append(f"files      {folder.path}/ ({', '.join(names)})")
    return "\n".join(lines)


def _share(text):
    if str(text).strip().lower() == "none":
        return None
    try:
        value = float(text)
    except ValueError:
        value = None
    if value is None or not 0 < value < 1:
        raise InputError(f"--max-interpolated = {text!r} is not allowed: it must be a number between 0 and 1 "
                         "(exclusive) or none.")
    return value


def _spike_threshold(value):
    if value is not None and not value > 0:
        raise InputError(f"--spike-threshold = {value!r} is not allowed: it must be > 0.")
    return value


def run(args):
    from bem.rough import LadderNotConverged

    from ..layer_law import ladder, make_layer_law, surface_from_file, synthetic_surface

    check_positive("--E-star", args.E_star)  # the options the library checks again, checked before any work
    check_rtol("--rtol", args.rtol)
    if (args.surface is None) == (args.synthetic is None):
        raise InputError("SURFACE is missing: give a surface file or --synthetic (one of them)." if args.surface is None
                         else f"SURFACE = {args.surface!r} is not allowed together with --synthetic: give one.")
    if args.synthetic is not None:
        for option, value in (("--scale", args.scale), ("--size", args.size), ("--fill", args.fill)):
            if value is not None:
                raise InputError(f"{option} = {value!r} is not allowed with --synthetic: it is for a SURFACE file "
                                 "(a synthetic surface is in m).")
        with option_names({key: f"--synthetic {key}" for key in SYNTHETIC}):
            synthetic = _synthetic(args.synthetic)
            _check_size(args, synthetic)
            for option, value, default in (("--detrend", args.detrend, "auto"), ("--cell", args.cell, "repeat")):
                if value != default:
                    raise InputError(f"{option} = {value!r} is not allowed with --synthetic: a synthetic surface "
                                     "is periodic, its own cell.")
            surface = synthetic_surface(**synthetic, spikes=args.spikes,
                                        spike_threshold=_spike_threshold(args.spike_threshold))
    else:
        surface = surface_from_file(Path(args.surface), scale=args.scale, physical_sizes=size_of(args), fill=args.fill,
                                    names=dict(OPTION_NAMES, file="SURFACE", cell="--cell", n_cols="--n-cols"),
                                    detrend=args.detrend, cell=args.cell, spikes=args.spikes,
                                    spike_threshold=_spike_threshold(args.spike_threshold), n_cols=args.n_cols)
    share = _share(args.max_interpolated)
    with option_names(_LADDER_OPTIONS):
        if args.p_range is not None:
            pressures = ladder(surface, args.E_star, pressures=pair("--p-range", args.p_range, ":"),
                               n=args.n_pressures)
        else:
            pressures = ladder(surface, args.E_star, relative=pair("--p-range-rel", args.p_range_rel, ":"),
                               n=args.n_pressures)
    bar = ProgressBar("layer law", "pressure", args.no_progress or None)
    try:
        with option_names({"n_cols": "--n-cols"}):
            folder = make_layer_law(surface, args.out, E_star=args.E_star, pressures=pressures, n_cols=args.n_cols,
                                    rtol=args.rtol, figures=not args.no_figures, progress=bar, what="--out",
                                    max_interpolated=share)
    except LadderNotConverged as exc:
        print(f"contactlab: error: {exc} (nothing was written)", file=sys.stderr)
        return 1
    finally:
        bar.close()
    print(_summary(folder))
    return 0
