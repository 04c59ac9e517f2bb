"""Figures of a coated body's stresses: the tractions and the von Mises stress at its coating/substrate interface.

:func:`plot_interface` draws, along the x-z section through the axis, the normal traction
``sigma_zz`` and the shear traction at the interface beside the surface pressure, and the von Mises
stress on the coating's and the substrate's side of the interface (it jumps there: the in-plane
stresses of two bonded materials differ); :func:`interface_tractions` draws it from a run's
``stress.bodies.*.coated`` (:mod:`validation.run.stress_coated`). Conventions:
:mod:`validation.report.figures`.
"""

from __future__ import annotations

import numpy as np

from bem.checks import InputError, check_positive

from ..render.content import Figure
from ..render.style import color_for, new_figure, save_figure

__all__ = ["plot_interface", "interface_tractions"]


def plot_interface(curves, path, *, a, scale, labels, surface=None, title=None):
    """The interface along a line: tractions (left panel) and von Mises stress from both sides (right panel).

    Parameters
    ----------
    curves : sequence of dict
        One per coated body: ``{"label", "x", "sigma_zz", "shear", "von_mises_coating", "von_mises_substrate"}``,
        ``x`` [length], the others [stress] (``von_mises_substrate`` ``None`` on a rigid substrate).
    labels : dict
        ``{"x", "traction", "von_mises"}`` axis labels (mathtext).
    surface : tuple, optional
        ``(x, p)`` of the surface pressure [length], [stress], drawn as ``-p`` for reference.
    """
    if not curves:
        raise InputError("curves = [] is not allowed: give at least one coated body's interface.")
    a, scale = check_positive("a", a), check_positive("scale", scale)
    with new_figure((10.0, 4.0), title=None, ncols=2) as (fig, (left, right)):
        if title:
            fig.suptitle(title)
        if surface is not None:
            left.plot(np.asarray(surface[0]) / a, -np.asarray(surface[1]) / scale, color="#999999", lw=1.0,
                      label="surface: $-p$")
        for i, c in enumerate(curves):
            x = np.asarray(c["x"]) / a
            color = color_for("", 2 * i)
            left.plot(x, np.asarray(c["sigma_zz"]) / scale, color=color, lw=1.6, label=rf"{c['label']}: $\sigma_{{zz}}$")
            left.plot(x, np.asarray(c["shear"]) / scale, color=color_for("", 2 * i + 1), lw=1.6, ls="--",
                      label=rf"{c['label']}: shear $\sqrt{{\sigma_{{xz}}^2 + \sigma_{{yz}}^2}}$")
            right.plot(x, np.asarray(c["von_mises_coating"]) / scale, color=color, lw=1.6,
                       label=f"{c['label']}: coating side")
            if c["von_mises_substrate"] is not None:
                right.plot(x, np.asarray(c["von_mises_substrate"]) / scale, color=color_for("", 2 * i + 1), lw=1.6,
                           ls="--", label=f"{c['label']}: substrate side")
        left.axhline(0.0, color="#bbbbbb", lw=0.8)
        left.set_title("tractions on the interface (compression < 0)", fontsize=9.5)
        right.set_title("von Mises stress on each side of the interface", fontsize=9.5)
        right.set_ylim(bottom=0.0)
        for ax, key in ((left, "traction"), (right, "von_mises")):
            ax.set_xlabel(labels["x"])
            ax.set_ylabel(labels[key])
            ax.legend(fontsize=8)
        return save_figure(fig, path)


def interface_tractions(res, work):
    """The interface figure of the coated bodies of a run with ``[stress]``, or None without one."""
    from .run import axis_label, stress_view

    block = res.result.stress
    coated = {} if block is None else {name: b.coated for name, b in block.bodies.items() if b.coated is not None}
    if not coated:
        return None
    a, s, l_name, s_name, normalised = stress_view(res)
    length, stress = (a, l_name, normalised), (s, s_name, normalised)
    curves = [{"label": name, **c.interface} for name, c in coated.items()]
    profile = res.result.profile
    surface = None if profile is None else (profile.x, profile.p)
    labels = {"x": axis_label("x", length), "traction": axis_label(r"\sigma", stress),
              "von_mises": axis_label(r"\sigma_{vM}", stress)}
    depth = ", ".join(f"{name} at depth t = {c.thickness / a:.4g} {l_name}" for name, c in coated.items())
    path = plot_interface(curves, work / "stress_interface.png", a=a, scale=s, labels=labels, surface=surface,
                          title=f"coating/substrate interface in the section y = {next(iter(curves))['y'] / a:.3g}")
    return Figure(path, f"The coating/substrate interface ({depth}) along the x-z section through the axis "
                        "(bem.coated_stress). Left: its normal traction sigma_zz (solid) and shear traction "
                        "(dashed), with the surface pressure -p (grey) for scale; the traction is continuous "
                        "across the bonded interface. Right: the von Mises stress on the coating's side (solid) and "
                        "on the substrate's side (dashed): the in-plane stresses jump at the material boundary.")
