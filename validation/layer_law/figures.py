"""The figures of a rough surface's layer law (:class:`bem.rough.TopographyLaw`, SI units).

- ``closure.png``: the closure ``w(p)`` on linear axes (with the first-touch mean gap
  ``ubar(0+)``, the full closure) and on logarithmic axes: the ladder's points marked, the
  tabulated law's interpolant (:class:`bem.layers.Tabulated`) between them;
- ``contact_fraction.png``: ``A/A0`` against ``p/(E* h'_rms)`` (``h'_rms = stats.rms_slope``),
  logarithmic axes, with the small-load line ``A/A0 = 2 p/(E* h'_rms)`` of Hyun et al.
  (PRE 70, 026117, 2004) as a guide;
- ``stiffness.png``: the interfacial stiffness ``K = dp/dw`` [Pa/m] against ``p``, logarithmic
  axes; points in full contact (``K = inf``) are left out and named in the legend;
- ``persson.png``: the ladder's ``A/A0`` (logarithmic axes) and mean gap ``ubar`` (in rms
  heights, logarithmic pressure axis) against ``p``, beside Persson's theory for the same cell's
  spectrum (:mod:`bem.rough.persson`, recorded in ``law.persson``): where the lines part, the
  numerical law departs from the theory (finite resolution and cell, spikes, a non-Gaussian
  surface, or the theory's approximations). Pressures added below the ladder are marked.

A law of plastic asperities (``law.hardness``, :mod:`bem.rough.layer_law`) names its hardness
``H`` in every title; ``contact_fraction.png`` draws the share of the cell at ``H`` beside
``A/A0``, and ``persson.png`` notes that the theory is elastic.

Matplotlib is imported inside the functions (the ``report`` extra).
"""

from __future__ import annotations

import numpy as np

from ..report.render.style import display_unit, new_figure, save_figure

__all__ = ["draw_all", "closure_figure", "contact_fraction_figure", "stiffness_figure", "persson_figure",
           "HYUN_KAPPA"]

#: the small-load slope of ``A/A0`` against ``p/(E* h'_rms)`` drawn as a guide (Hyun et al. 2004)
HYUN_KAPPA = 2.0
_POINTS = dict(marker="o", markersize=5, linestyle="none", color="#1f77b4")
_CURVE = dict(color="#1f77b4", linewidth=1.2)


def _source(law):
    source = law.stats.source or "surface"
    return source if len(source) <= 60 else "..." + source[-57:]


def _hardness(law):
    """``", H = ... Pa (plastic asperities)"`` for a law with a hardness, ``""`` for an elastic one."""
    return "" if law.hardness is None else f", hardness $H$ = {law.hardness:.4g} Pa (plastic asperities)"


def closure_figure(law, path):
    """``w(p)`` on linear and logarithmic axes; returns the figure after writing ``path``."""
    p, w = law.mean_pressure, law.closure
    pu, pf = display_unit("Pa", float(p[-1]))
    wu, wf = display_unit("m", float(max(w[-1], law.first_touch_gap)))
    with new_figure((9.6, 4.0), ncols=2) as (fig, (lin, log)):
        fine = np.linspace(0.0, p[-1], 400)
        lin.plot(fine / pf, law.law.w(fine) / wf, label="tabulated law (monotone cubic)", **_CURVE)
        lin.plot(p / pf, w / wf, label=f"ladder ({p.size} solves)", **_POINTS)
        lin.axhline(law.first_touch_gap / wf, color="0.4", linestyle="--", linewidth=1,
                    label=r"first-touch mean gap $\bar u(0^+)$ (full closure)")
        lin.set_xlim(0.0, 1.02 * p[-1] / pf)
        lin.set_ylim(0.0, 1.08 * max(law.first_touch_gap, w[-1]) / wf)  # a flattened surface closes beyond it
        lin.legend(loc="lower right", fontsize="small")
        geo = np.geomspace(p[0], p[-1], 400)
        log.loglog(geo / pf, law.law.w(geo) / wf, **_CURVE)
        log.loglog(p / pf, w / wf, **_POINTS)
        for ax in (lin, log):
            ax.set_xlabel(f"mean pressure $p$ [{pu}]")
            ax.set_ylabel(f"closure $w$ [{wu}]")
            ax.grid(True, which="both", alpha=0.3)
        lin.set_title("linear axes")
        log.set_title("logarithmic axes")
        fig.suptitle(r"Layer law $w(p) = \bar u(0^+) - \bar u(p)$ of " + _source(law)
                     + f", $E^*$ = {law.E_star:.4g} Pa" + _hardness(law))
        save_figure(fig, path)
        return fig


