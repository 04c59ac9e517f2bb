"""The stresses of the coating study against the FEM (:mod:`validation.studies.coating_fem`): the BEM's
pressure, averaged on rings, carried into the coated body by :func:`bem.coating_fields.axisymmetric_stress`,
against the FEM's stresses recovered one-sidedly (:func:`fem_reference.fields.one_sided_stresses`: the
coating's elements for the coating, the substrate's for the substrate, so that each side of the bond keeps
its own value).

- The bond ``z = t``, within ``BOND_WINDOW max(a, t)`` of the axis (a thick coating spreads the load over
  its thickness): ``sigma_zz`` and ``sigma_rz`` at the FEM's bond nodes, on the substrate's side (the
  coating's side differs from it by the FEM's own recovery error, ``fem_sides``). Errors: the largest
  difference over the largest traction magnitude ``sqrt(sigma_zz^2 + sigma_rz^2)`` on the bond (``szz``,
  ``srz``: what a designer compares with the bond's strength), and over each component's own largest
  value (``szz_own``, ``srz_own``; large where ``sigma_rz`` nearly vanishes). ``*_projected``: the
  continuous L2 projection of :func:`fem_reference.fields.nodal_stresses`, within ``1.5 a``, over each
  component's own largest value.
- The largest von Mises stress of the FEM's nodes in the coating (depths ``0.02 t ... t``) and in the
  substrate (``t ... t + 3 a``), ``r <= 2 a``, one-sided (the bond included on both sides), against the
  BEM's at that node, on that side.
- Per level (:func:`fem_scalars`, :func:`bem_scalars`): ``sigma_zz`` on the axis at the bond, the largest
  ``|sigma_rz|`` on the bond and the two von Mises maxima, for the observed orders of both methods.
"""

from __future__ import annotations

import numpy as np

__all__ = ["BOND_WINDOW", "STRESS_SCALARS", "radial_profile", "fem_scalars", "bem_scalars", "interface_stresses"]

#: radius of the compared bond in units of ``max(contact radius, thickness)``
BOND_WINDOW = 1.5
#: the per-level stress scalars: ``sigma_zz`` at the bond's axis point, the largest ``|sigma_rz|`` on the
#: bond, the largest von Mises stress in the coating and in the substrate [pressure]
STRESS_SCALARS = ("szz_axis", "srz_max", "vm_coating", "vm_substrate")


def radial_profile(res):
    """The BEM's pressure on rings of the lattice step: ``(r, p)`` (means over the nodes of each ring)."""
    r = np.hypot(res.x, res.y)
    k = np.floor(r / res.step + 0.5).astype(int)
    n = np.bincount(k)
    keep = n > 0
    return (np.bincount(k, weights=r)[keep] / n[keep], np.bincount(k, weights=res.p)[keep] / n[keep])


def _fem_sides(f):
    """The FEM's one-sided stresses ``{"coating": ..., "substrate": ...}`` and its node coordinates."""
    from fem_reference.fields import one_sided_stresses

    m, u = f.model, f.displacement_dofs
    lower = m.amesh.body == 1
    sides = {"coating": one_sided_stresses(m, u, lower & m.amesh.coated),
             "substrate": one_sided_stresses(m, u, lower & ~m.amesh.coated)}
    r, z = m.scalar_basis.doflocs
    return sides, r, -z


def _windows(r, depth, t, a):
    """Node masks: the bond within the window, and the von Mises windows per material."""
    bond = np.isclose(depth, t, rtol=0, atol=1e-9 * t) & (r <= BOND_WINDOW * max(a, t))
    near = r <= 2.0 * a
    return bond, {"coating": near & (depth >= 0.02 * t) & (depth <= t * (1 + 1e-9)),
                  "substrate": near & (depth >= t * (1 - 1e-9)) & (depth <= t + 3.0 * a)}


def fem_scalars(f, coating):
    """The FEM's :data:`STRESS_SCALARS` of one level (one-sided; von Mises: its largest node per material)."""
    sides, r, depth = _fem_sides(f)
    bond, vm = _windows(r, depth, coating.thickness, float(f.edge_radius))
    sub = sides["substrate"]
    axis = np.nonzero(bond & (r == 0.0))[0]
    out = dict(szz_axis=float(sub["sigma_zz"][axis[0]]) if axis.size else None,
               srz_max=float(np.abs(sub["sigma_rz"][bond]).max()))
    for name, nodes in vm.items():
        nodes = nodes & sides[name]["nodes"]
        out[f"vm_{name}"] = float(sides[name]["von_mises"][nodes].max()) if nodes.any() else None
    return out


def _profile_function(res):
    rb, pb = radial_profile(res)
    return (lambda x: np.interp(x, rb, pb, right=0.0)), float(rb[pb > 0].max()) + res.step


