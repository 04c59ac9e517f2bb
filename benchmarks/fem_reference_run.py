"""Default-settings FEM reference run: size and time split (mesh, assembly, solve).

Run: ``python benchmarks/fem_reference_run.py`` (about 2-5 s on a 2-core machine).

Problem: steel sphere (R = 10 mm) on a steel flat, P = 100 N (Hertz: a = 0.19 mm,
p0 = 1327 MPa), smooth and with a root-law layer ``w = lam sqrt(p)``; everything else
at the defaults of :func:`fem_reference.solve`.
"""

import math
import time

import fem_reference as fr
from bem.gaps import Paraboloid
from bem.layers import Root

E, NU, R, P = 210e3, 0.3, 10.0, 100.0  # MPa, -, mm, N


def hertz(force, radius, Es):
    a = (3 * force * radius / (4 * Es)) ** (1 / 3)
    return a, 3 * force / (2 * math.pi * a * a), a * a / radius


def report(label, res, exact=None):
    t = res.timings
    print(f"\n{label}: converged={res.converged} ({res.message}), Newton steps={res.iterations}")
    print(f"  DOFs={res.n_dofs}  triangles={res.n_elements}  interface pairs={res.n_interface_nodes}  "
          f"elements across contact={res.n_elements_across_contact:.1f}")
    print(f"  time [s]: mesh={t['mesh']:.2f} assembly={t['assembly']:.2f} solve={t['solve']:.2f} "
          f"(factorize={t['factorize']:.2f} compliance={t['compliance']:.2f} newton={t['newton']:.3f} "
          f"recover={t['recover']:.3f}) total={t['total']:.2f}")
    print(f"  p_max={res.p_max:.2f} MPa  a={res.edge_radius:.5f} mm  delta={res.approach:.6f} mm  "
          f"force={res.force:.4f} N (reactions {res.force_reaction:.4f} N)")
    print(f"  penalty: factor={res.penalty['factor']:.0e}, relative penetration="
          f"{res.penalty['relative_penetration']:.1e}; truncation correction dc*P="
          f"{res.truncation['correction']:.3e} mm ({res.truncation['correction'] / res.approach:.2%} of delta)")
    if exact is not None:
        a, p0, delta = exact
        print(f"  vs Hertz: p_max {res.p_max / p0 - 1:+.3%}, a {res.edge_radius / a - 1:+.3%}, "
              f"delta {res.approach / delta - 1:+.3%}")


def main():
    Es = 1 / (2 * (1 - NU**2) / E)
    gap = Paraboloid(R)
    t0 = time.perf_counter()
    report("Hertz (no layer)", fr.solve(gap, E1=E, nu1=NU, E2=E, nu2=NU, force=P), hertz(P, R, Es))
    a, p0, _ = hertz(P, R, Es)
    report("root layer w = lam sqrt(p), lam sqrt(p0) = a/E*",
           fr.solve(gap, E1=E, nu1=NU, E2=E, nu2=NU, force=P, layer=Root(a / Es * math.sqrt(p0))))
    print(f"\nwall time of both runs: {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
