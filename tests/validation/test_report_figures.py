"""Every figure type of validation.report renders a real, non-blank PNG of the expected size and
draws what it is given: its curves are the data in the stated units, its limits hold them, its
labels name them; the helpers behind the figures are checked against hand-computed values;
inputs stay untouched; files are written atomically."""

import math
import os

import numpy as np
import pytest

import bem
from bem.checks import InputError
from bem.reference import hertz_sphere
from validation.report.figures import iterations as fit
from validation.report.figures import precision as fva
from validation.report.figures import profiles as fpr
from validation.report.figures import surfaces as f3d
from validation.report.figures import sweeps as fsw
from bem.files import atomic_path
from validation.report.render.style import DPI, save_figure

from .figure_spy import drawn, horizontal_at, lines_of, vertical_at  # noqa: F401 - drawn is a fixture

HERTZ = hertz_sphere(R=1.0, E_star=1.0, force=1.0)
A, P0 = HERTZ.contact_radius, HERTZ.p_max
STEP = A / 6
LAM = 10 * bem.diagonal_coefficient(STEP, 1.0)


def _solve(layer=None, **kw):
    return bem.solve(bem.gaps.Paraboloid(1.0), E_star=1.0, force=1.0, step=STEP, extent=2.0 * A, layer=layer,
                     rtol=1e-8, **kw)


@pytest.fixture(scope="module")
def cases():
    smooth = _solve()
    lin = _solve(bem.layers.Linear(LAM))
    er = bem.layers.ElasticRigid(LAM, 0.5 * lin.p_max)
    return {"smooth": smooth, "linear": lin, "er_law": er, "er": _solve(er),
            "er_vc": _solve(er, method="variable_compliance", record=True),
            "er_newton": _solve(er, method="newton", record=True, nested=False)}


def _image(path):
    from PIL import Image

    with Image.open(path) as img:
        assert img.format == "PNG"
        return np.asarray(img.convert("RGB"), dtype=float)


def section_field_size():
    """Size of :func:`plot_section_field`'s figure [inch]: with pyvista its 3-D view is beside the section."""
    from validation.report.figures.views3d import pyvista_or_none

    return (5.8, 4.6) if pyvista_or_none() is None else (10.4, 4.6)


def check_png(path, size_in=None, *, floor=8.0):
    """A real PNG, of ``size_in`` inches at DPI when given, with visible content."""
    assert os.path.isfile(path)
    img = _image(path)
    if size_in is not None:
        assert img.shape[:2] == (round(size_in[1] * DPI), round(size_in[0] * DPI))
    assert img.std() > floor, "blank image"
    # not only background: a sizeable share of pixels is not white
    assert np.mean(img.min(axis=2) < 200) > 0.01
    return img


# ---------------------------------------------------------------- helpers against hand values

def test_axial_section_selects_y0_and_sorts():
    x = np.array([0.3, -0.1, 0.2, 0.0, 0.5])
    y = np.array([0.0, 0.0, 0.1, 0.0, -0.2])
    v = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    xs, vs = fpr.axial_section(x, y, v)
    np.testing.assert_array_equal(xs, [-0.1, 0.0, 0.3])
    np.testing.assert_array_equal(vs, [2.0, 4.0, 1.0])
    with pytest.raises(InputError, match="y = 0"):
        fpr.axial_section(x, y + 1.0, v)


def test_section_of_result_is_lattice_row_zero(cases):
    r = cases["er"]
    lat = r.lattice
    row = lat.half_rows  # brick row of lattice row j = 0
    x, p = fpr.section_of(r)
    np.testing.assert_allclose(x, lat.x[row][lat.mask[row]])
    np.testing.assert_allclose(p, r.grid()[row][lat.mask[row]])


def test_section_of_fem_like_is_mirrored():
    class Fem:
        r = np.array([0.0, 1.0, 2.0])
        p = np.array([3.0, 2.0, 0.0])

    x, p = fpr.section_of(Fem())
    np.testing.assert_array_equal(x, [-2.0, -1.0, 0.0, 1.0, 2.0])
    np.testing.assert_array_equal(p, [0.0, 2.0, 3.0, 2.0, 0.0])


