"""Size the BEM candidate region from the expected contact before any solve.

A scene may give the lattice directly (``bem.step``, ``bem.extent``) or relative to the
expected contact: ``bem.nodes_across`` nodes across its smaller diameter and
``bem.extent_factor`` times its semi-axes. The expected semi-axes ``(ax, ay)`` are closed-form
estimates:

- axisymmetric gaps: :func:`bem.reference.estimate_contact_radius` (Hertz radius of the gap,
  combined with the layer-alone radius when there is a layer);
- elliptic paraboloid: Hertz's ellipse (:func:`bem.reference.hertz_elliptic`), scaled by
  the layer's widening of the paraboloid of the same mean radius ``sqrt(Rx Ry)``;
- crowned roller (axis along x): ``ax = l/2``; ``ay`` the Hertz line-contact half-width
  ``b = sqrt(4 P R / (pi l E*))`` (Johnson 1985, ISBN 978-0-521-34796-9, sec. 4.3, load per
  length ``P/l``), or ``sqrt(R delta)`` under approach control (heuristic);
- tables and callables: no estimate (the scene must give ``bem.step`` and ``bem.extent``).

An estimate only sizes the region: the runner enlarges an automatic region when the contact
reaches its border.
"""

from __future__ import annotations

import math

from bem.checks import InputError
from bem.lattice import SQRT3

__all__ = ["expected_semi_axes", "inner_domain", "node_count", "MAX_NODES"]

#: Largest candidate region a scene may ask for (memory and time guard).
MAX_NODES = 4_000_000
#: An automatic extent stays this fraction inside a bounded gap domain.
DOMAIN_MARGIN = 1e-3


def expected_semi_axes(gap, *, E_star, force=None, approach=None, layer=None):
    """Expected contact semi-axes ``(ax, ay)`` [length], or ``None`` without an estimate
    (:meth:`bem.gaps.Gap.expected_semi_axes`).

    Raises
    ------
    bem.InputError
        The estimate failed (e.g. a gap that does not grow with the radius).
    """
    return gap.expected_semi_axes(E_star=E_star, force=force, approach=approach, layer=layer)


def inner_domain(gap):
    """Largest half-widths ``(hx, hy)`` of a centred rectangle inside ``gap.domain`` (may be inf)."""
    (x0, x1), (y0, y1) = gap.domain
    return min(-x0, x1), min(-y0, y1)


def node_count(step, extent):
    """Number of lattice nodes of the candidate region (as :meth:`bem.Lattice.from_extent`)."""
    ex, ey = extent
    cols = 2 * math.floor(ex / step + 1e-9) + 1
    rows = 2 * math.floor(ey / (step * SQRT3 / 2) + 1e-9) + 1
    return cols * rows


def check_estimate(gap, **kw):
    """:func:`expected_semi_axes`, re-raising a failure as InputError with advice."""
    try:
        return expected_semi_axes(gap, **kw)
    except InputError as exc:
        raise InputError(f"bem.nodes_across cannot be used: the contact size could not be estimated ({exc}); "
                         "give bem.step and bem.extent.") from None
