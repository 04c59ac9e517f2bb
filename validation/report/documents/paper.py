"""The report of the paper's test problem: analogues of Fig. 4-11, the stresses and the validation.

:func:`report_paper_problem` runs the cases (:mod:`validation.studies.paper_problem`) and
writes the report. Pressures are divided by Hertz's peak ``p0`` and lengths by Hertz's radius
``a_H`` of the smooth problem; the validation figures are those of a run's report
(:data:`validation.report.figures.FIGURES`) of the cases run with the FEM reference.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from ...studies.paper_problem import AG_RELAXATION, ALPHA_A_ITERATIONS, RTOL, SCENES, SOLVE_STAGES, run_paper_problem
from ..figures import run as run_figures
from ..render import Figure, Progress, Section, Table, draw_and_build, problem_section
from ..render.style import method_text
from .results import results_of

__all__ = ["report_paper_problem", "paper_sections", "expected_stalls", "STAGES", "TITLE"]

TITLE = "contactlab: the paper's test problem - paraboloids with a nonlinear interface layer"
#: what the title of a quick report adds: its numbers are those of a coarse lattice and short sweeps
PREVIEW = "COARSE PREVIEW, --quick: not the numbers of record"
#: the stages of :func:`report_paper_problem`, as reported to its ``progress``
STAGES = (*SOLVE_STAGES, "figures", "writing")
#: case -> its key in figure names and colours (``"linear Winkler"`` -> ``"linear"``)
_KEYS = {case: scene.removeprefix("paper_") for case, scene in SCENES.items()}


def _method(r):
    """The method that ran (``r.method``): quadratic problems go to the Kalker QP whatever was asked."""
    return method_text(r.method, short=True)


def _how(r, res):
    return (f"{_method(r)}; lattice step c = a_H/{res.nodes_per_radius}, {r.p.size} candidate nodes, "
            f"{int(np.count_nonzero(r.p > 0))} in contact; KKT tolerance {RTOL:.0e}")


def _problem(res, work):
    from validation.scene.paper import c_nn

    from ..figures.profiles import plot_layer_laws

    smooth, info = res.outcomes["smooth"].scene, res.outcomes["elastic-rigid"].result.layer
    u, laws = smooth.units.as_dict(), res.laws
    pf, wf = res.p0, res.a  # as every pressure and length of the report: over p_0 and a_H
    path = plot_layer_laws([(k, v and run_figures.Scaled(v, pf, wf)) for k, v in laws.items()],
                           work / "fig04_layer_laws.png", p_max=1.1, p_label=r"pressure $p\,/\,p_0$",
                           w_label=r"layer closure $w(p)\,/\,a_H$",
                           marks=[(r"$p_{cr} = \alpha_a p_{max}^{\lambda}$", laws["elastic-rigid"].p_cr / pf)],
                           title="interface layer laws $w(p)$ (paper Fig. 4 b-d)")
    m = smooth.materials
    text = (
        f"Two elastic paraboloids (the built-in scenes paper_*: effective radius R = {smooth.gap.R:g} "
        f"{u['length']}, E1 = {m['E1']:g} {u['pressure']}, nu1 = {m['nu1']:g}, E2 = {m['E2']:g} {u['pressure']}, "
        f"nu2 = {m['nu2']:g}) pressed together by the force P = {smooth.load['force']:g} {u['force']}, with a thin "
        "interface layer between them whose closure w(p) depends nonlinearly on the contact pressure p (paper "
        f"section 6, Fig. 4). The smooth (Hertz) contact has radius a_H = {res.a:.4g} {u['length']}, peak "
        f"pressure p_0 = {res.p0:.4g} {u['pressure']} and approach delta_H = {res.approach:.4g} {u['length']}; all "
        "pressures below are divided by p_0 and all lengths by a_H.",
        f"The linear (Winkler) layer has the compliance lam = {info['lam_ref']:.4g} {u['length']}/{u['pressure']}, "
        f"the paper's {info['lam_ref'] / c_nn(res.a / 20, smooth.E_star):.3g} C_nn at the reference step "
        "c = a_H/20 (C_nn = c/(pi E*) w_t(0,0), the diagonal influence coefficient, eq. 6), fixed in physical "
        f"units so that every lattice solves the same problem; on this "
        f"report's lattice c = a_H/{res.nodes_per_radius} it is {info['lam_over_cnn']:.3g} C_nn. Its peak pressure "
        f"p_max^lambda = {res.p_lin / res.p0:.4f} p_0 scales the other laws: elastic-rigid w = lam min(p, p_cr) with "
        f"p_cr = alpha_a p_max^lambda, alpha_a = {info['alpha_a']:g}; root w = lam_b sqrt(p) with lam_b = lam "
        "sqrt(p_max^lambda) (root and linear laws close equally at p_max^lambda); bilinear with slope lam up to "
        "p* = alpha_a p_max^lambda and lam tan(alpha_c) beyond, alpha_c = "
        f"{res.outcomes['bilinear'].result.layer['alpha_c']:.4f} rad.")
    fig = Figure(path, "The layer laws w(p) of the test problem (analogue of the paper's Fig. 4 b-d), drawn from "
                       "the bem.layers objects the runs used; the dotted line marks p_cr = p*.")
    return problem_section(gap=smooth.gap, materials=m, load={"force": smooth.load["force"]}, units=u,
                           layers=list(laws.items()), figure=fig, text=text)


def _distributions(res, work):
    from ..figures.profiles import plot_pressure_profiles
    from ..figures.surfaces import plot_contact_map

    b, prof = res.base, res.outcomes["smooth"].result.analytic.profile
    path = plot_pressure_profiles(list(b.items()), work / "fig05_pressure_profiles.png", p0=res.p0, a=res.a,
                                  hertz=(prof["x"], prof["p"]),
                                  title="contact pressure in the axial section (paper Fig. 5)")
    er = b["elastic-rigid"]
    map_path = plot_contact_map(er, work / "fig05_contact_map_elastic_rigid.png", p0=res.p0, a=res.a,
                                levels=[(r"$p = p_{cr}$ (region I | II)", er.layer.p_cr)],
                                title=rf"elastic-rigid layer, $\alpha_a$ = {er.layer.p_cr / res.p_lin:g}")
    rows = tuple((k, _method(r), r.p_max / res.p0, r.contact_radius / res.a, r.approach / res.approach,
                  r.iterations, r.kkt_residual, r.wall_time_s, r.status)
                 for k, r in b.items())
    table = Table(("case", "method", "p_max / p_0", "r_c / a_H", "approach / delta_H", "iterations", "KKT residual",
                   "time [s]", "status"), rows, status_column="status",
                  caption="Key numbers of the Fig. 5 cases (r_c = sqrt(A/pi) from the loaded node area; approach "
                          "relative to the Hertz approach delta_H).")
    return Section("Pressure distributions for the layer laws (Fig. 5)", kind="results", text=(
        "All laws solved at the same load; the layer spreads the pressure over a wider contact and lowers the peak. "
        "The elastic-rigid law shows two regions: region I near the centre, where the layer is on its rigid branch "
        "(p >= p_cr) and the pressure has the shape of a smooth-body distribution, and region II outside, where the "
        "layer is elastic; the kink between them is the transition zone of the paper's Fig. 5-7.",), items=(
        Figure(path, "Contact pressure in the axial section y = 0 for every law (analogue of the paper's Fig. 5), "
                     "with Hertz's closed form (result.json of the smooth run) as the grey band. " + _how(er, res)
                     + ". Dashed with markers: the same bilinear problem solved by the paper's variable compliance "
                     "method; it coincides with the Newton solution."),
        Figure(map_path, "Pressure over the contact plane for the elastic-rigid law: the dotted contour p = p_cr "
                         "separates region I (rigid branch, inside) from region II (elastic branch). "
                         + _how(er, res) + "."), table))


def _stresses(res, work):
    from ..figures.fields import plot_depth_profiles

    st, base = res.stress, res.base
    smooth, nu = st["smooth"], res.outcomes["smooth"].scene.materials["nu1"]
    curves, marks, rows, parts = [], [], [], []
    for label, s in st.items():
        curves.append({"label": label, "z": s.z, "values": s.von_mises[:, s.nearest(0.0, 0.0)], "key": _KEYS[label]})
        if np.hypot(*s.location_of_max[:2]) <= 0.5 * base[label].step:
            marks.append((s.depth_of_max, s.max_von_mises, "black"))
        shift = (s.depth_of_max - smooth.depth_of_max) / res.a
        rows.append((label, s.max_von_mises / res.p0, f"{100 * (s.max_von_mises / smooth.max_von_mises - 1):+.1f} %",
                     s.depth_of_max / res.a, f"{shift:+.3f}", float(np.hypot(*s.location_of_max[:2])) / res.a,
                     s.max_tresca / res.p0, f"{100 * (s.max_tresca / smooth.max_tresca - 1):+.1f} %",
                     base[label].p_max / res.p0))
        if label != "smooth":
            parts.append(f"{label} {100 * (1 - s.max_von_mises / smooth.max_von_mises):.0f} % lower (p_max "
                         f"{100 * (1 - base[label].p_max / base['smooth'].p_max):.0f} % lower), {abs(shift):.3f} a_H "
                         f"{'deeper' if shift > 0 else 'shallower'}")
    path = plot_depth_profiles(curves, work / "fig_stress_profiles_laws.png", a=res.a, scale=res.p0,
                               stress_label=r"von Mises stress $\sigma_{vM}\,/\,p_0$", depth_label=r"depth $z\,/\,a_H$",
                               marks=marks, title="von Mises stress on the axis, same force, each layer law")
    deeper = [k for k, s in st.items() if s.depth_of_max > smooth.depth_of_max]
    shallower = [k for k, s in st.items() if s.depth_of_max < smooth.depth_of_max]
    moves = [f"{way} with {', '.join(laws)}" for way, laws in (("deeper", deeper), ("towards the surface", shallower))
             if laws]
    summary = (f"Smooth bodies: the largest von Mises stress is {smooth.max_von_mises / res.p0:.3f} p_0 at depth "
               f"{smooth.depth_of_max / res.a:.3f} a_H below the centre (Hertz: 0.620 p_0 at 0.481 a_H for nu = 0.3). "
               "With the same force it is, for the laws of Fig. 5: " + "; ".join(parts) + ". "
               + ("It moves " + " and ".join(moves) + "." if moves else ""))
    table = Table(("case", "max von Mises / p_0", "vs smooth", "its depth / a_H", "depth shift / a_H",
                   "its distance from the axis / a_H", "max shear / p_0", "vs smooth", "p_max / p_0"), tuple(rows),
                  caption="Largest von Mises stress and largest maximum shear (s1 - s3)/2 over the body (every "
                          f"candidate node, {smooth.z.size} depths from 0 to {smooth.z.max() / res.a:g} a_H, refined "
                          f"in depth by a parabola), nu = {nu:g}; changes against the smooth contact. The peak "
                          "contact pressure p_max is repeated for comparison.")
    return Section("Subsurface stresses of the layer laws", kind="results", text=(
        "The paper's conclusion is that the interface layer changes the contact pressure and, through it, the "
        "stress-strain state of the bodies. What matters for the strength of a heavily loaded part is the stress "
        "below the surface, where it yields first: here the same force is applied with each layer law and the "
        "largest von Mises stress is compared with that of the smooth contact.", summary), items=(
        Figure(path, "Von Mises stress on the axis below the centre of the contact against the depth, for every law "
                     f"of Fig. 5 at the same force: [stress] of the runs (bem.subsurface_stress of the Newton "
                     f"solutions, a_H/c = {res.nodes_per_radius}), nu = {nu:g}, frictionless; circles: the maxima "
                     "over the whole field where they lie on the axis."), table))


def _iterations(res, work):
    from ..figures.iterations import plot_convergence, plot_iteration_profiles
    from ..figures.surfaces import plot_pressure_surfaces

    it, p0, a, al = res.iterations, res.p0, res.a, ALPHA_A_ITERATIONS
    er_vc, root_vc, aug = (it[k] for k in ("elastic-rigid, variable compliance", "root, variable compliance",
                                           "elastic-rigid, augmented gap"))
    f6 = plot_iteration_profiles(er_vc, work / "fig06_iterations_elastic_rigid.png", p0=p0, a=a,
                                 title=rf"elastic-rigid, $\alpha_a$ = {al}: iterates of the variable compliance "
                                       "method (paper Fig. 6)")
    runs = [(k.split(", ")[1] + (f" (omega = {AG_RELAXATION})" if "augmented" in k else ""), v)
            for k, v in it.items() if k.startswith("elastic-rigid")]
    f8 = plot_convergence(runs, work / "fig08_convergence.png", p0=p0, tol=RTOL,
                          title=rf"elastic-rigid, $\alpha_a$ = {al}: max. pressure per iteration (paper Fig. 8)")
    f10 = plot_iteration_profiles(root_vc, work / "fig10_iterations_root.png", p0=p0, a=a,
                                  title="root law: iterates of the variable compliance method (paper Fig. 10)")
    hist = root_vc.history["p"]
    panels = [(f"k = {k}" + (" (final)" if k == len(hist) else ""), (root_vc.x, root_vc.y, hist[k - 1]))
              for k in sorted({1, 2, min(4, len(hist)), len(hist)})]
    f11 = plot_pressure_surfaces(panels, work / "fig11_root_iterations_3d.png", p0=p0, a=a,
                                 title="root law: iterates of the variable compliance method (paper Fig. 11)")
    return Section("Iterations of the methods (Fig. 6, 8, 10, 11)", kind="iterations", text=(
        "The paper's two iterative methods start from the smooth-body solution (k = 1) and approach the layered "
        f"solution step by step. {_augmented_gap_summary(res)} With the relaxation omega = {AG_RELAXATION} "
        "(p_(k+1) = (1 - omega) p_k + omega p_QP) it " + ("converges" if aug.converged else "does not converge either")
        + f" on the elastic-rigid law with alpha_a = {al} ({aug.iterations} iterations). The Newton method on the "
        "generalised functional (eq. 15, the toolkit's default) needs a few steps from p = 0.",), items=(
        Figure(f6, "Axial-section pressure of the iterates k of the variable compliance method (eq. 21-23) for the "
                   f"elastic-rigid law, alpha_a = {al} (analogue of Fig. 6); the colour gives k, the dashed line the "
                   f"final state. {_how(er_vc, res)}; {er_vc.iterations} iterations."),
        Figure(f8, "Maximum pressure (top) and KKT residual of eq. 14 (bottom) against the iteration for the "
                   f"elastic-rigid law, alpha_a = {al} (analogue of Fig. 8): variable compliance, augmented gap with "
                   f"relaxation omega = {AG_RELAXATION}, and Newton started from p = 0 (no nested iteration). Same "
                   f"lattice as above (a_H/c = {res.nodes_per_radius})."),
        Figure(f10, "Axial-section pressure of the iterates of the variable compliance method for the root law "
                    f"(analogue of Fig. 10). {_how(root_vc, res)}; {root_vc.iterations} iterations."),
        Figure(f11, "The same iterates as isometric pressure surfaces over the contact (analogue of Fig. 11), one "
                    "colour scale; the black line is the axial section y = 0.")))


def _sweeps(res, work):
    from ..figures.profiles import section_of
    from ..figures.surfaces import plot_pressure_surfaces
    from ..figures.sweeps import plot_sweep, plot_transition_line, transition_radius

    p0, a, p_lin, alpha_a = res.p0, res.a, res.p_lin, res.laws["elastic-rigid"].p_cr / res.p_lin
    sec = {al: section_of(r) for al, r in res.sweep_a}
    fa = plot_sweep([(al, *sec[al]) for al, _ in res.sweep_a], work / "fig05_sweep_alpha_a.png", p0=p0, a=a,
                    name=r"$\alpha_a$", title=r"elastic-rigid law: threshold $\alpha_a = p_{cr}\,/\,p_{max}^{\lambda}$")
    r_tr = [r.contact_radius if al == 0 else transition_radius(*sec[al], al * p_lin) for al, r in res.sweep_a]
    r_c = [r.contact_radius for _, r in res.sweep_a]
    alphas = [al for al, _ in res.sweep_a]
    f7 = plot_transition_line(alphas, r_tr, work / "fig07_transition_line.png", a=a, r_contact=r_c,
                              title="transition between the rigid and elastic branches (paper Fig. 7)")
    pick = alphas if res.quick else [0.0, 0.3, 0.5, 0.7, 0.9, 1.0]
    f9 = plot_pressure_surfaces([(rf"$\alpha_a$ = {al:g}", r) for al, r in res.sweep_a
                                 if any(abs(al - q) < 1e-9 for q in pick)], work / "fig09_alpha_a_3d.png", p0=p0, a=a,
                                title=r"elastic-rigid law: pressure over the contact as $\alpha_a$ varies "
                                      "(paper Fig. 9)")
    fb = plot_sweep([(ab, *section_of(r)) for _, ab, r in res.sweep_b], work / "fig10_sweep_alpha_b.png",
                    p0=p0, a=a,
                    name=r"$\alpha_b = p_{max}^{root} / p_{max}^{\lambda}$", cmap="viridis",
                    title=r"root law $w = \lambda_b \sqrt{p}$: varying $\lambda_b$",
                    extra=[("linear Winkler", *section_of(res.base["linear Winkler"]), {"color": "black", "ls": "--"})])
    fc = plot_sweep([(t, *section_of(r)) for t, r in res.sweep_c], work / "fig05_sweep_alpha_c.png", p0=p0, a=a,
                    name=r"$\alpha_c = \arctan(\lambda_2/\lambda_1)$ [rad]", cmap="cividis",
                    title=r"bilinear law: angle $\alpha_c$ of the second branch")
    how = f"Newton (eq. 15), a_H/c = {res.nodes_per_radius}, KKT tolerance {RTOL:.0e}"
    t_a = Table(("alpha_a", "p_max / p_0", "r_transition / a_H", "r_c / a_H"),
                tuple((al, r.p_max / p0, rt / a, rc / a) for (al, r), rt, rc in zip(res.sweep_a, r_tr, r_c)),
                caption="Elastic-rigid sweep: transition radius (p crosses p_cr on the axial section, linear "
                        "interpolation between nodes; at alpha_a = 0 the whole contact is rigid) and contact radius "
                        "r_c = sqrt(A/pi).")
    t_b = Table(("lam_b / (lam sqrt(p_max^lambda))", "alpha_b", "p_max / p_0", "r_c / a_H"),
                tuple((f, ab, r.p_max / p0, r.contact_radius / a) for f, ab, r in res.sweep_b),
                caption="Root-law sweep.")
    t_c = Table(("alpha_c [rad]", "lam2 / lam1", "p_max / p_0", "r_c / a_H"),
                tuple((t, math.tan(t), r.p_max / p0, r.contact_radius / a) for t, r in res.sweep_c),
                caption="Bilinear sweep (alpha_c = 0 is the elastic-rigid law, pi/4 the linear layer).")
    return Section("Parameter sweeps alpha_a, alpha_b, alpha_c (Fig. 5, 7, 9)", kind="sweeps", text=(
        "alpha_a moves the pressure continuously from the smooth-body distribution (alpha_a = 0) to the linear-layer "
        "one (alpha_a = 1); the rigid region I shrinks as alpha_a grows (Fig. 7). The root law gives a smoother decay "
        "towards the edge of a wider contact than the linear layer; the bilinear law tends to the elastic-rigid one "
        "as alpha_c -> 0 and flattens and widens as alpha_c grows.",), items=(
        Figure(fa, f"Axial-section pressure for alpha_a from 0 (smooth) to 1 (linear layer). {how}."), t_a,
        Figure(f7, "Radius of the transition p = p_cr between region I (rigid branch) and region II (elastic branch), "
                   "and the contact edge, against alpha_a (analogue of Fig. 7); from the sweep above."),
        Figure(f9, "Isometric pressure surfaces for several alpha_a (analogue of Fig. 9); one colour scale, height "
                   f"proportional to p / p_0; black line: the axial section. {how}."),
        Figure(fb, "Root law for several coefficients lam_b; the colour gives alpha_b = p_max^root / p_max^lambda; "
                   f"dashed: the linear layer. {how}."), t_b,
        Figure(fc, f"Bilinear law (p* = alpha_a p_max^lambda, alpha_a = {alpha_a:g}) for several alpha_c. {how}."),
        t_c))


def _augmented_gap_summary(res):
    """What the stability table says about the augmented gap method as printed (omega = 1)."""
    rows = [r for r in res.stability if r["method"].startswith("augmented gap, omega = 1 ")]
    failed = [r["law"] for r in rows if r["status"] != "converged"]
    if not rows:
        return ""
    if not failed:
        return "The augmented gap method as printed in the paper (omega = 1) converges on every law tested."
    return (f"The augmented gap method as printed in the paper (omega = 1) does not converge for {len(failed)} of "
            f"{len(rows)} laws ({', '.join(failed)}; see the stability table): with lam = {res.lam_over_cnn:.3g} C_nn "
            "the layer is much softer than the bodies on the scale of one node, and the fixed-point map "
            "h_bar = h + w(p_k) is not a contraction.")


def expected_stalls(res):
    """The notes of a paper report run on the augmented gap runs of the stability table that did not converge.

    Their solver warnings are held back while they run; one note says what they were and that
    they are the documented behaviour of the method on this problem (empty when all converged).
    """
    rows = [r for r in res.stability if r["method"].startswith("augmented gap") and r["status"] != "converged"]
    if not rows:
        return ()
    runs = "; ".join(f"{r['law']}, {r['method'].removeprefix('augmented gap, ')}: {r['status']} after "
                     f"{r['iterations']} iterations" for r in rows)
    total = sum(r["method"].startswith("augmented gap") for r in res.stability)
    anchor = Section("Stability of the methods", kind="stability").anchor
    return (f"the augmented gap method did not converge in {len(rows)} of its {total} runs of the stability table "
            f"({runs}). This is the expected, documented behaviour of the augmented gap method on this problem "
            "(a layer much softer than the bodies on the scale of one node: the fixed-point map is not a "
            "contraction), not a failure of the report; the report discusses it in the section \"Stability of the "
            f"methods\" (report.html#{anchor}) and in the iteration histories.",)


def _stability(res):
    rows = tuple((r["law"], r["method"], r["status"], r["iterations"], r["p_max/p0"], r["kkt_residual"],
                  r["wall_time_s"], r["message"] if len(r["message"]) <= 90
                  else r["message"][: r["message"].rfind(" ", 0, 90)] + " ...") for r in res.stability)
    table = Table(("law", "method", "status", "iterations", "p_max / p_0", "KKT residual", "time [s]", "message"),
                  rows, status_column="status",
                  caption=f"Every method on the same problems (a_H/c = {res.nodes_per_radius}, tolerance {RTOL:.0e}); "
                          "green: converged, amber: stalled, red: diverged or failed.")
    return Section("Stability of the methods", kind="stability", items=(table,), text=(
        "A method that does not reach its tolerance says so; its result is never used as an answer. "
        + _augmented_gap_summary(res),))


def _validation(res, work):
    from ..figures.precision import plot_work_precision, time_spread

    items, rows = [], []
    for case, outcome in res.validation.items():
        folder = work / f"validation_{_KEYS[case]}"
        folder.mkdir(exist_ok=True)
        items += run_figures.profiles(results_of(outcome, units="dimensionless", hertz_peak="p_0"), folder)
        b, f = outcome.bem, outcome.fem
        rows.append((case, b.p_max / res.p0, f.p_max / res.p0, f"{(b.p_max - f.p_max) / f.p_max:+.2%}",
                     b.contact_radius / res.a, f.edge_radius / res.a, b.approach / res.approach,
                     f.approach / res.approach, b.wall_time_s, f.wall_time_s,
                     f.status if b.converged else b.status))
    items.append(Table(("case", "BEM p_max / p_0", "FEM p_max / p_0", "rel. difference", "BEM r_c / a_H",
                        "FEM r_edge / a_H", "BEM delta / delta_H", "FEM delta / delta_H", "BEM time [s]", "FEM time [s]",
                        "status"), tuple(rows), status_column="status",
                       caption="BEM against FEM (Hertz: p_max / p_0 = 1, r_c / a_H = 1, delta / delta_H = 1). BEM r_c "
                               "= sqrt(A/pi) from the loaded nodes; FEM r_edge: the edge of the loaded zone, "
                               "interpolated between the interface nodes."))
    smooth = results_of(res.validation["smooth"], units="dimensionless", hertz_peak="p_0")
    items.append(run_figures.fem_von_mises(smooth, work / "validation_smooth"))
    wp = plot_work_precision(res.work_precision, work / "fig_work_precision.png",
                             error_label=r"peak-pressure error $|p_{max} - p_0|\,/\,p_0$",
                             title="Hertz problem: error against run time")
    items += [Figure(wp, "Work-precision of the two solvers on the Hertz problem: error of the peak pressure against "
                         "wall-clock time (2 shared cores, indicative), one marker per resolution at the median of its "
                         "repeated runs, the bar spanning the fastest to the slowest; dotted lines at 1 % and 0.1 %."),
              Table(("solver", "method", "resolution", "N (nodes / DOFs)", "error", "median time [s]", "fastest [s]",
                     "slowest [s]", "runs"),
                    tuple((r["solver"], r["method"], r["resolution"], r["N"], r["error"], *time_spread(r),
                           len(r.get("wall_times_s") or ()) or 1) for r in res.work_precision),
                    caption="Resolution study of the smooth (Hertz) problem.")]
    return Section("Validation: analytic solution and FEM reference", kind="fem", items=tuple(items), text=(
        "The paper validates its solver against analytic theory and ANSYS; here the BEM is compared with Hertz's "
        "solution and with the toolkit's own axisymmetric FEM reference (scikit-fem), which carries the same layer "
        "law through the interface. The profiles are those of a run's report of each case run with [fem] and, for "
        "the smooth case, [analytic] kind = \"hertz\"; the von Mises stress of the FEM reference (nu = 0.3) peaks "
        "at about 0.62 p_0 at depth 0.48 a_H below the centre of the smooth contact.",))


def paper_sections(res, work):
    """The report sections of :class:`validation.studies.paper_problem.PaperRuns`; figures go to ``work``."""
    work = Path(work)
    sections = [_problem(res, work), _distributions(res, work), _stresses(res, work), _iterations(res, work),
                _sweeps(res, work), _stability(res)]
    return sections + ([_validation(res, work)] if res.validation else [])


def report_paper_problem(out_dir, *, quick=False, fem=True, fmt="png", progress=None):
    """Run the paper's test problem and write its report to ``out_dir``.

    Parameters
    ----------
    out_dir : path-like
        Report directory (``report.html``, ``report.md``, ``figures/``), written whole or not at all.
    quick : bool
        Coarse lattice (a_H/c = 8) and short sweeps: a preview in a fraction of the full report's time
        (measured times: docs/performance.md, "Studies and reports").
    fem : bool
        Include the FEM reference and the resolution study.
    fmt : {"png", "svg", "pdf"}
        Figure files (:func:`validation.report.render.style.figure_format`).
    progress : callable, optional
        ``progress(stage, done, total)`` at the start of each stage (:data:`STAGES`, the FEM
        stage only with ``fem``) and ``progress("done", total, total)`` at the end.

    Returns
    -------
    validation.report.render.BuiltReport
        With ``notes``: :func:`expected_stalls` (the augmented gap runs that stalled, the
        method's expected behaviour on this problem; their solver warnings are held back).
    """
    notify = Progress([s for s in STAGES if fem or s != SOLVE_STAGES[3]], progress)
    res = run_paper_problem(quick=quick, fem=fem, progress=notify)
    subtitle = (f"Steel paraboloids (built-in scenes paper_*), lam = {res.lam:.4g} m/Pa; BEM lattice "
                f"a_H/c = {res.nodes_per_radius}{' (coarse preview)' if quick else ''}; "
                f"computed in {res.wall_time_s:.0f} s.")
    title = f"{TITLE} ({PREVIEW})" if quick else TITLE
    built = draw_and_build(lambda work: paper_sections(res, work), out_dir, title=title, subtitle=subtitle, fmt=fmt,
                           notify=notify)
    return dataclasses.replace(built, notes=expected_stalls(res))