def test_transition_radius_exact_on_piecewise_linear_profile():
    x = np.linspace(-1.0, 1.0, 11)  # nodes every 0.2
    p = 1.0 - np.abs(x)  # linear between nodes: the interpolated crossing is exact
    assert fsw.transition_radius(x, p, 0.3) == pytest.approx(0.7)
    assert fsw.transition_radius(x, p, 0.85) == pytest.approx(0.15)
    assert fsw.transition_radius(x, p, 1.5) == 0.0  # no node reaches p_cr: no rigid region
    assert fsw.edge_radius(x, np.where(np.abs(x) < 0.5, p, 0.0)) == pytest.approx(0.5)  # midway 0.4 | 0.6


def test_pick_iterations():
    np.testing.assert_array_equal(fit.pick_iterations(4), [1, 2, 3, 4])
    ks = fit.pick_iterations(200, most=10)
    assert ks[0] == 1 and ks[-1] == 200 and len(ks) <= 10 and np.all(np.diff(ks) > 0)


def test_work_precision_rows_accepts_tuples_and_drops_unplottable():
    rows = fva.work_precision_rows([("BEM", "qp", "a/c=5", 100, 1e-3, 0.1), {"solver": "FEM", "error": 0.0,
                                                                              "wall_time_s": 1.0},
                                    {"solver": "FEM", "error": float("nan"), "wall_time_s": 1.0}])
    assert len(rows) == 1 and rows[0]["N"] == 100 and rows[0]["resolution"] == "a/c=5"
    with pytest.raises(InputError, match="lacks"):
        fva.work_precision_rows([{"solver": "BEM"}])


# ---------------------------------------------------------------- every figure type

def test_pressure_profiles_png(cases, tmp_path, drawn):
    curves = [("smooth", cases["smooth"]), ("linear", cases["linear"]), ("elastic-rigid", cases["er"])]
    s = np.linspace(-1.5 * A, 1.5 * A, 301)
    path = fpr.plot_pressure_profiles(curves, tmp_path / "p.png", p0=P0, a=A, hertz=(s, HERTZ.pressure(s)))
    img = check_png(path, (8.2, 4.0))
    ax = drawn[-1].axes[0]
    lines = lines_of(ax)
    assert list(lines) == ["Hertz (closed form)", "smooth", "linear", "elastic-rigid"]
    np.testing.assert_allclose(lines["Hertz (closed form)"][1], HERTZ.pressure(s) / P0)
    edge = 0.0
    for label, res in curves:  # the axial section y = 0 of each result, in units of a and p0
        y0 = np.abs(res.y) < 1e-12 * A
        order = np.argsort(res.x[y0])
        np.testing.assert_allclose(lines[label][0], res.x[y0][order] / A)
        np.testing.assert_allclose(lines[label][1], res.p[y0][order] / P0)
        edge = max(edge, np.abs(res.x[y0][res.p[y0] > 0]).max() / A)
    lo, hi = ax.get_xlim()
    assert lo <= -edge and edge <= hi <= 1.5 * edge + 0.5  # every loaded node, not the whole region
    assert ax.get_ylim()[0] == 0.0 and ax.get_ylim()[1] >= max(r.p_max for _, r in curves) / P0
    assert "y = 0" in ax.get_xlabel() and "p_0" in ax.get_ylabel()
    # the data matter: a different set of curves gives a different picture
    other = fpr.plot_pressure_profiles(curves[:1], tmp_path / "q.png", p0=P0, a=A)
    assert np.abs(_image(other) - img).mean() > 0.5


