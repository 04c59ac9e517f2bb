"""Every figure in every file format: PNG at 300 dpi of the stated size, SVG that parses, PDF with
its magic bytes and page size; reports embed SVG and carry the PDF beside the PNG; pyvista (the
optional [3d] extra) is imported only by the 3-D views, inside their functions."""

import re
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from validation.report.figures import iterations as fit
from validation.report.figures import precision as fva
from validation.report.figures import profiles as fpr
from validation.report.figures import surfaces as f3d
from validation.report.figures import sweeps as fsw
from validation.report.figures.fields import plot_section_field
from validation.report.render import Figure, Section, build_report
from validation.report.render.style import DPI, FORMATS, figure_format, vector_copy

from .test_report_build import figure_sources
from .test_report_figures import A, HERTZ, P0, cases, check_png, section_field_size  # noqa: F401 - cases: fixture

ROOT = Path(__file__).resolve().parents[2]
HERTZ_X = np.linspace(-1.5 * A, 1.5 * A, 301)


def _fem_section():
    """A small (r, z) triangulation with a smooth field (no FEM solve needed)."""
    r, z = np.meshgrid(np.linspace(0.0, 3.0 * A, 13), np.linspace(-3.0 * A, 3.0 * A, 25))
    r, z = r.ravel(), z.ravel()
    from scipy.spatial import Delaunay

    tri = Delaunay(np.column_stack([r, z])).simplices
    return r, z, tri, P0 * np.exp(-((r / A) ** 2 + (np.abs(z) / A - 0.5) ** 2))


#: name -> (draw(cases, path), size in inches)
FIGURES = {
    "profiles": (lambda c, p: fpr.plot_pressure_profiles([("smooth", c["smooth"]), ("er", c["er"])], p, p0=P0, a=A,
                                                         hertz=(HERTZ_X, HERTZ.pressure(HERTZ_X))), (8.2, 4.0)),
    "layer_laws": (lambda c, p: fpr.plot_layer_laws([("er", c["er_law"])], p, p_max=P0), (6.0, 3.8)),
    "iterations": (lambda c, p: fit.plot_iteration_profiles(c["er_vc"], p, p0=P0, a=A), (6.8, 4.0)),
    "convergence": (lambda c, p: fit.plot_convergence([("vc", c["er_vc"])], p, p0=P0, tol=1e-8), (6.6, 5.2)),
    "surfaces": (lambda c, p: f3d.plot_pressure_surfaces([("smooth", c["smooth"]), ("er", c["er"])], p, p0=P0, a=A,
                                                         title="t"), (3.3 * 2 + 0.9, 2.8 + 0.35)),
    "contact_map": (lambda c, p: f3d.plot_contact_map(c["er"], p, p0=P0, a=A, levels=[("p_cr", c["er_law"].p_cr)]),
                    (5.4, 4.4)),
    "sweep": (lambda c, p: fsw.plot_sweep([(0.0, *fpr.section_of(c["smooth"])), (1.0, *fpr.section_of(c["linear"]))],
                                          p, p0=P0, a=A, name="alpha"), (6.8, 4.0)),
    "transition": (lambda c, p: fsw.plot_transition_line([0.0, 0.5, 1.0], [1.0, 0.7, 0.0], p, a=1.0,
                                                         r_contact=[1.0, 1.1, 1.2]), (6.0, 4.0)),
    "sweep_scalars": (lambda c, p: fsw.plot_sweep_scalars([1.0, 2.0, 3.0], [("p [MPa]", [1.0, 2.0, 2.5]),
                                                                            ("a [mm]", [0.1, 0.2, 0.25])], p,
                                                          name="force [N]"), (6.4, 1.2 + 1.9 * 2)),
    "comparison": (lambda c, p: fpr.plot_profile_comparison([("BEM", *fpr.section_of(c["smooth"]), "bem")], p, p0=P0,
                                                            a=A, reference=("Hertz", HERTZ.pressure)), (6.6, 5.4)),
    "work_precision": (lambda c, p: fva.plot_work_precision(
        [{"solver": "BEM", "method": "qp", "resolution": f"a/c = {m}", "N": 100 * m * m, "error": 0.3 / m ** 2,
          "wall_time_s": 0.01 * m, "wall_times_s": [0.009 * m, 0.01 * m, 0.013 * m]} for m in (5, 10, 20)], p),
        (7.0, 4.6)),
    "section_field": (lambda c, p: plot_section_field(*_fem_section(), p, a=A, scale=P0, label="s",
                                                      contact_radius=A), section_field_size()),
}


