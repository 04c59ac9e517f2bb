"""A layer from measured pressure-closure pairs: a rough steel ball on a steel flat.

A compression test of the rough surface gives pairs (pressure [Pa], closure [m]);
:class:`bem.layers.Tabulated` interpolates them monotonically (PCHIP), passes through (0, 0)
and continues linearly beyond the last pair. The pairs below are SYNTHETIC (no measurement):
sampled from ``w = s ln(1 + p / p_s)``, ``s = 0.5 um``, ``p_s = 50 MPa``, the closure law of an
exponential distribution of asperity heights (Greenwood and Williamson 1966,
DOI 10.1098/rspa.1966.0242), rounded to 4 digits - as in the built-in scene ``rough_sphere``.
Run::

    python docs/examples/measured_layer.py
"""

from __future__ import annotations

import numpy as np

import bem
from bem.gaps import Paraboloid
from bem.layers import Tabulated
from bem.reference import hertz_sphere

#: pressure [Pa] and closure [m] pairs of the rough layer
PAIRS_P = [0.0, 5e6, 1e7, 2.5e7, 5e7, 1e8, 2e8, 4e8, 8e8, 1.6e9, 3.2e9]
PAIRS_W = [0.0, 4.766e-08, 9.116e-08, 2.027e-07, 3.466e-07, 5.493e-07, 8.047e-07, 1.099e-06, 1.417e-06,
           1.748e-06, 2.087e-06]


def main():
    """Solve the ball with and without the rough layer; return both results and the layer."""
    R, E, nu, P = 0.01, 210e9, 0.3, 100.0          # m, Pa, -, N
    E_star = bem.effective_modulus(E, nu, E, nu)   # Pa
    layer = Tabulated(PAIRS_P, PAIRS_W)            # w(p) [m] from p [Pa]
    a = hertz_sphere(R, E_star, force=P).contact_radius         # m, contact radius without the layer
    options = dict(E_star=E_star, force=P, step=a / 20, extent=2.5 * a)
    rough = bem.solve(Paraboloid(R), layer=layer, **options)
    smooth = bem.solve(Paraboloid(R), **options)
    centre = int(np.argmax(rough.p))
    print(f"smooth: p_max {smooth.p_max / 1e9:.3f} GPa, contact radius {smooth.contact_radius * 1e6:.0f} um")
    print(f"rough:  p_max {rough.p_max / 1e9:.3f} GPa, contact radius {rough.contact_radius * 1e6:.0f} um, "
          f"layer closure at the centre {rough.closure[centre] * 1e6:.3f} um; converged {rough.converged}")
    return {"rough": rough, "smooth": smooth, "layer": layer}


if __name__ == "__main__":
    main()