def test_layer_laws_png(cases, tmp_path, drawn):
    laws = [("smooth", None), ("linear", cases["linear"].layer), ("elastic-rigid", cases["er_law"]),
            ("root", bem.layers.Root(LAM))]
    check_png(fpr.plot_layer_laws(laws, tmp_path / "w.png", p_max=P0, marks=[("p_cr", cases["er_law"].p_cr)]),
              (6.0, 3.8))
    ax = drawn[-1].axes[0]
    lines = lines_of(ax)
    assert list(lines) == [label for label, _ in laws]
    for label, layer in laws:  # w(p) of each law over 0..p_max; the smooth bodies on the axis
        p, w = lines[label]
        assert p[0] == 0.0 and p[-1] == P0
        np.testing.assert_allclose(w, 0.0 if layer is None else layer.w(p), rtol=1e-12, atol=0)
    assert ax.get_xlim() == (0.0, P0) and ax.get_ylim()[1] >= max(lines["root"][1].max(), lines["linear"][1].max())
    assert vertical_at(ax, cases["er_law"].p_cr)
    assert "p" in ax.get_xlabel() and "w(p)" in ax.get_ylabel()


def test_iteration_profiles_png(cases, tmp_path, drawn):
    r = cases["er_vc"]
    assert len(r.history["p"]) == r.iterations
    check_png(fit.plot_iteration_profiles(r, tmp_path / "it.png", p0=P0, a=A), (6.8, 4.0))
    ax = drawn[-1].axes[0]
    ks = fit.pick_iterations(r.iterations)
    drawn_p = [ln.get_ydata() for ln in ax.get_lines()]
    assert len(drawn_p) == ks.size + 1  # the iterates picked, then the final state
    for k, y in zip(ks, drawn_p):
        np.testing.assert_allclose(y, fpr.section_of(r, r.history["p"][k - 1])[1] / P0)
    final = lines_of(ax)
    (label, (_x, y)), = final.items()
    assert label.startswith("final (converged") and f"k = {r.iterations}" in label
    np.testing.assert_allclose(y, fpr.section_of(r)[1] / P0)
    with pytest.raises(InputError, match="record=True"):
        fit.plot_iteration_profiles(cases["er"], tmp_path / "x.png", p0=P0, a=A)
    with pytest.raises(InputError, match="iterations"):
        fit.plot_iteration_profiles(r, tmp_path / "x.png", p0=P0, a=A, iterations=[0, 1])
    assert not (tmp_path / "x.png").exists()


def test_convergence_png(cases, tmp_path, drawn):
    runs = [("variable compliance", cases["er_vc"]), ("Newton", cases["er_newton"])]
    check_png(fit.plot_convergence(runs, tmp_path / "c.png", p0=P0, tol=1e-8), (6.6, 5.2))
    top, bot = drawn[-1].axes[:2]
    lines = lines_of(top)
    assert list(lines) == ["variable compliance", "Newton"]
    for (label, r), (k, pm), res_line in zip(runs, lines.values(), bot.get_lines()):
        np.testing.assert_array_equal(k, np.arange(1, len(r.history["p_max"]) + 1))
        np.testing.assert_allclose(pm, np.asarray(r.history["p_max"]) / P0)
        np.testing.assert_allclose(res_line.get_ydata(), r.history["residual"])
        assert r.history["residual"][-1] <= 1e-8
    assert horizontal_at(bot, 1e-8) and bot.get_yscale() == "log" and bot.get_xscale() == "log"
    assert bot.get_ylabel() == "KKT residual" and "p_0" in top.get_ylabel()


def test_pressure_surfaces_3d_png(cases, tmp_path, drawn):
    r = cases["er_vc"]
    panels = [("final", r), ("k = 1", (r.x, r.y, r.history["p"][0])), ("smooth", cases["smooth"])]
    # two panels per row (each half a report page wide): two rows of 3.3 x 2.8 in, the colour bar, the title
    check_png(f3d.plot_pressure_surfaces(panels, tmp_path / "s.png", p0=P0, a=A, title="t"),
              (3.3 * 2 + 0.9, 2.8 * 2 + 0.35))
    *surfaces, bar = drawn[-1].axes
    assert [ax.get_title() for ax in surfaces] == ["final", "k = 1", "smooth"]
    assert r.p_max < 0.97 * cases["smooth"].p_max  # the first panel is not the highest
    vmax = max(cases["smooth"].p.max(), r.history["p"][0].max(), r.p.max()) / P0
    assert bar.get_ylim() == pytest.approx((0.0, vmax))  # one colour scale: the highest peak of all panels


