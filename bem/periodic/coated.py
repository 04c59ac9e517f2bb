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

Routes
    The sum has about ``0.069 N g^2`` terms for ``N`` nodes and the cut ``g`` [1/step], with
    ``g`` close to ``20 c / t`` for the thinnest coating: it grows like ``(c / t)^2``, and is the
    same for every level of nested iteration (``N c^2`` is the cell's area). A coating whose own
    sum would exceed :data:`ALIAS_PER_NODE` terms a node and :data:`ALIAS_FLOOR` terms (or
    :data:`MAX_TERMS`) takes the real-space route of :mod:`bem.periodic.coated_thin` where the cell
    admits it
    (:func:`bem.periodic.coated_thin.admits`: the images within the coating's reach, 8 steps at
    least, about ``40 t`` for a soft coating, ``6600 t`` at ``E_c = 100 E_s``, at most
    :data:`bem.periodic.coated_thin.MAX_OFFSETS` coefficients of the half-space region): its part of
    the template split at the substrate's ``s(0)`` instead of ``s_inf``, the half-space region's
    coefficients at the images within the reach and the tail of the others in closed form, at a
    cost that does not depend on ``t`` on a cell longer than twice the reach. Both routes are
    exact where they run (tests/bem/test_coated_periodic_thin.py); the switch is one of cost
    (:func:`routes`, per coated body). A coating that neither takes (its sum above
    :data:`MAX_TERMS`, its images within reach above
    :data:`bem.periodic.coated_thin.MAX_OFFSETS` coefficients) is refused with the step that
    would take it (benchmarks/coated_symbol.py measures the build).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ..coating import factor_constants, mode_compliance
from ..errors import InputError
from .coated_thin import admits, refusal, thin_part
from .kernel import alias_sum, periodic_template

__all__ = ["coated_template", "alias_cut", "routes", "thin_limit", "ALIAS_FLOOR", "ALIAS_PER_NODE", "MAX_TERMS"]

#: The largest number of alias terms one coated periodic template sums (memory and time bound).
MAX_TERMS = 400_000_000
#: Alias terms a node above which a coating takes the real-space route where it can (cost, not accuracy).
ALIAS_PER_NODE = 30.0
#: Alias terms below which a coating keeps the alias sum (the real-space route's fixed cost: the tabulation
#: of the coating's remainder kernel, up to seconds for a stiff coating).
ALIAS_FLOOR = 10_000_000
_TERM_FLOOR = 1e-17  # terms below this fraction of E* s_inf are left out
_HAT_BOUND = 2.31  # |hat(k)| <= 2.31 / |k|^2 (hat <= sqrt3/2 everywhere)
_SQRT3 = math.sqrt(3.0)
_X_MAX = 40.0  # k t beyond which s - s_inf < 1e-30 s_inf for every coating: the sum stops there at the latest


def _s_inf(E, nu, coating):
    """``s`` of a body for short waves [1/pressure]: the coating's, or the body's own."""
    if coating is not None:
        return (1.0 - coating.nu ** 2) / coating.E
    return float(mode_compliance(0.0, E, nu))


def _excess(k, parts, step):
    """``s(k / c) - s_inf`` of the coated bodies ``parts`` at the wavenumbers ``k`` [1/step] [1/pressure]."""
    out = np.zeros(np.shape(k))
    for E, nu, coating in parts:
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
    return _cut([b for b in _bodies(bodies) if b[2] is not None], bodies, step)


def _cut(parts, bodies, step):
    """:func:`alias_cut` of the coated bodies ``parts`` alone."""
    t_min = min(c.thickness for _, _, c in parts) / step
    s_inf = sum(_s_inf(*b) for b in _bodies(bodies))
    k = np.linspace(0.0, _X_MAX, 4001)[1:] / t_min
    bound = 2 * math.pi / k * np.abs(_excess(k, parts, step)) * np.minimum(_SQRT3 / 2, _HAT_BOUND / (k * k))
    above = np.nonzero(bound > _TERM_FLOOR * s_inf)[0]
    return float(k[min(above[-1] + 1, k.size - 1)]) if above.size else float(k[0])


def routes(n_rows, n_cols, step, bodies):
    """The coated bodies (1, 2) of the alias sum and of the real-space route on this cell, ``(alias, real)``.

    A coating goes the real-space way (:mod:`bem.periodic.coated_thin`) when its own alias sum would
    exceed :data:`ALIAS_PER_NODE` terms a node and :data:`ALIAS_FLOOR` terms (or :data:`MAX_TERMS`)
    and the cell admits it (:func:`bem.periodic.coated_thin.admits`); the alias sum otherwise. Both
    are exact where they run; the switch is one of cost.
    """
    alias, real = [], []
    for i, (E, nu, coating) in enumerate(_bodies(bodies), start=1):
        if coating is None:
            continue
        terms = 0.069 * n_rows * n_cols * _cut([(E, nu, coating)], bodies, step) ** 2
        if terms > min(max(ALIAS_PER_NODE * n_rows * n_cols, ALIAS_FLOOR), MAX_TERMS) and admits(
                n_rows, n_cols, step, bodies, i):
            real.append(i)
        else:
            alias.append(i)
    return tuple(alias), tuple(real)


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
    alias, real = routes(n_rows, n_cols, step, bodies)
    parts = [b for i, b in enumerate(_bodies(bodies), start=1) if i in alias]
    if parts:
        g_cut = _cut(parts, bodies, step)
        terms = 0.069 * n_rows * n_cols * g_cut * g_cut  # (sqrt3/2) N g^2 / (4 pi): the G in the disc
        if terms > MAX_TERMS:
            _refuse(n_rows, n_cols, step, bodies, alias, terms)
    s_base = sum(float(mode_compliance(0.0, E, nu)) if i in real else _s_inf(E, nu, c)
                 for i, (E, nu, c) in enumerate(_bodies(bodies), start=1))
    w = E_star * s_base * periodic_template(n_rows, n_cols)
    if parts:
        def radial(k):
            return 2 * math.pi / k * E_star * _excess(k, parts, step)

        w = w + alias_sum(n_rows, n_cols, radial, g_cut)
    if real:
        w = w + thin_part(n_rows, n_cols, step, bodies, real)
    w -= w.mean()  # the G = 0 term (the alias sum's mean is zero to round-off: hat vanishes on the aliases of 0)
    w.setflags(write=False)
    return w


def _refuse(n_rows, n_cols, step, bodies, alias, terms):
    """Refuse the cell: the alias sum of the bodies ``alias`` (1, 2) is too long; named by the thinnest coating."""
    coating = {i: c for i, (_, _, c) in enumerate(_bodies(bodies), start=1)}
    i = min(alias, key=lambda k: coating[k].thickness)
    t = coating[i].thickness
    fine = step * math.sqrt(MAX_TERMS / terms)
    raise InputError(
        f"thickness = {t!r} is not allowed with step = {step!r} on this cell of {n_rows * n_cols} nodes: the "
        f"periodic coated symbol would sum about {terms:.2g} alias terms (at most {MAX_TERMS:.0e}, which a step "
        f"of {fine:.3g} or a cell of fewer nodes keeps), and {refusal(n_rows, n_cols, step, bodies, i)}. "
        f"{_thin_hint(thin_limit(bodies))}")