def bem_scalars(res, coating, s, points):
    """The BEM's :data:`STRESS_SCALARS` of one level at the FEM's finest nodes ``points`` (from
    :func:`interface_stresses`): the bond nodes' radii and the von Mises nodes ``(r, depth)`` per material."""
    from bem.coating_fields import axisymmetric_stress, von_mises

    p, edge = _profile_function(res)
    t = coating.thickness
    bond = axisymmetric_stress(p, edge, np.r_[0.0, points["bond_r"]], [t], coating, s["E_s"], s["nu_s"],
                               side="substrate")
    out = dict(szz_axis=float(bond["szz"][0, 0]), srz_max=float(np.abs(bond["srz"]).max()))
    for name in ("coating", "substrate"):
        at = points.get(f"vm_{name}_at")
        if at is None:
            out[f"vm_{name}"] = None
            continue
        st = axisymmetric_stress(p, edge, [at[0]], [at[1]], coating, s["E_s"], s["nu_s"], side=name)
        out[f"vm_{name}"] = float(von_mises(st["srr"], st["stt"], st["szz"], st["srz"])[0, 0])
    return out


def _projected(f, p, edge, coating, s):
    """The bond's tractions against the continuous projection within ``1.5 a`` (own maxima)."""
    from bem.coating_fields import axisymmetric_stress
    from fem_reference.fields import nodal_stresses

    t = coating.thickness
    fs = nodal_stresses(f.model, f.displacement_dofs)
    r, z = f.model.scalar_basis.doflocs
    on = np.isclose(z, -t, rtol=0, atol=1e-9 * t) & (r < 1.5 * float(f.edge_radius))
    ours = axisymmetric_stress(p, edge, r[on], [t], coating, s["E_s"], s["nu_s"], side="substrate")
    return {f"{k}_projected": float(np.abs(fs[name][on] - sign * ours[k][:, 0]).max() / np.abs(fs[name][on]).max())
            for k, name, sign in (("szz", "sigma_zz", 1.0), ("srz", "sigma_rz", -1.0))}


def interface_stresses(b, f, coating, s):
    """BEM (finest result ``b``) against FEM (finest result ``f``): a dict of relative errors, the maxima and
    ``points`` (where the per-level scalars of :func:`bem_scalars` are taken)."""
    from bem.coating_fields import axisymmetric_stress, von_mises

    t, E, nu = coating.thickness, s["E_s"], s["nu_s"]
    p, edge = _profile_function(b)
    sides, r, depth = _fem_sides(f)
    a = float(f.edge_radius)
    bond, vm = _windows(r, depth, t, a)
    ours = axisymmetric_stress(p, edge, r[bond], [t], coating, E, nu, side="substrate")
    szz, srz = ours["szz"][:, 0], -ours["srz"][:, 0]  # the FEM's z points up: sigma_rz changes sign
    sub, top = sides["substrate"], sides["coating"]
    traction = float(np.hypot(sub["sigma_zz"][bond], sub["sigma_rz"][bond]).max())
    dzz, drz = np.abs(sub["sigma_zz"][bond] - szz).max(), np.abs(sub["sigma_rz"][bond] - srz).max()
    out = dict(nodes=int(bond.sum()), window=BOND_WINDOW * max(a, t), traction_max=traction,
               szz=float(dzz / traction), srz=float(drz / traction),
               szz_own=float(dzz / np.abs(sub["sigma_zz"][bond]).max()),
               srz_own=float(drz / np.abs(sub["sigma_rz"][bond]).max()),
               fem_sides=float(max(np.abs(top[k][bond] - sub[k][bond]).max() for k in ("sigma_zz", "sigma_rz"))
                               / traction),
               **_projected(f, p, edge, coating, s))
    points = {"bond_r": [float(x) for x in r[bond]]}
    for name, nodes in vm.items():
        nodes = np.nonzero(nodes & sides[name]["nodes"])[0]
        if nodes.size == 0:  # no FEM node in the window
            out[f"vm_{name}_fem"] = out[f"vm_{name}_bem"] = out[f"vm_{name}_at"] = out[f"vm_{name}"] = None
            points[f"vm_{name}_at"] = None
            continue
        k = nodes[np.argmax(sides[name]["von_mises"][nodes])]
        st = axisymmetric_stress(p, edge, [r[k]], [depth[k]], coating, E, nu, side=name)
        out[f"vm_{name}_fem"] = float(sides[name]["von_mises"][k])
        out[f"vm_{name}_bem"] = float(von_mises(st["srr"], st["stt"], st["szz"], st["srz"])[0, 0])
        out[f"vm_{name}_at"] = points[f"vm_{name}_at"] = [float(r[k]), float(depth[k])]
        out[f"vm_{name}"] = out[f"vm_{name}_bem"] / out[f"vm_{name}_fem"] - 1.0
    return out, points