def test_pressure_surface_without_axis_nodes(tmp_path):
    x, y = np.meshgrid(np.linspace(-1, 1, 20), np.linspace(-1, 1, 20))  # even count: no node on y = 0
    p = np.clip(1 - x**2 - y**2, 0, None)
    check_png(f3d.plot_pressure_surfaces([("cap", (x.ravel(), y.ravel(), p.ravel()))], tmp_path / "s.png",
                                         p0=1.0, a=1.0))


def test_contact_map_png(cases, tmp_path, drawn):
    er = cases["er"]
    check_png(f3d.plot_contact_map(er, tmp_path / "m.png", p0=P0, a=A, levels=[("p_cr", cases["er_law"].p_cr)]),
              (5.4, 4.4))
    ax = drawn[-1].axes[0]
    field = ax.collections[0]
    xs, ys, ps, _tri = f3d.contact_patch(er.x, er.y, er.p, margin=0.3)
    np.testing.assert_allclose(field.get_array(), ps / P0)  # p / p0 over the patch around the contact
    assert field.get_clim() == pytest.approx((0.0, er.p_max / P0))
    lines = lines_of(ax)
    assert {"contact boundary", "p_cr"} < set(lines)
    circle = lines[r"equal-area circle $r = \sqrt{A/\pi}$"]
    np.testing.assert_allclose(np.hypot(*circle), er.contact_radius / A)
    (x0, x1), (y0, y1) = f3d.covered_window(xs, ys)
    assert ax.get_xlim() == pytest.approx((x0 / A, x1 / A)) and ax.get_ylim() == pytest.approx((y0 / A, y1 / A))


def test_contact_map_window_is_covered_by_the_triangles(cases):
    """The map's axes show only the rectangle the lattice triangles cover: no white notch at the
    corners where the outermost rows are the ones shifted by half a step."""
    from scipy.spatial import Delaunay

    r = cases["er"]
    notched = 0
    for margin in np.linspace(0.2, 0.5, 7):
        xs, ys, _ps, _tri = f3d.contact_patch(r.x, r.y, r.p, margin=margin)
        (x0, x1), (y0, y1) = f3d.covered_window(xs, ys)
        assert x0 <= -np.abs(xs).max() + STEP / 2 + 1e-12 and x1 >= np.abs(xs).max() - STEP / 2 - 1e-12
        assert (y0, y1) == (ys.min(), ys.max())
        hull = Delaunay(np.column_stack([xs, ys]))
        gx, gy = np.meshgrid(np.linspace(x0, x1, 81), np.linspace(y0, y1, 81))
        assert (hull.find_simplex(np.column_stack([gx.ravel(), gy.ravel()]), tol=1e-12) >= 0).all(), margin
        corners = [(u, v) for u in (xs.min(), xs.max()) for v in (ys.min(), ys.max())]
        notched += bool((hull.find_simplex(corners) < 0).any())  # autoscaled axes showed white there
    assert notched > 0


def test_contact_patch_covers_contact(cases):
    r = cases["er"]
    xs, ys, ps, tri = f3d.contact_patch(r.x, r.y, r.p)
    assert np.count_nonzero(ps > 0) == np.count_nonzero(r.p > 0)
    # equilateral lattice: every Delaunay triangle has the area sqrt(3)/4 c^2
    e1 = np.stack([xs[tri[:, 1]] - xs[tri[:, 0]], ys[tri[:, 1]] - ys[tri[:, 0]]], axis=1)
    e2 = np.stack([xs[tri[:, 2]] - xs[tri[:, 0]], ys[tri[:, 2]] - ys[tri[:, 0]]], axis=1)
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    np.testing.assert_allclose(area, math.sqrt(3) / 4 * STEP**2, rtol=1e-9)


