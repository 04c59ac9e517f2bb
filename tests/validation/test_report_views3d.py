"""The 3-D views: rendered off-screen by pyvista with the [3d] extra, drawn by matplotlib without
it (pyvista's import made to fail) or when pyvista cannot render; each checked for what it shows:
the colours of the data range in the expected panel, the panel layout."""

import logging
import sys

import numpy as np
import pytest
from matplotlib import colormaps

from validation.report.figures import fields, surfaces, views3d

from .test_report_figures import _image


def _hemisphere(h=0.125, n=16):
    """Hertz's pressure sqrt(1 - r^2) on an equilateral lattice (written out here)."""
    j, i = np.meshgrid(np.arange(-n, n + 1), np.arange(-n, n + 1), indexing="ij")
    x = (i * h + 0.5 * h * (j % 2)).ravel()
    y = (j * h * np.sqrt(3) / 2).ravel()
    return x, y, np.sqrt(np.clip(1.0 - x**2 - y**2, 0.0, None))


def _near(img, rgb, tol=40):
    """Pixels of ``img`` within ``tol`` of the colour ``rgb`` (0..255)."""
    return np.abs(img[:, :, :3].astype(float) - np.asarray(rgb, float)).max(axis=2) < tol


def _viridis(v):
    return np.array(colormaps["viridis"](v)[:3]) * 255


@pytest.fixture
def no_pyvista(monkeypatch):
    """pyvista as if it were not installed: its import raises ImportError."""
    monkeypatch.setitem(sys.modules, "pyvista", None)
    assert views3d.pyvista_or_none() is None


def _surfaces(tmp_path, name):
    """One panel with the full peak p0 and one with half of it, side by side."""
    x, y, p = _hemisphere()
    path = surfaces.plot_pressure_surfaces([("full", (x, y, p)), ("half", (x, y, 0.5 * p))], tmp_path / name,
                                           p0=1.0, a=1.0)
    img = _image(path)
    width = img.shape[1]
    return img[:, : int(0.45 * width)], img[:, int(0.45 * width): int(0.88 * width)]


def _check_common_colour_scale(left, right):
    """The peak's colour (viridis at 1) shows in the full panel only; the half panel's top is viridis at 0.5."""
    top, half = _viridis(1.0), _viridis(0.5)
    assert _near(left, top).sum() > 200, "the full panel shows its peak p0"
    assert _near(right, top).sum() < 20, "the half panel never reaches p0 on the common scale"
    assert _near(right, half).sum() > 200


def test_pressure_surfaces_rendered_by_pyvista(tmp_path, monkeypatch):
    pytest.importorskip("pyvista")
    calls = []
    render = views3d.render_surface
    monkeypatch.setattr(views3d, "render_surface", lambda *a, **k: calls.append(k["clim"]) or render(*a, **k))
    left, right = _surfaces(tmp_path, "pv.png")
    assert calls == [(0.0, 1.0), (0.0, 1.0)]  # both panels on one colour scale
    _check_common_colour_scale(left, right)


def test_pressure_surfaces_without_pyvista_use_matplotlib(tmp_path, monkeypatch, no_pyvista):
    monkeypatch.setattr(views3d, "render_surface", lambda *a, **k: pytest.fail("pyvista path taken"))
    left, right = _surfaces(tmp_path, "mpl.png")
    _check_common_colour_scale(left, right)


def test_pressure_surfaces_fall_back_when_pyvista_cannot_render(tmp_path, monkeypatch, caplog):
    pytest.importorskip("pyvista")

    def blank(*args, **kwargs):
        raise RuntimeError("the off-screen rendering is blank")

    monkeypatch.setattr(views3d, "render_surface", blank)
    with caplog.at_level(logging.WARNING):
        left, right = _surfaces(tmp_path, "fallback.png")
    _check_common_colour_scale(left, right)
    assert any("drawn with matplotlib" in r.getMessage() for r in caplog.records)


def _section_field():
    """A field on an (r, z) triangulation of both bodies peaking at 1 at depth 0.5 on the axis."""
    import matplotlib.tri as mtri

    r, z = np.meshgrid(np.linspace(0.0, 4.0, 41), np.linspace(-4.0, 4.0, 81))
    r, z = r.ravel(), z.ravel()
    tri = mtri.Triangulation(r, z).triangles
    return r, z, tri, np.exp(-(r**2 + (np.abs(z) - 0.5) ** 2))


def _von_mises(tmp_path, name):
    r, z, tri, values = _section_field()
    return _image(fields.plot_section_field(r, z, tri, values, tmp_path / name, a=1.0, scale=1.0, label="s",
                                            contact_radius=1.0))


def test_stress_volume_rendered_by_pyvista_beside_the_section(tmp_path):
    pytest.importorskip("pyvista")
    img = _von_mises(tmp_path, "pv.png")
    assert img.shape[1] / img.shape[0] == pytest.approx(10.4 / 4.6, rel=0.01)  # 3-D view and section
    left = img[:, : int(0.4 * img.shape[1])]
    bright = _near(left, np.array(colormaps["magma"](0.95)[:3]) * 255, tol=45)
    assert bright.sum() > 200, "the cut shows the field's maximum below the contact"
    rows = np.nonzero(bright.any(axis=1))[0]
    cyan = np.nonzero(_near(left, (0, 208, 255), tol=60).any(axis=1))[0]
    assert cyan.size and cyan.min() < rows.mean(), "the contact patch is drawn above the maximum"


def test_stress_section_alone_without_pyvista(tmp_path, no_pyvista):
    img = _von_mises(tmp_path, "mpl.png")
    assert img.shape[1] / img.shape[0] == pytest.approx(5.8 / 4.6, rel=0.01)
    assert _near(img, np.array(colormaps["magma"](0.95)[:3]) * 255, tol=45).sum() > 200


@pytest.mark.parametrize("label, plain", [(r"$x\,/\,a_H$", "x / a_H"), (r"$p$ [MPa]", "p [MPa]"),
                                          (r"$\sigma_{vM}\,/\,p_0$", "sigma_vM / p_0")])
def test_plain_labels_for_vtk(label, plain):
    assert views3d.plain_label(label) == plain
