"""The report of the paper's test problem: analogues of Fig. 4-11 and the validation.

:func:`report_paper_problem` solves the problem (:mod:`validation.report.paper`) and
writes the report with :func:`validation.report.build.build_report`.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np

from . import figures_3d as f3d
from . import figures_iterations as fit
from . import figures_profiles as fpr
from . import figures_sweeps as fsw
from . import figures_validation as fva
from .build import Progress, draw_and_build
from .figures_fem import plot_von_mises
from .paper import AG_RELAXATION, SOLVE_STAGES, solve_paper_problem
from .paper_stress import stress_section
from .sections import Figure, Section, Table, problem_section
from .style import method_label

__all__ = ["report_paper_problem", "paper_sections", "STAGES"]

log = logging.getLogger(__name__)

TITLE = "contactlab: the paper's test problem - paraboloids with a nonlinear interface layer"
#: the stages of :func:`report_paper_problem`, as reported to its ``progress``
STAGES = (*SOLVE_STAGES, "figures", "writing")


def _method(result):
    """The method that actually ran: quadratic problems go to the Kalker QP whatever was asked."""
    layer = result.layer
    if result.method in ("newton", "kalker") and (layer is None or layer.is_linear):
        return method_label("kalker")
    return method_label(result.method)


def _clip(text, n=90):
    return text if len(text) <= n else text[: text.rfind(" ", 0, n)] + " ..."


def _how(result, pb):
    n = round(pb.a / result.step)
    name = _method(result)
    return (f"{name[0].upper()}{name[1:]}; lattice step c = {result.step:.4g} (a_H/c = {n}), "
            f"{result.p.size} candidate nodes, {int(np.count_nonzero(result.p > 0))} in contact; "
            f"KKT tolerance {pb.rtol:.0e}")


def _row(label, r, pb):
    status = "converged" if r.converged else "not converged"
    return (label, _method(r), r.p_max / pb.p0, r.contact_radius / pb.a, r.approach / pb.hertz.approach,
            r.iterations, r.kkt_residual, r.wall_time_s, status)


_RESULT_COLUMNS = ("case", "method", "p_max / p0", "r_c / a_H", "approach / delta_H", "iterations",
                   "KKT residual", "time [s]", "status")


def _problem(res, work):
    pb = res.problem
    p_lin = res.p_lin
    laws = [(k, v) for k, v in res.laws.items()]
    path = fpr.plot_layer_laws(laws, work / "fig04_layer_laws.png", p_max=1.1 * pb.p0,
                               marks=[(r"$p_{cr} = \alpha_a p_{max}^{\lambda}$", pb.alpha_a * p_lin)],
                               title="interface layer laws $w(p)$ (paper Fig. 4 b-d)")
    text = (
        "Two elastic paraboloids (effective radius R) pressed together by the force P, with a thin interface "
        "layer between them whose closure w(p) depends nonlinearly on the contact pressure p (paper section 6, "
        "Fig. 4). Normalised units: R = E* = P = 1, so the smooth (Hertz) contact has radius "
        f"a_H = {pb.a:.4f}, peak pressure p0 = {pb.p0:.4f} and approach delta_H = {pb.hertz.approach:.4f}; all "
        "pressures below are divided by p0 and all lengths by a_H.",
        f"The linear (Winkler) layer has lam = {pb.lam_factor:g} C_nn = {pb.lam:.4f}, where C_nn = c/(pi E*) "
        f"w_t(0,0) = {pb.C_nn:.5f} is the diagonal influence coefficient (eq. 6) of the lattice step "
        f"c = a_H/{pb.lam_nodes_per_radius}. Its peak pressure p_max^lambda = {p_lin:.4f} = "
        f"{p_lin / pb.p0:.4f} p0 scales the other laws: elastic-rigid w = lam min(p, p_cr) with "
        f"p_cr = alpha_a p_max^lambda, alpha_a = {pb.alpha_a}; root w = lam_b sqrt(p) with "
        "lam_b = lam sqrt(p_max^lambda) (root and linear laws close equally at p_max^lambda); bilinear with "
        f"slope lam up to p* = alpha_a p_max^lambda and lam tan(alpha_c) beyond, alpha_c = {pb.alpha_c:.4f} rad.",
    )
    fig = Figure(path, "The layer laws w(p) of the test problem (analogue of the paper's Fig. 4 b-d), drawn "
                       "from the bem.layers objects used by the solver; the dotted line marks p_cr = p*.")
    units = {"length": "R", "pressure": "E*", "force": "P"}
    return problem_section(gap=pb.gap, materials={"E_star": pb.E_star}, load={"force": pb.force}, units=units,
                           layers=laws, figure=fig, text=text)


def _distributions(res, work):
    pb = res.problem
    b = res.base
    curves = [(k, v) for k, v in b.items()]
    path = fpr.plot_pressure_profiles(curves, work / "fig05_pressure_profiles.png", p0=pb.p0, a=pb.a, hertz=True,
                                      title="contact pressure in the axial section (paper Fig. 5)")
    er = b["elastic-rigid"]
    map_path = f3d.plot_contact_map(er, work / "fig05_contact_map_elastic_rigid.png", p0=pb.p0, a=pb.a,
                                    levels=[(r"$p = p_{cr}$ (region I | II)", res.laws["elastic-rigid"].p_cr)],
                                    title=rf"elastic-rigid layer, $\alpha_a$ = {pb.alpha_a}")
    table = Table(_RESULT_COLUMNS, tuple(_row(k, v, pb) for k, v in b.items()), status_column="status",
                  caption="Key numbers of the Fig. 5 cases (r_c = sqrt(A/pi) from the loaded node area; "
                          "approach relative to the Hertz approach delta_H).")
    text = ("All laws solved at the same load; the layer spreads the pressure over a wider contact and lowers "
            "the peak. The elastic-rigid law shows two regions: region I near the centre, where the layer is on "
            "its rigid branch (p >= p_cr) and the pressure has the shape of a smooth-body distribution, and "
            "region II outside, where the layer is elastic; the kink between them is the transition zone of "
            "the paper's Fig. 5-7.",)
    return Section("Pressure distributions for the layer laws (Fig. 5)", kind="results", text=text, items=(
        Figure(path, "Contact pressure in the axial section y = 0 for every law (analogue of the paper's Fig. 5), "
                     "with Hertz's closed form as the grey band. " + _how(b["elastic-rigid"], pb)
                     + ". Dashed with markers: the same bilinear problem solved by the paper's variable compliance "
                     "method; it coincides with the Newton solution."),
        Figure(map_path, "Pressure over the contact plane for the elastic-rigid law: the dotted contour p = p_cr "
                         "separates region I (rigid branch, inside) from region II (elastic branch). "
                         + _how(er, pb) + "."),
        table))


def _iterations(res, work):
    pb = res.problem
    it = res.iterations
    er_vc, root_vc = it["elastic-rigid, variable compliance"], it["root, variable compliance"]
    f6 = fit.plot_iteration_profiles(er_vc, work / "fig06_iterations_elastic_rigid.png", p0=pb.p0, a=pb.a,
                                     title=rf"elastic-rigid, $\alpha_a$ = {pb.alpha_a_iterations}: iterates of the "
                                           "variable compliance method (paper Fig. 6)")
    runs = [(k.split(", ")[1] + (" (omega = 0.08)" if "augmented" in k else ""), v)
            for k, v in it.items() if k.startswith("elastic-rigid")]
    f8 = fit.plot_convergence(runs, work / "fig08_convergence.png", p0=pb.p0, tol=pb.rtol,
                              title=rf"elastic-rigid, $\alpha_a$ = {pb.alpha_a_iterations}: max. pressure per "
                                    "iteration (paper Fig. 8)")
    f10 = fit.plot_iteration_profiles(root_vc, work / "fig10_iterations_root.png", p0=pb.p0, a=pb.a,
                                      title="root law: iterates of the variable compliance method (paper Fig. 10)")
    hist = root_vc.history["p"]
    ks = sorted({1, 2, min(4, len(hist)), len(hist)})
    panels = [(f"k = {k}" + (" (final)" if k == len(hist) else ""), (root_vc.x, root_vc.y, hist[k - 1]))
              for k in ks]
    f11 = f3d.plot_pressure_surfaces(panels, work / "fig11_root_iterations_3d.png", p0=pb.p0, a=pb.a,
                                     title="root law: iterates of the variable compliance method (paper Fig. 11)")
    aug = it["elastic-rigid, augmented gap"]
    text = (
        "The paper's two iterative methods start from the smooth-body solution (k = 1) and approach the layered "
        f"solution step by step. {_augmented_gap_summary(res)} With the relaxation omega = {AG_RELAXATION} "
        "(p_(k+1) = (1 - omega) p_k + omega p_QP) it "
        + ("converges" if aug.converged else "does not converge either")
        + f" on the elastic-rigid law with alpha_a = {pb.alpha_a_iterations} ({aug.iterations} iterations). The "
        "Newton method on the generalised functional (eq. 15, the toolkit's default) needs a few steps from "
        "p = 0.",)
    return Section("Iterations of the methods (Fig. 6, 8, 10, 11)", kind="iterations", text=text, items=(
        Figure(f6, "Axial-section pressure of the iterates k of the variable compliance method (eq. 21-23) for "
                   f"the elastic-rigid law, alpha_a = {pb.alpha_a_iterations} (analogue of Fig. 6); the colour "
                   f"gives k, the dashed line the final state. {_how(er_vc, pb)}; {er_vc.iterations} iterations."),
        Figure(f8, f"Maximum pressure (top) and KKT residual of eq. 14 (bottom) against the iteration for the "
                   f"elastic-rigid law, alpha_a = {pb.alpha_a_iterations} (analogue of Fig. 8): variable compliance, "
                   f"augmented gap with relaxation omega = {AG_RELAXATION}, and Newton started from p = 0 (no nested "
                   f"iteration). Same lattice as above (a_H/c = {pb.nodes_per_radius})."),
        Figure(f10, "Axial-section pressure of the iterates of the variable compliance method for the root law "
                    f"(analogue of Fig. 10). {_how(root_vc, pb)}; {root_vc.iterations} iterations."),
        Figure(f11, "The same iterates as isometric pressure surfaces over the contact (analogue of Fig. 11), "
                    "one colour scale; the black line is the axial section y = 0.")))


def _sweeps(res, work):
    pb = res.problem
    p_lin = res.p_lin
    sec = {al: fpr.section_of(r) for al, r in res.sweep_a}
    curves = [(al, *sec[al]) for al, _ in res.sweep_a]
    fa = fsw.plot_sweep(curves, work / "fig05_sweep_alpha_a.png", p0=pb.p0, a=pb.a, name=r"$\alpha_a$",
                        title=r"elastic-rigid law: threshold $\alpha_a = p_{cr}\,/\,p_{max}^{\lambda}$")
    r_tr = [r.contact_radius if al == 0 else fsw.transition_radius(*sec[al], al * p_lin) for al, r in res.sweep_a]
    r_c = [r.contact_radius for _, r in res.sweep_a]
    alphas = [al for al, _ in res.sweep_a]
    f7 = fsw.plot_transition_line(alphas, r_tr, work / "fig07_transition_line.png", a=pb.a, r_contact=r_c,
                                  title="transition between the rigid and elastic branches (paper Fig. 7)")
    pick = [0.0, 0.3, 0.5, 0.7, 0.9, 1.0] if not res.quick else alphas
    panels = [(rf"$\alpha_a$ = {al:g}", r) for al, r in res.sweep_a if any(abs(al - q) < 1e-9 for q in pick)]
    f9 = f3d.plot_pressure_surfaces(panels, work / "fig09_alpha_a_3d.png", p0=pb.p0, a=pb.a,
                                    title=r"elastic-rigid law: pressure over the contact as $\alpha_a$ varies "
                                          "(paper Fig. 9)")
    lin_x, lin_p = fpr.section_of(res.base["linear Winkler"])
    fb = fsw.plot_sweep([(ab, *fpr.section_of(r)) for _, ab, r in res.sweep_b], work / "fig10_sweep_alpha_b.png",
                        p0=pb.p0, a=pb.a, name=r"$\alpha_b = p_{max}^{root} / p_{max}^{\lambda}$",
                        title=r"root law $w = \lambda_b \sqrt{p}$: varying $\lambda_b$", cmap="viridis",
                        extra=[("linear Winkler", lin_x, lin_p, {"color": "black", "ls": "--"})])
    fc = fsw.plot_sweep([(t, *fpr.section_of(r)) for t, r in res.sweep_c], work / "fig05_sweep_alpha_c.png",
                        p0=pb.p0, a=pb.a, name=r"$\alpha_c = \arctan(\lambda_2/\lambda_1)$ [rad]",
                        title=r"bilinear law: angle $\alpha_c$ of the second branch", cmap="cividis")
    how = f"Newton (eq. 15), a_H/c = {pb.nodes_per_radius}, KKT tolerance {pb.rtol:.0e}"
    t_a = Table(("alpha_a", "p_max / p0", "r_transition / a_H", "r_c / a_H"),
                tuple((al, r.p_max / pb.p0, rt / pb.a, rc / pb.a) for (al, r), rt, rc in zip(res.sweep_a, r_tr, r_c)),
                caption="Elastic-rigid sweep: transition radius (p crosses p_cr on the axial section, linear "
                        "interpolation between nodes; at alpha_a = 0 the whole contact is rigid) and contact "
                        "radius r_c = sqrt(A/pi).")
    t_b = Table(("lam_b / (lam sqrt(p_max^lambda))", "alpha_b", "p_max / p0", "r_c / a_H"),
                tuple((f, ab, r.p_max / pb.p0, r.contact_radius / pb.a) for f, ab, r in res.sweep_b),
                caption="Root-law sweep.")
    t_c = Table(("alpha_c [rad]", "lam2 / lam1", "p_max / p0", "r_c / a_H"),
                tuple((t, math.tan(t), r.p_max / pb.p0, r.contact_radius / pb.a) for t, r in res.sweep_c),
                caption="Bilinear sweep (alpha_c = 0 is the elastic-rigid law, pi/4 the linear layer).")
    return Section("Parameter sweeps alpha_a, alpha_b, alpha_c (Fig. 5, 7, 9)", kind="sweeps", text=(
        "alpha_a moves the pressure continuously from the smooth-body distribution (alpha_a = 0) to the "
        "linear-layer one (alpha_a = 1); the rigid region I shrinks as alpha_a grows (Fig. 7). The root law "
        "gives a smoother decay towards the edge of a wider contact than the linear layer; the bilinear law "
        "tends to the elastic-rigid one as alpha_c -> 0 and flattens and widens as alpha_c grows.",), items=(
        Figure(fa, f"Axial-section pressure for alpha_a from 0 (smooth) to 1 (linear layer). {how}."), t_a,
        Figure(f7, "Radius of the transition p = p_cr between region I (rigid branch) and region II (elastic "
                   "branch), and the contact edge, against alpha_a (analogue of Fig. 7); from the sweep above."),
        Figure(f9, "Isometric pressure surfaces for several alpha_a (analogue of Fig. 9); one colour scale, "
                   f"height proportional to p / p0; black line: the axial section. {how}."),
        Figure(fb, "Root law for several coefficients lam_b; the colour gives alpha_b = p_max^root / "
                   f"p_max^lambda; dashed: the linear layer. {how}."), t_b,
        Figure(fc, f"Bilinear law (p* = alpha_a p_max^lambda, alpha_a = {pb.alpha_a}) for several alpha_c. {how}."),
        t_c))


def _stability(res):
    rows = tuple((r["law"], r["method"], r["status"], r["iterations"], r["p_max/p0"], r["kkt_residual"],
                  r["wall_time_s"], _clip(r["message"])) for r in res.stability)
    table = Table(("law", "method", "status", "iterations", "p_max / p0", "KKT residual", "time [s]", "message"),
                  rows, status_column="status",
                  caption=f"Every method on the same problems (a_H/c = {res.problem.nodes_per_radius}, tolerance "
                          f"{res.problem.rtol:.0e}); green: converged, amber: stalled, red: diverged or failed.")
    return Section("Stability of the methods", kind="stability", items=(table,), text=(
        "A method that does not reach its tolerance says so; its result is never used as an answer. "
        + _augmented_gap_summary(res),))


def _augmented_gap_summary(res):
    """What the stability table says about the augmented gap method as printed (omega = 1)."""
    rows = [r for r in res.stability if r["method"].startswith("augmented gap, omega = 1 ")]
    failed = [r["law"] for r in rows if r["status"] != "converged"]
    if not rows:
        return ""
    if not failed:
        return "The augmented gap method as printed in the paper (omega = 1) converges on every law tested."
    return (f"The augmented gap method as printed in the paper (omega = 1) does not converge for {len(failed)} of "
            f"{len(rows)} laws ({', '.join(failed)}; see the stability table): with lam = {res.problem.lam_factor:g} "
            "C_nn the layer is much softer than the bodies on the scale of one node, and the fixed-point map "
            "h_bar = h + w(p_k) is not a contraction.")


def _validation(res, work):
    pb = res.problem
    items, rows = [], []
    bem_s, fem_s = res.fem["smooth"]
    curves = [("BEM", bem_s.x[bem_s.y == 0], bem_s.p[bem_s.y == 0], "bem"), ("FEM", fem_s.r, fem_s.p, "fem")]
    path = fva.plot_profile_comparison(curves, work / "fig_validation_hertz.png", p0=pb.p0, a=pb.a,
                                       reference=("Hertz (analytic)", pb.hertz.pressure),
                                       title="smooth paraboloids: BEM and FEM against Hertz")
    n_fem = fem_s.mesh.get("n_contact")
    items.append(Figure(path, f"Smooth contact: BEM ({_method(bem_s)}, a_H/c = "
                              f"{pb.nodes_per_radius}, {bem_s.p.size} nodes) and axisymmetric FEM (quadratic "
                              f"triangles, {n_fem} elements across the estimated contact radius, {fem_s.n_dofs} DOFs) "
                              "against Hertz's closed form; lower panel: the error at each solver's nodes."))
    for label in ("linear Winkler", "elastic-rigid", "root"):
        b, f = res.fem[label]
        name = label.split()[0].replace("-", "_")
        curves = [("BEM", b.x[b.y == 0], b.p[b.y == 0], "bem")]
        path = fva.plot_profile_comparison(curves, work / f"fig_validation_{name}.png", p0=pb.p0, a=pb.a,
                                           reference=("FEM reference", f.r, f.p),
                                           title=f"{label} layer: BEM against the FEM reference")
        items.append(Figure(path, f"{label.capitalize()} layer: BEM ({_method(b)}, a_H/c = "
                                  f"{pb.nodes_per_radius}) against the FEM reference carrying the same law as a "
                                  f"penalty ({n_fem} elements across the contact); error relative to p0 at the BEM "
                                  "nodes (FEM interpolated linearly)."))
    for label, (b, f) in res.fem.items():
        rows.append((label, b.p_max / pb.p0, f.p_max / pb.p0, f"{(b.p_max - f.p_max) / f.p_max:+.2%}",
                     b.contact_radius / pb.a,
                     f.contact_radius / pb.a, b.approach / pb.hertz.approach, f.approach / pb.hertz.approach,
                     b.wall_time_s, f.wall_time_s, "converged" if (b.converged and f.converged) else "failed"))
    table = Table(("case", "BEM p_max / p0", "FEM p_max / p0", "rel. difference", "BEM r_c / a_H", "FEM r_c / a_H",
                   "BEM delta / delta_H", "FEM delta / delta_H", "BEM time [s]", "FEM time [s]", "status"),
                  tuple(rows), status_column="status",
                  caption="BEM against FEM (Hertz: p_max / p0 = 1, r_c / a_H = 1, delta / delta_H = 1). BEM r_c = "
                          "sqrt(A/pi) from the loaded nodes; FEM r_c from the closure crossing zero.")
    vm = plot_von_mises(fem_s, work / "fig_fem_von_mises.png", a=pb.a, p0=pb.p0,
                        title="FEM reference, smooth contact: von Mises stress")
    items += [table, Figure(vm, "Von Mises stress of the FEM reference for the smooth contact (nu = 0.3) in the "
                                "axial section, both bodies; the classical maximum 0.62 p0 at depth 0.48 a_H below "
                                "the centre of the contact is visible.")]
    wp = fva.plot_work_precision(res.work_precision, work / "fig_work_precision.png",
                                 error_label=r"peak-pressure error $|p_{max} - p_0|\,/\,p_0$",
                                 title="Hertz problem: error against run time")
    wp_table = Table(("solver", "method", "resolution", "N (nodes / DOFs)", "error", "median time [s]",
                      "fastest [s]", "slowest [s]", "runs"),
                     tuple((r["solver"], r["method"], r["resolution"], r["N"], r["error"], *fva.time_spread(r),
                            len(r.get("wall_times_s") or ()) or 1) for r in res.work_precision),
                     caption="Resolution study of the smooth (Hertz) problem.")
    items += [Figure(wp, "Work-precision of the two solvers on the Hertz problem: error of the peak pressure "
                         "against wall-clock time (2 shared cores, indicative), one marker per resolution at the "
                         "median of its repeated runs, the bar spanning the fastest to the slowest; dotted "
                         "lines at 1 % and 0.1 %."), wp_table]
    return Section("Validation: analytic solution and FEM reference", kind="fem", items=tuple(items), text=(
        "The paper validates its solver against analytic theory and ANSYS; here the BEM is compared with "
        "Hertz's solution and with the toolkit's own axisymmetric FEM reference (scikit-fem), which carries the "
        "same layer law through the interface.",))


def paper_sections(res, work):
    """The report sections of solved :class:`validation.report.paper.PaperResults`; figures go to ``work``."""
    work = Path(work)
    sections = [_problem(res, work), _distributions(res, work)]
    stress = stress_section(res, work)
    if stress is not None:
        sections.append(stress)
    sections += [_iterations(res, work), _sweeps(res, work), _stability(res)]
    if res.fem:
        sections.append(_validation(res, work))
    return sections


def report_paper_problem(out_dir, *, quick=False, fem=True, problem=None, fmt="png", progress=None):
    """Solve the paper's test problem and write its report to ``out_dir``.

    Parameters
    ----------
    out_dir : path-like
        Report directory (``report.html``, ``report.md``, ``figures/``), written whole or not at all.
    quick : bool
        Coarse lattice (a_H/c = 8) and short sweeps: seconds instead of about a minute.
    fem : bool
        Include the FEM reference and the resolution study.
    problem : validation.report.paper.PaperProblem, optional
        Other parameters.
    fmt : {"png", "svg", "pdf"}
        Figure files (:func:`validation.report.style.figure_format`).
    progress : callable, optional
        ``progress(stage, done, total)`` at the start of each stage (:data:`STAGES`, the FEM
        stage only with ``fem``) and ``progress("done", total, total)`` at the end.

    Returns
    -------
    validation.report.build.BuiltReport
    """
    stages = [s for s in STAGES if fem or s != "FEM reference"]
    notify = Progress(stages, progress)
    res = solve_paper_problem(problem, quick=quick, fem=fem, progress=notify)
    pb = res.problem
    subtitle = (f"Paraboloids R = E* = P = 1, lam = {pb.lam_factor:g} C_nn; BEM lattice a_H/c = "
                f"{pb.nodes_per_radius}{' (quick preview)' if quick else ''}; computed in {res.wall_time_s:.0f} s.")
    return draw_and_build(lambda work: paper_sections(res, work), out_dir, title=TITLE, subtitle=subtitle, fmt=fmt,
                          notify=notify)