def test_sweep_and_transition_line_png(cases, tmp_path, drawn):
    curves = [(al, *fpr.section_of(r)) for al, r in ((0.0, cases["smooth"]), (0.5, cases["er"]),
                                                      (1.0, cases["linear"]))]
    check_png(fsw.plot_sweep(curves, tmp_path / "sw.png", p0=P0, a=A, name=r"$\alpha_a$"), (6.8, 4.0))
    ax, bar = drawn[-1].axes
    for (_alpha, x, p), ln in zip(curves, ax.get_lines(), strict=True):
        np.testing.assert_allclose(ln.get_xdata(), x / A)
        np.testing.assert_allclose(ln.get_ydata(), p / P0)
    np.testing.assert_allclose(bar.get_yticks(), [0.0, 0.5, 1.0])  # the colour bar names the swept values
    assert bar.get_ylabel() == r"$\alpha_a$"
    check_png(fsw.plot_transition_line([0.5, 0.0, 1.0], [0.8, 1.0, 0.0], tmp_path / "tl.png", a=2.0,
                                       r_contact=[1.1, 1.0, 1.2]), (6.0, 4.0))
    ax = drawn[-1].axes[0]
    lines = lines_of(ax)
    np.testing.assert_allclose(lines["transition line $p = p_{cr}$"], [[0.0, 0.5, 1.0], [0.5, 0.4, 0.0]])
    np.testing.assert_allclose(lines["contact edge"], [[0.0, 0.5, 1.0], [0.5, 0.55, 0.6]])  # sorted, r / a
    assert ax.get_xlim() == (0.0, 1.0) and ax.get_ylim() == pytest.approx((0.0, 1.08 * 0.6))


def test_profile_comparison_png(cases, tmp_path, drawn):
    s = cases["smooth"]
    x, p = fpr.section_of(s)
    curves = [("BEM", x, p, "bem"), ("shifted", x, 0.98 * p, "fem")]
    check_png(fpr.plot_profile_comparison(curves, tmp_path / "cmp.png", p0=P0, a=A,
                                          reference=("Hertz", HERTZ.pressure)), (6.6, 5.4))
    top, bot = drawn[-1].axes[:2]
    lines = lines_of(top)
    assert list(lines) == ["Hertz", "BEM", "shifted"]
    r, pr = lines["BEM"][0] * A, lines["BEM"][1] * P0
    assert np.all(r >= 0) and np.isin(np.round(r / A, 9), np.round(np.abs(x) / A, 9)).all()
    errors = {ln.get_label().split(":")[0]: ln for ln in bot.get_lines() if not ln.get_label().startswith("_")}
    for label, factor in (("BEM", 1.0), ("shifted", 0.98)):  # the lower panel: (p - p_Hertz) / p0 at the nodes
        rr = errors[label].get_xdata() * A
        expected = (factor * np.interp(rr, r, pr) - HERTZ.pressure(rr)) / P0
        np.testing.assert_allclose(errors[label].get_ydata(), expected, atol=1e-12)
    worst = max(np.abs(ln.get_ydata()).max() for ln in errors.values())
    assert bot.get_ylim() == pytest.approx((-1.15 * worst, 1.15 * worst))
    assert top.get_xlim()[0] == 0.0 and top.get_xlim()[1] >= np.abs(x[p > 0]).max() / A
    # reference given as samples (no callable)
    check_png(fpr.plot_profile_comparison(curves, tmp_path / "cmp2.png", p0=P0, a=A))