def _svg_size_in(root):
    return tuple(float(root.get(k).removesuffix("pt")) / 72.0 for k in ("width", "height"))


def _pdf_size_in(data):
    box = re.search(rb"/MediaBox\s*\[\s*0\s+0\s+([\d.]+)\s+([\d.]+)\s*\]", data)
    assert box, "no page size"
    return float(box.group(1)) / 72.0, float(box.group(2)) / 72.0


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("name", list(FIGURES))
def test_every_figure_in_every_format(cases, tmp_path, name, fmt):
    draw, size = FIGURES[name]
    with figure_format(fmt):
        out = draw(cases, tmp_path / f"{name}.png")
    out = Path(out)
    assert out.suffix == (".svg" if fmt == "svg" else ".png") and out.is_file()
    if fmt == "svg":
        root = ET.parse(out).getroot()
        assert root.tag.endswith("svg")
        assert _svg_size_in(root) == pytest.approx(size, abs=0.01)
        drawn = [el for el in root.iter() if el.tag.rsplit("}", 1)[-1] in ("path", "use", "image")]
        assert len(drawn) > 20, "blank SVG"
        assert not (tmp_path / f"{name}.png").exists()
        return
    img = check_png(out, size)  # 300 dpi: the pixel size of the stated inches, not blank
    assert img.shape[:2] == (round(size[1] * 300), round(size[0] * 300)) and DPI == 300
    from PIL import Image

    with Image.open(out) as png:
        assert png.mode == "P"  # a palette image (save_figure's colors=256), not full RGB
    if fmt == "pdf":
        pdf = Path(vector_copy(out))
        data = pdf.read_bytes()
        assert data.startswith(b"%PDF-") and b"%%EOF" in data[-32:]
        assert _pdf_size_in(data) == pytest.approx(size, abs=0.01)
        assert 2_000 < len(data) < 3e6
    else:
        assert vector_copy(out) is None


@pytest.mark.parametrize("view", ["pyvista", "matplotlib"])
def test_colour_fields_are_rasterised_in_vector_files(cases, tmp_path, monkeypatch, view):
    """Surfaces and colour maps go into SVG/PDF as one image each; the titles and colour bar stay
    vector, and matplotlib's 3-D axes too (pyvista's views are images, their axes inside)."""
    if view == "pyvista":
        pytest.importorskip("pyvista")
    else:
        monkeypatch.setitem(sys.modules, "pyvista", None)
    with figure_format("svg"):
        out = f3d.plot_pressure_surfaces([("a", cases["smooth"]), ("b", cases["er"])], tmp_path / "s.png", p0=P0, a=A)
    root = ET.parse(out).getroot()
    images = [el for el in root.iter() if el.tag.endswith("image")]
    texts = [el for el in root.iter() if el.tag.endswith("path")]
    assert len(images) == 3 and len(texts) > (50 if view == "matplotlib" else 20)  # two surfaces, the colour bar


