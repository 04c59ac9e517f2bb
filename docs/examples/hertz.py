"""Hertz's contact: a steel ball on a steel flat, solved by the BEM and checked against the closed form.

Run it from anywhere (the core install is enough)::

    python docs/examples/hertz.py

Units are SI: lengths in m, moduli and pressures in Pa, forces in N.
"""

from __future__ import annotations

import bem
from bem.gaps import Paraboloid
from bem.reference import hertz_sphere


def main():
    """Solve the contact and return the relative errors against Hertz's solution."""
    R = 0.01           # m, effective radius of the ball (1/R = 1/R1 + 1/R2, flat: R2 = inf)
    E, nu = 210e9, 0.3  # Pa, -: steel, both bodies
    P = 100.0          # N, normal force
    E_star = bem.effective_modulus(E, nu, E, nu)  # Pa, 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2
    hz = hertz_sphere(R, E_star, force=P)          # closed form: p0 [Pa], a [m], delta [m]

    # 60 lattice nodes across the contact diameter, candidate region 1.5 contact radii wide
    a = hz.contact_radius
    res = bem.solve(Paraboloid(R), E_star=E_star, force=P, step=2 * a / 60, extent=1.5 * a)
    errors = {"p_max": res.p_max / hz.p_max - 1, "approach": res.approach / hz.approach - 1,
              "contact_radius": res.contact_radius / hz.contact_radius - 1}
    print(f"p_max {res.p_max / 1e9:.4f} GPa (Hertz {hz.p_max / 1e9:.4f} GPa), contact radius "
          f"{res.contact_radius * 1e6:.1f} um (Hertz {hz.contact_radius * 1e6:.1f} um), approach "
          f"{res.approach * 1e6:.4f} um (Hertz {hz.approach * 1e6:.4f} um); converged {res.converged} "
          f"in {res.iterations} iterations")
    print("relative errors: " + ", ".join(f"{k} {v:+.1e}" for k, v in errors.items()))
    return {"result": res, "hertz": hz, "errors": errors}


if __name__ == "__main__":
    main()