def test_work_precision_png(tmp_path, drawn):
    rows = [("BEM", "qp", f"a/c={m}", 100 * m, 0.3 / m**1.5, 0.01 * m) for m in (5, 10, 20)]
    rows += [{"solver": "FEM", "method": "P2", "resolution": f"{n}/a", "N": 1000 * n, "error": 0.1 / n**2,
              "wall_time_s": 0.1 * n} for n in (4, 8)]
    check_png(fva.plot_work_precision(rows, tmp_path / "wp.png"), (7.0, 4.6))
    ax = drawn[-1].axes[0]
    lines = lines_of(ax)
    assert list(lines) == ["BEM (qp)", "FEM (P2)"]
    np.testing.assert_allclose(lines["BEM (qp)"], [[0.05, 0.1, 0.2], [0.3 / m**1.5 for m in (5, 10, 20)]])
    np.testing.assert_allclose(lines["FEM (P2)"], [[0.4, 0.8], [0.1 / 16, 0.1 / 64]])
    assert ax.get_xscale() == ax.get_yscale() == "log" and ax.get_ylabel() == "relative error"
    assert horizontal_at(ax, 0.01) and horizontal_at(ax, 0.001)
    # repeats: the marker at the median, the bar from the fastest to the slowest
    spread = [dict(r, wall_times_s=[0.8 * r["wall_time_s"], r["wall_time_s"], 1.5 * r["wall_time_s"]])
              for r in fva.work_precision_rows(rows)]
    assert fva.time_spread(spread[0]) == pytest.approx((0.05, 0.04, 0.075))
    assert fva.time_spread(fva.work_precision_rows(rows)[0]) == pytest.approx((0.05, 0.05, 0.05))  # one run
    with_bars = check_png(fva.plot_work_precision(spread, tmp_path / "wp2.png"), (7.0, 4.6))
    assert np.abs(with_bars - _image(tmp_path / "wp.png")).mean() > 0.1  # the bars are drawn
    with pytest.raises(InputError, match="nothing to draw"):
        fva.plot_work_precision([("BEM", "qp", "x", 1, 0.0, 1.0)], tmp_path / "none.png")


def test_von_mises_png(tmp_path, drawn):
    from validation.report.figures.fields import plot_section_field, von_mises_of

    import fem_reference

    e_body = 2.0 * (1.0 - 0.09)
    fem = fem_reference.solve(bem.gaps.Paraboloid(1.0), E1=e_body, nu1=0.3, E2=e_body, nu2=0.3, force=1.0,
                              n_contact_elements=6)
    r, z, tri, vm = von_mises_of(fem)
    # Hertz (Johnson 1985, Fig. 4.4 / eq. 3.73-3.74, nu = 0.3): max von Mises ~0.62 p0 at z ~ 0.48 a on the axis
    k = int(np.argmax(vm))
    assert vm[k] / P0 == pytest.approx(0.62, abs=0.03)
    assert abs(z[k]) / A == pytest.approx(0.48, abs=0.12) and r[k] / A < 0.25
    check_png(plot_section_field(r, z, tri, vm, tmp_path / "vm.png", a=A, scale=P0, label="von Mises",
                                 contact_radius=fem.edge_radius), section_field_size())
    ax = next(ax for ax in drawn[-1].axes if ax.collections)  # the (r, z) map (beside a 3-D view with [3d])
    shown = ax.collections[0].get_array()
    assert shown.max() == pytest.approx(vm.max() / P0, rel=1e-12)  # the FEM's von Mises stress / p0
    assert np.all(shown >= 0) and ax.get_xlim() == (-3.0, 3.0) and ax.get_ylim() == (-3.0, 3.0)
    (label, (xc, zc)), = lines_of(ax).items()  # the contact, marked on the interface
    assert label.startswith("contact") and np.all(zc == 0.0)
    np.testing.assert_allclose(xc, np.array([-1.0, 1.0]) * fem.edge_radius / A)


# ---------------------------------------------------------------- inputs untouched, atomic writes

