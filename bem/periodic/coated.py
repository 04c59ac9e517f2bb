"""The periodic template of coated bodies: the pyramid and its images on a layered half-space.

With coatings (:class:`bem.Bodies`) the surface closure of the pressure mode ``k`` is
``2 s(k) / k`` per unit amplitude, ``s = s1 + s2`` of :mod:`bem.coating`, instead of
``2 / (E* k)``. In lattice units (step ``c = 1``, wavenumbers in 1/step) the periodic template of
:mod:`bem.periodic.kernel` becomes ::

    W_c(x) = (1/A) sum_{G != 0} (2 pi / |G|) E* s(|G| / c) hat(G) exp(i G.x)
           = E* s_inf W(x) + (1/A) sum_{G != 0} (2 pi / |G|) E* (s(|G| / c) - s_inf) hat(G) exp(i G.x),

``E*`` the substrates' effective modulus (:attr:`bem.Bodies.E_star`, the scale of the operator,
``C = c / (pi E*) W_c``), ``s_inf`` the limit of ``s`` for short waves (the coatings' own
``(1 - nu_c**2) / E_c``, or the body's where it is not coated) and ``W`` the homogeneous template.
The first term is the homogeneous operator of modulus ``1 / s_inf``, exact to round-off; the
second, the correction, decays like ``(k t)^2 exp(-2 k t)`` in each coating's ``k t``
(:func:`bem.coating.coating_factor`) and is summed over the aliases ``G`` directly
(:func:`bem.periodic.kernel.alias_sum`), to the wavenumber beyond which every term is below
``1e-17`` of ``E* s_inf`` (the bound ``|hat(k)| <= 2.31 / k^2``), and at ``k t = 40`` at the latest (where
``s - s_inf`` is below ``1e-30 s_inf`` for every coating). Both ends are exact: equal
materials give a correction of exactly zero (``s = s_inf``), a thick coating (``k t`` above 350 at
the cell's longest wave) gives the coating's operator, and every term is formed without overflow.

Cost
    The sum has about ``0.069 N g^2`` terms for ``N`` nodes and the cut ``g`` [1/step], with
    ``g`` close to ``20 c / t`` for the thinnest coating: it grows like ``(c / t)^2``, and is the
    same for every level of nested iteration (``N c^2`` is the cell's area).
    :data:`MAX_TERMS` bounds it; a thinner coating is refused with the step that would resolve it
    (benchmarks/coated_symbol.py measures the build).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ..coating import factor_constants, mode_compliance
from ..errors import InputError
from .kernel import alias_sum, periodic_template

__all__ = ["coated_template", "alias_cut", "thin_limit", "MAX_TERMS"]

#: The largest number of alias terms one coated periodic template sums (memory and time bound).
MAX_TERMS = 400_000_000
_TERM_FLOOR = 1e-17  # terms below this fraction of E* s_inf are left out
_HAT_BOUND = 2.31  # |hat(k)| <= 2.31 / |k|^2 (hat <= sqrt3/2 everywhere)
_SQRT3 = math.sqrt(3.0)
_X_MAX = 40.0  # k t beyond which s - s_inf < 1e-30 s_inf for every coating: the sum stops there at the latest


def _s_inf(E, nu, coating):
    """``s`` of a body for short waves [1/pressure]: the coating's, or the body's own."""
    if coating is not None:
        return (1.0 - coating.nu ** 2) / coating.E
    return float(mode_compliance(0.0, E, nu))


def _excess(k, bodies, step):
    """``s(k / c) - s_inf`` at the wavenumbers ``k`` [1/step] (the coated bodies' terms) [1/pressure]."""
    out = np.zeros(np.shape(k))
    for E, nu, coating in _bodies(bodies):
        if coating is not None:
            out += mode_compliance(np.asarray(k) / step, E, nu, coating) - _s_inf(E, nu, coating)
    return out


def _bodies(bodies):
    return ((bodies.E1, bodies.nu1, bodies.coating1), (bodies.E2, bodies.nu2, bodies.coating2))


def thin_limit(bodies):
    """The compliance ``lim_{q -> 0} 2 (s(q) - s(0)) / q`` of the coatings [length/pressure].

    A coating much thinner than the step is, on the lattice, the substrate plus this linear layer
    ``w = lam p`` (docs/method.md, "Coated bodies on the periodic cell"): ``2 t s_c phi'(0)`` per
    coating, with ``phi'(0) = (N'(0) D(0) - N(0) D'(0)) / D(0)^2`` of the numerator ``N`` and the
    denominator ``D`` of :func:`bem.coating.coating_factor`. On a rigid substrate it is the
    oedometric compliance (:func:`bem.coating.oedometric_compliance`).
    """
    total = 0.0
    for E, nu, coating in _bodies(bodies):
        if coating is None:
            continue
        nu_c = coating.nu
        one_m_lam, one_m_kap, one_m_lk = factor_constants(coating, E, nu)
        lam, kap = 1.0 - one_m_lam, 1.0 - one_m_kap
        d0 = one_m_lam * one_m_kap
        dphi = (4.0 * kap * (1.0 + lam) * d0 - one_m_lk * (2.0 * (lam + kap) - 4.0 * lam * kap)) / (d0 * d0)
        total += 2.0 * coating.thickness * (1.0 - nu_c ** 2) / coating.E * dphi
    return total


def _thin_hint(lam):
    where = "docs/method.md, coated bodies on the periodic cell"
    if lam > 0:
        return (f"A coating much thinner than the step is, on this lattice, the substrate with the linear layer "
                f"w = lam p, lam = {lam:.6g} (bem.layers.Linear; {where}).")
    return (f"A coating much thinner than the step stiffens the substrate's surface by the compliance {lam:.6g} on "
            f"the diagonal, which no layer law stands for ({where}).")


def alias_cut(bodies, step):
    """The largest ``|G|`` [1/step] of the correction sum: beyond it every term is below ``1e-17 E* s_inf``."""
    t_min = min(c.thickness for _, _, c in _bodies(bodies) if c is not None) / step
    s_inf = sum(_s_inf(*b) for b in _bodies(bodies))
    k = np.linspace(0.0, _X_MAX, 4001)[1:] / t_min
    bound = 2 * math.pi / k * np.abs(_excess(k, bodies, step)) * np.minimum(_SQRT3 / 2, _HAT_BOUND / (k * k))
    above = np.nonzero(bound > _TERM_FLOOR * s_inf)[0]
    return float(k[min(above[-1] + 1, k.size - 1)]) if above.size else float(k[0])


def coated_template(n_rows, n_cols, step, bodies):
    """``W_c`` at every node of a cell of ``n_cols x n_rows`` nodes (lattice units), for coated bodies.

    Parameters
    ----------
    n_rows, n_cols : int
        Rows (even) and columns of the cell.
    step : float
        Lattice step ``c`` [length] (the coatings' thicknesses are in its unit).
    bodies : bem.Bodies
        The two bodies; at least one coated.

    Returns
    -------
    ndarray, shape ``(n_rows, n_cols)``, read-only
        ``W_c`` at the offset of node ``(q, r)`` from node ``(0, 0)``, brick storage: the
        displacement of a pyramid of height ``p`` is ``c p W_c / (pi E*)``, ``E* = bodies.E_star``.

    Raises
    ------
    bem.InputError
        A coating so thin against the step that the sum would exceed :data:`MAX_TERMS` terms.
    """
    return _cached(int(n_rows), int(n_cols), float(step), bodies)


@lru_cache(maxsize=8)  # the levels of nested iteration of one or two cells
def _cached(n_rows, n_cols, step, bodies):
    E_star = bodies.E_star
    s_inf = sum(_s_inf(*b) for b in _bodies(bodies))
    g_cut = alias_cut(bodies, step)
    terms = 0.069 * n_rows * n_cols * g_cut * g_cut  # (sqrt3/2) N g^2 / (4 pi): the G in the disc
    if terms > MAX_TERMS:
        t = min(c.thickness for _, _, c in _bodies(bodies) if c is not None)
        fine = step * math.sqrt(MAX_TERMS / terms)
        raise InputError(
            f"thickness = {t!r} is not allowed with step = {step!r} on this cell of {n_rows * n_cols} nodes: the "
            f"periodic coated symbol would sum about {terms:.2g} alias terms (at most {MAX_TERMS:.0e}, which a step "
            f"of {fine:.3g} or a cell of fewer nodes keeps). {_thin_hint(thin_limit(bodies))}")

    def radial(k):
        return 2 * math.pi / k * E_star * _excess(k, bodies, step)

    w = E_star * s_inf * periodic_template(n_rows, n_cols) + alias_sum(n_rows, n_cols, radial, g_cut)
    w -= w.mean()  # zero to round-off already: hat vanishes on the nonzero aliases of G = 0
    w.setflags(write=False)
    return w
