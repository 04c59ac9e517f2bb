"""The paper's test problem: two paraboloids with a nonlinear interface layer (its section 6, Fig. 5).

Normalised units R = E* = P = 1. The layer laws are given as in the paper: the compliance
``lam = 10 C_nn`` (``C_nn`` the diagonal influence coefficient) taken at the reference step
``a_H / 20``, a fixed compliance whatever lattice solves the problem, the elastic-rigid
threshold ``p_cr = alpha_a p_max^lambda`` with ``alpha_a = 0.5`` (``p_max^lambda``: the peak
with the linear layer ``lam``), and the root law ``w = lam sqrt(p_max^lambda) sqrt(p)``. Each
law is solved by Newton's method on the generalised functional (the default) and, for the root
law, also by the paper's variable compliance method.
See docs/method.md, section 5. Run::

    python docs/examples/paper_problem.py
"""

from __future__ import annotations

import bem
from bem.gaps import Paraboloid
from bem.reference import hertz_sphere
from validation.scene.paper import c_nn, paper_law


def main(nodes_per_radius=12):
    """Solve the smooth, linear, elastic-rigid and root cases; return the peaks over Hertz's p0."""
    R = E_star = P = 1.0
    hz = hertz_sphere(R, E_star, force=P)                    # p0, a of the smooth contact
    step = hz.contact_radius / nodes_per_radius                           # lattice step c
    lam = 10 * c_nn(hz.contact_radius / 20, E_star)          # the paper's lam = 10 C_nn at c = a_H/20

    def solve(layer, method="newton"):
        return bem.solve(Paraboloid(R), E_star=E_star, force=P, step=step, extent=1.8 * hz.contact_radius, layer=layer,
                         method=method)

    linear = solve(paper_law("linear", lam))
    p_lambda = linear.p_max                                  # p_max^lambda
    results = {"smooth": solve(None), "linear": linear,
               "elastic_rigid": solve(paper_law("elastic_rigid", lam, p_lambda, alpha_a=0.5)),
               "root": solve(paper_law("root", lam, p_lambda))}
    root_vc = solve(paper_law("root", lam, p_lambda), method="variable_compliance")
    peaks = {name: res.p_max / hz.p_max for name, res in results.items()}
    agreement = abs(root_vc.p_max / results["root"].p_max - 1)
    for name, res in results.items():
        print(f"{name:14s} p_max / p0 = {peaks[name]:.4f}, "
              f"contact radius / a = {res.contact_radius / hz.contact_radius:.3f}, "
              f"converged {res.converged} ({res.iterations} iterations)")
    print(f"alpha_b = p_max^root / p_max^lambda = {results['root'].p_max / p_lambda:.4f}; variable compliance "
          f"method: {root_vc.iterations} iterations, peak within {agreement:.1e} of Newton's")
    return {"results": results, "peaks": peaks, "root_variable_compliance": root_vc, "agreement": agreement}


if __name__ == "__main__":
    main()