def test_figures_do_not_modify_inputs(cases, tmp_path):
    x, p = fpr.section_of(cases["er"])
    x0, p0 = x.copy(), p.copy()
    r = cases["er_vc"]
    hist = [h.copy() for h in r.history["p"]]
    fsw.plot_sweep([(0.5, x, p)], tmp_path / "a.png", p0=P0, a=A, name="a")
    fsw.transition_radius(x, p, 0.1)
    fpr.plot_profile_comparison([("c", x, p)], tmp_path / "b.png", p0=P0, a=A, reference=("h", HERTZ.pressure))
    fit.plot_iteration_profiles(r, tmp_path / "c.png", p0=P0, a=A)
    np.testing.assert_array_equal(x, x0)
    np.testing.assert_array_equal(p, p0)
    for h, h0 in zip(r.history["p"], hist):
        np.testing.assert_array_equal(h, h0)


def test_save_figure_is_atomic(tmp_path, monkeypatch):
    from matplotlib.figure import Figure

    target = tmp_path / "f.png"
    target.write_bytes(b"old")
    fig = Figure()
    fig.subplots().plot([0, 1], [0, 1])

    def boom(*args, **kwargs):
        raise RuntimeError("disk full")

    monkeypatch.setattr(fig, "savefig", boom)
    with pytest.raises(RuntimeError, match="disk full"):
        save_figure(fig, target)
    assert target.read_bytes() == b"old"
    assert sorted(os.listdir(tmp_path)) == ["f.png"]  # no temporary left behind


def test_atomic_path_leaves_nothing_on_error(tmp_path):
    with pytest.raises(ValueError):
        with atomic_path(tmp_path / "x.png") as tmp:
            with open(tmp, "wb") as fh:
                fh.write(b"partial")
            raise ValueError("interrupted")
    assert os.listdir(tmp_path) == []


def test_bad_scales_raise(cases, tmp_path):
    with pytest.raises(InputError, match="p0"):
        fpr.plot_pressure_profiles([("s", cases["smooth"])], tmp_path / "z.png", p0=-1.0, a=A)
    with pytest.raises(InputError, match="curves"):
        fpr.plot_pressure_profiles([], tmp_path / "z.png", p0=P0, a=A)
    assert not (tmp_path / "z.png").exists()


def _drawn_lines(monkeypatch, module):
    """Every figure ``module.save_figure`` writes: its first axes' lines as (marker, x, y)."""
    drawn, real = [], module.save_figure

    def spy(fig, path, **kwargs):
        drawn.append([(ln.get_marker(), np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float))
                      for ln in fig.axes[0].lines])
        return real(fig, path, **kwargs)

    monkeypatch.setattr(module, "save_figure", spy)
    return drawn


def test_tabulated_layer_law_shows_its_points(tmp_path, monkeypatch):
    from bem.layers import Linear, Tabulated
    from validation.report.figures import profiles
    from validation.report.figures.run import Scaled

    p, w = np.array([0.0, 1e6, 2e6, 4e6, 8e6]), np.array([0.0, 0.5e-6, 0.8e-6, 1.0e-6, 1.1e-6])
    drawn = _drawn_lines(monkeypatch, profiles)
    check_png(profiles.plot_layer_laws([("table", Scaled(Tabulated(p, w), 1e6, 1e-6)), ("linear", Linear(1.0))],
                                       tmp_path / "law.png", p_max=5.0, p_unit="MPa", w_unit="µm"))
    points = [(x, y) for marker, x, y in drawn[0] if marker == "o"]
    assert len(points) == 1, "the table's points, and no markers on the formula law"
    np.testing.assert_allclose(points[0][0], [0.0, 1.0, 2.0, 4.0])  # in view: p <= p_max, in MPa
    np.testing.assert_allclose(points[0][1], [0.0, 0.5, 0.8, 1.0])  # in µm


def test_the_tolerance_in_a_caption_is_the_recorded_bem_rtol_never_read_from_the_message():
    from types import SimpleNamespace

    from validation.report.figures.run import _tolerance

    bem = SimpleNamespace(rtol=1e-8, message="KKT residual 1e-12 <= rtol 1.0e-03")
    assert _tolerance(SimpleNamespace(bem=bem)) == 1e-8