def contact_fraction_figure(law, path):
    """``A/A0`` against ``p/(E* h'_rms)``, logarithmic axes; returns the figure after writing ``path``."""
    slope = float(law.stats.rms_slope)
    x = law.mean_pressure / (law.E_star * slope)
    a = law.contact_fraction
    with new_figure((6.4, 4.4)) as (fig, ax):
        guide = np.geomspace(x[0], min(x[-1], 1.0 / HYUN_KAPPA), 50)
        ax.loglog(guide, HYUN_KAPPA * guide, color="0.5", linestyle="--", linewidth=1,
                  label=rf"$A/A_0 = {HYUN_KAPPA:g}\, p/(E^* h'_\mathrm{{rms}})$ (Hyun et al. 2004)")
        ax.loglog(x, a, label=f"ladder ({x.size} solves)", **_CURVE, marker="o", markersize=5)
        if law.hardness is not None and np.any(law.plastic_fraction > 0):
            flows = law.plastic_fraction > 0
            ax.loglog(x[flows], law.plastic_fraction[flows], color="#d62728", marker="s", markersize=4,
                      linewidth=1, label=f"share at the hardness $H$ = {law.hardness:.4g} Pa (flowing)")
        ax.set_xlabel(r"$p\,/\,(E^*\,h'_\mathrm{rms})$ [-]")
        ax.set_ylabel(r"real contact fraction $A/A_0$ [-]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(loc="lower right", fontsize="small")
        ax.set_title(rf"Contact fraction, $h'_\mathrm{{rms}}$ = {slope:.4g}, $E^*$ = {law.E_star:.4g} Pa"
                     + ("" if law.hardness is None else f", hardness $H$ = {law.hardness:.4g} Pa"), fontsize="medium")
        save_figure(fig, path)
        return fig


def stiffness_figure(law, path):
    """``K(p)`` [Pa/m], logarithmic axes, full-contact points left out; returns the figure after writing ``path``."""
    p, k = law.mean_pressure, law.stiffness
    finite = np.isfinite(k)
    pu, pf = display_unit("Pa", float(p[-1]))
    with new_figure((6.4, 4.4)) as (fig, ax):
        ax.loglog(p[finite] / pf, k[finite], label=f"ladder ({int(finite.sum())} of {p.size} solves)", **_CURVE,
                  marker="o", markersize=5)
        if not finite.all():
            ax.plot([], [], " ", label=f"full contact (K = inf) at p >= {p[~finite][0] / pf:.4g} {pu}: not drawn")
        ax.set_xlabel(f"mean pressure $p$ [{pu}]")
        ax.set_ylabel(r"interfacial stiffness $K = \mathrm{d}p/\mathrm{d}w$ [Pa/m]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(loc="lower right", fontsize="small")
        ax.set_title(r"Interfacial stiffness $K = -\mathrm{d}p/\mathrm{d}\bar u$" + _hardness(law),
                     fontsize="medium")
        save_figure(fig, path)
        return fig


def persson_figure(law, path):
    """``A/A0`` and ``ubar/h_rms`` of the ladder beside Persson's theory; returns the figure after writing ``path``."""
    theory, p = law.persson, law.mean_pressure
    pu, pf = display_unit("Pa", float(p[-1]))
    rms = float(law.stats.rms_height)
    added = int(law.ladder_start.get("added", 0))
    with new_figure((9.6, 4.2), ncols=2) as (fig, (area, gap)):
        label = rf"Persson (2001, 2007), $\gamma$ = {theory['gamma']:g}" + ("" if law.hardness is None else
                                                                             ", elastic (no hardness)")
        area.loglog(theory["mean_pressure"] / pf, theory["contact_fraction"], color="0.3", linestyle="--",
                    linewidth=1.2, label=label)
        area.loglog(p / pf, law.contact_fraction, label=f"ladder ({p.size} solves)", **_CURVE, marker="o",
                    markersize=5)
        gap.semilogx(theory["mean_pressure"] / pf, np.asarray(theory["mean_gap"]) / rms, color="0.3",
                     linestyle="--", linewidth=1.2, label=label)
        gap.semilogx(p / pf, law.mean_gap / rms, label=f"ladder ({p.size} solves)", **_CURVE, marker="o",
                     markersize=5)
        gap.axhline(law.first_touch_gap / rms, color="0.6", linestyle=":", linewidth=1,
                    label=r"first-touch mean gap $\bar u(0^+)$")
        if added:
            for ax, y in ((area, law.contact_fraction), (gap, law.mean_gap / rms)):
                ax.plot(p[:added] / pf, y[:added], linestyle="none", marker="s", markersize=7, markerfacecolor="none",
                        color="#d62728", label=f"{added} added below the ladder asked for")
        area.set_ylabel(r"real contact fraction $A/A_0$ [-]")
        gap.set_ylabel(rf"mean gap $\bar u / h_\mathrm{{rms}}$ [-], $h_\mathrm{{rms}}$ = {rms:.3g} m")
        for ax in (area, gap):
            ax.set_xlabel(f"mean pressure $p$ [{pu}]")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(loc="best", fontsize="small")
        fig.suptitle(f"Layer law of {_source(law)} beside Persson's theory for its spectrum "
                     rf"($h'_\mathrm{{rms}}$ = {theory['rms_slope']:.3g}, $E^*$ = {law.E_star:.4g} Pa"
                     + _hardness(law) + ")",
                     fontsize="medium")
        save_figure(fig, path)
        return fig


def draw_all(law, folder):
    """Write the four figures into ``folder``; returns ``{file name: figure}``."""
    return {name: draw(law, folder / name) for name, draw in (("closure.png", closure_figure),
                                                             ("contact_fraction.png", contact_fraction_figure),
                                                             ("stiffness.png", stiffness_figure),
                                                             ("persson.png", persson_figure))}
