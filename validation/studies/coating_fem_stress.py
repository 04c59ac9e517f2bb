"""The stresses of the coating study against the FEM (:mod:`validation.studies.coating_fem`): the BEM's
pressure, averaged on rings, carried into the coated body by :func:`bem.coating_fields.axisymmetric_stress`,
against the FEM's projected nodal stresses (:func:`fem_reference.fields.nodal_stresses`).

- At the interface ``z = t``: ``sigma_zz`` and ``sigma_rz`` at the FEM's interface nodes within ``1.5``
  contact radii; the error is the largest difference over the largest magnitude of the FEM's values.
- The von Mises stress at the FEM node of its largest value in the coating (depths ``0.02 t ... 0.75 t``)
  and in the substrate (``1.25 t ... t + 3 a``), ``r <= 2 a``, and the BEM's there. The FEM's nodal
  stresses are a continuous projection: at the bond, where ``sigma_rr`` and ``sigma_tt`` jump, they take
  a mean of the two materials, hence the quarter thickness kept clear of it on both sides (``None`` where the window holds no node).
"""

from __future__ import annotations

import numpy as np

__all__ = ["radial_profile", "interface_stresses"]


def radial_profile(res):
    """The BEM's pressure on rings of the lattice step: ``(r, p)`` (means over the nodes of each ring)."""
    r = np.hypot(res.x, res.y)
    k = np.floor(r / res.step + 0.5).astype(int)
    n = np.bincount(k)
    keep = n > 0
    return (np.bincount(k, weights=r)[keep] / n[keep], np.bincount(k, weights=res.p)[keep] / n[keep])


def interface_stresses(b, f, coating, s):
    """BEM (finest result ``b``) against FEM (finest result ``f``): a dict of relative errors and maxima."""
    from bem.coating_fields import axisymmetric_stress, von_mises
    from fem_reference.fields import nodal_stresses

    t, E, nu = coating.thickness, s["E_s"], s["nu_s"]
    rb, pb = radial_profile(b)
    edge = float(rb[pb > 0].max()) + b.step
    p = lambda x: np.interp(x, rb, pb, right=0.0)  # noqa: E731
    fs = nodal_stresses(f.model, f.displacement_dofs)
    r, z = f.model.scalar_basis.doflocs
    a = float(f.edge_radius)
    on = np.isclose(z, -t, rtol=0, atol=1e-9 * t) & (r < 1.5 * a)
    ours = axisymmetric_stress(p, edge, r[on], [t], coating, E, nu, side="substrate")
    szz, srz = ours["szz"][:, 0], -ours["srz"][:, 0]  # the FEM's z points up: sigma_rz changes sign
    out = dict(nodes=int(on.sum()),
               szz=float(np.abs(fs["sigma_zz"][on] - szz).max() / np.abs(fs["sigma_zz"][on]).max()),
               srz=float(np.abs(fs["sigma_rz"][on] - srz).max() / np.abs(fs["sigma_rz"][on]).max()))
    depth = -z
    zones = {"coating": (depth >= 0.02 * t) & (depth <= 0.75 * t),
             "substrate": (depth >= 1.25 * t) & (depth <= t + 3.0 * a)}
    for name, nodes in zones.items():
        nodes = np.nonzero(nodes & (r <= 2.0 * a))[0]
        if nodes.size == 0:  # a thick coating's coarse substrate mesh: no node in the window
            out[f"vm_{name}_fem"] = out[f"vm_{name}_bem"] = out[f"vm_{name}_at"] = out[f"vm_{name}"] = None
            continue
        k = nodes[np.argmax(fs["von_mises"][nodes])]
        st = axisymmetric_stress(p, edge, [r[k]], [depth[k]], coating, E, nu, side=name)
        out[f"vm_{name}_fem"] = float(fs["von_mises"][k])
        out[f"vm_{name}_bem"] = float(von_mises(st["srr"], st["stt"], st["szz"], st["srz"])[0, 0])
        out[f"vm_{name}_at"] = [float(r[k]), float(depth[k])]
        out[f"vm_{name}"] = out[f"vm_{name}_bem"] / out[f"vm_{name}_fem"] - 1.0
    return out