@pytest.mark.parametrize("fmt", FORMATS)
def test_report_carries_the_format(cases, tmp_path, fmt):
    with figure_format(fmt):
        paths = [FIGURES[n][0](cases, tmp_path / f"{n}.png") for n in ("profiles", "contact_map")]
    sections = [Section("Figures", items=tuple(Figure(str(p), f"Figure {k}.") for k, p in enumerate(paths)))]
    built = build_report(sections, tmp_path / "rep", title="T")
    html = built.html.read_text(encoding="utf-8")
    md = built.markdown.read_text(encoding="utf-8")
    files = sorted(p.name for p in (built.out_dir / "figures").iterdir())
    if fmt == "svg":
        assert files == ["contact_map.svg", "profiles.svg"]
        assert figure_sources(html) == ["figures/profiles.svg", "figures/contact_map.svg"]
        assert "](figures/profiles.svg)" in md
    else:
        assert figure_sources(html) == ["figures/profiles.png", "figures/contact_map.png"]
        pngs = ["contact_map.png", "profiles.png"]
        assert files == (sorted(pngs + ["contact_map.pdf", "profiles.pdf"]) if fmt == "pdf" else pngs)
        assert ("(vector: [figures/profiles.pdf](figures/profiles.pdf))" in md) == (fmt == "pdf")
        assert ('(vector: <a href="figures/profiles.pdf">figures/profiles.pdf</a>)' in html) == (fmt == "pdf")
    from .test_report_build import assert_valid_offline_html

    assert_valid_offline_html(html)


def test_figure_format_is_checked_and_scoped(tmp_path):
    from bem.checks import InputError

    with pytest.raises(InputError, match="format"):
        with figure_format("jpg"):
            pass
    with figure_format("svg"):
        pass
    out = fsw.plot_transition_line([0.0, 1.0], [1.0, 0.0], tmp_path / "t.png", a=1.0)
    assert out.endswith(".png")  # back to the default after the block


def test_the_command_line_offers_the_figure_formats(capsys):
    """``contactlab report --format`` takes exactly :data:`FORMATS` and its help states :data:`DPI`."""
    from validation.cli import build_parser

    parser = build_parser()
    for fmt in FORMATS:
        assert parser.parse_args(["report", "hertz", "--format", fmt]).format == fmt
    with pytest.raises(SystemExit):
        parser.parse_args(["report", "hertz", "--format", "jpg"])
    assert "{" + ",".join(FORMATS) + "}" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        parser.parse_args(["report", "--help"])
    assert f"png ({DPI} dpi, default)" in " ".join(capsys.readouterr().out.split())


def test_only_the_3d_views_import_pyvista_inside_functions():
    import ast

    found = []
    for d in ("bem", "fem_reference", "validation", "benchmarks", "docs"):
        for path in (ROOT / d).rglob("*.py"):
            tree = ast.parse(path.read_text(encoding="utf-8"))
            top = {id(node) for node in tree.body}
            for node in ast.walk(tree):
                names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                         else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
                if any(n.split(".")[0] in ("pyvista", "vtk", "vtkmodules") for n in names):
                    found.append((str(path.relative_to(ROOT)), id(node) in top))
    assert found == [("validation/report/figures/views3d.py", False)]


def test_png_is_not_sheared_at_fractional_pixel_sizes(tmp_path):
    """A figure 3.3 * 3 + 0.9 in wide (not a whole number of pixels at 300 dpi, as the 3-D panels)
    keeps a vertical line vertical: the PNG is read with its own size, not a computed one."""
    from validation.report.render.style import new_figure, save_figure

    with new_figure((3.3 * 3 + 0.9, 2.8)) as (fig, ax):
        ax.set_axis_off()
        ax.axvline(0.5, color="black", lw=2)
        ax.set_xlim(0, 1)
        path = save_figure(fig, tmp_path / "v.png")
    from PIL import Image

    with Image.open(path) as im:
        pixels = np.asarray(im.convert("L"), dtype=float)
    dark = [int(np.argmin(row)) for row in pixels[pixels.shape[0] // 4: 3 * pixels.shape[0] // 4: 20]]
    assert max(dark) - min(dark) <= 1
