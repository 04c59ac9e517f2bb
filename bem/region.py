"""The half-space domain of :func:`bem.solve`: a rectangular candidate region of the triangular lattice.

:class:`HalfSpaceRegion` is the lattice step and the half-widths of the region ``|x| <= ex``,
``|y| <= ey`` where contact may occur. An automatic region (``extent="auto"``) starts at
:data:`EXTENT_FACTOR` times the gap's expected contact semi-axes
(:meth:`bem.gaps.Gap.expected_semi_axes`) and, like any region given with ``grow=True``, is
enlarged :data:`GROW` times, at most :data:`MAX_GROW` times and never beyond
:func:`region_limit`, when the contact reaches its border. The other domain is the periodic
cell, :class:`bem.periodic.PeriodicCell`; both offer the methods :func:`bem.solve` calls.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from .checks import check_bool, check_gap_values, check_node_count, check_positive
from .errors import InputError, RegionTooSmallError
from .lattice import Lattice, extent_pair, node_count
from .operator import InfluenceOperator
from .result import ContactResult
from .windows import solve_in_window

__all__ = ["HalfSpaceRegion", "inner_domain", "region_limit", "DOMAIN_MARGIN", "EXTENT_FACTOR", "GROW",
           "MAX_GROW"]

log = logging.getLogger(__name__)

#: An automatic region stays this fraction inside a bounded gap domain.
DOMAIN_MARGIN = 1e-3
#: An automatic region starts at this many times the expected contact semi-axes.
EXTENT_FACTOR = 1.5
#: A growing region is enlarged this many times when the contact reaches its border ...
GROW = 1.5
#: ... at most this many times.
MAX_GROW = 3
_COARSEST_NODES = 4096  # nested iteration stops coarsening below this many nodes
# KKT residual to which the coarser lattices of nested iteration are solved, per solver (the layer methods:
# the default). Kalker's QP, whose directions are kept when the contact changes, takes on the finest lattice of the
# rough sphere of benchmarks/cases.py from 1e-4 about the iterations it takes from 1e-6 (26, 28, 25, 25 against
# 26, 26, 24, 24 from 512^2 to 4096^2), and the coarser lattices take two fifths fewer; from 1e-3 the finest
# lattice takes longer at 2048^2 (27 iterations). The layer methods: Newton's paths gain nothing measurable; the
# plain loop (no preconditioner, restarted at entering nodes) takes 253 iterations at 256^2 from 1e-4 against 96
# (docs/performance.md).
_COARSE_RTOL = {"kalker": 1e-4}
_COARSE_RTOL_DEFAULT = 1e-6


def inner_domain(gap):
    """Largest half-widths ``(hx, hy)`` [length] of a centred rectangle inside ``gap.domain`` (may be inf;
    a gap without a ``domain`` is defined everywhere)."""
    (x0, x1), (y0, y1) = getattr(gap, "domain", ((-math.inf, math.inf), (-math.inf, math.inf)))
    return min(-x0, x1), min(-y0, y1)


def region_limit(gap):
    """The largest half-widths ``(ex, ey)`` [length] of an automatic region: :data:`DOMAIN_MARGIN` inside
    :func:`inner_domain` (may be inf). The automatic start and the enlargement both stop there."""
    hx, hy = inner_domain(gap)
    return (1 - DOMAIN_MARGIN) * hx, (1 - DOMAIN_MARGIN) * hy


class HalfSpaceRegion:
    """A rectangular candidate region of the half-space, the domain of :func:`bem.solve` for a bounded contact.

    Parameters
    ----------
    step : float
        Lattice step ``c`` [length], > 0.
    extent : float, (float, float) or "auto"
        Half-widths ``(ex, ey)`` of the region ``|x| <= ex``, ``|y| <= ey`` [length] (one number
        for a square), or ``"auto"``: :data:`EXTENT_FACTOR` times the gap's expected contact
        semi-axes, within :func:`region_limit`. The region holds at most
        :func:`bem.checks.max_nodes` nodes (checked before anything is built).
    grow : bool, optional
        Enlarge the region when the contact reaches its border (module docstring). Default:
        True for ``extent="auto"``, False otherwise (the contact at the border is then a
        :class:`bem.RegionTooSmallError`).
    """

    result_class = ContactResult

    def __init__(self, step, extent="auto", *, grow=None):
        self.step = check_positive("step", step)
        self.extent = "auto" if isinstance(extent, str) and extent == "auto" else extent_pair("extent", extent)
        self._given = extent  # as the user wrote it, for messages
        self.grow = (self.extent == "auto") if grow is None else check_bool("grow", grow)
        if self.extent != "auto":
            check_node_count("step", step, node_count(self.step, self.extent))

    def __repr__(self):
        return f"HalfSpaceRegion(step={self.step!r}, extent={self.extent!r}, grow={self.grow!r})"

    # -- the problem on the region -------------------------------------------------------------

    def check_gap(self, gap):
        """Raise unless ``gap`` is a callable ``h(x, y)``."""
        if not callable(gap):
            raise InputError(f"gap = {gap!r} is not allowed: it must be callable (a bem.gaps shape or "
                             "h(x, y)) on a half-space region.")

    def resolved(self, gap, *, E_star, force, approach, layer):
        """This region with a numeric extent (``"auto"``: from the gap's expected contact), checked against the gap."""
        if self.extent != "auto":
            region = self
        else:
            axes = getattr(gap, "expected_semi_axes", None)
            axes = None if axes is None else axes(E_star=E_star, force=force, approach=approach, layer=layer)
            if axes is None:
                raise InputError(f"extent = 'auto' is not allowed with gap = {gap!r}: the gap has no estimate "
                                 "of the contact size; give extent.")
            limit = region_limit(gap)
            region = HalfSpaceRegion(self.step, tuple(min(EXTENT_FACTOR * a, lim) for a, lim in zip(axes, limit)),
                                     grow=self.grow)
        if hasattr(gap, "check_region"):  # a gap known on a bounded region only (bem.gaps.RegionTable)
            gap.check_region(region._given)
        return region

    def lattice(self):
        """The candidate lattice (:meth:`bem.lattice.Lattice.from_extent`) of a resolved region."""
        return Lattice.from_extent(self.step, self.extent)

    def nodal_gap(self, gap, lattice):
        """The initial gap at the candidate nodes of ``lattice`` (brick array, 0 off them) [length]."""
        x, y = lattice.x, lattice.y
        h = check_gap_values(gap(x, y), {"x": x, "y": y}, mask=lattice.mask,
                             region="over the candidate region (make extent smaller or fix the gap)")
        del x, y
        lattice.release_coordinates()  # not held through the solve (the result makes them again)
        return np.where(lattice.mask, h, 0.0)

    def check_approach(self, approach, h, layer):
        """Every approach > 0 is allowed on a half-space region."""

    def levels(self, lattice, h, gap, nested):
        """``(lattice, gap)`` pairs of nested iteration, from the coarsest lattice to ``lattice`` (gap ``h``)."""
        levels = [lattice]
        while nested:
            coarse = levels[-1].coarsen()
            if coarse is None or coarse.n_nodes < _COARSEST_NODES:
                break
            levels.append(coarse)
        return [(lat, h if lat is lattice else self.nodal_gap(gap, lat)) for lat in levels[::-1]]

    def coarse_rtol(self, solver, precondition=True):
        """KKT residual to which the coarser lattices of nested iteration are solved (the plain loop of Polonsky
        and Keer, ``precondition=False``: the default of the layer methods)."""
        return _COARSE_RTOL.get(solver, _COARSE_RTOL_DEFAULT) if precondition else _COARSE_RTOL_DEFAULT

    def operator(self, lattice, E_star, backend, *, bodies=None):
        """The influence operator ``C`` of the half-space on ``lattice`` (of coated ``bodies`` where given)."""
        if bodies is None:
            return InfluenceOperator(lattice, E_star, device=backend)
        return InfluenceOperator(lattice, E_star, device=backend, bodies=bodies)

    def solve_level(self, run, make_op, lattice, h, kw, delta, solver, handover=None):
        """One level of nested iteration (``delta``: the approach it knows, or None; ``handover``: what the coarser
        level hands over): on a window of :mod:`bem.windows` where there is one; the solution, the operators used
        and the product ``C p`` on the lattice where the level made it (:func:`bem.windows.solve_in_window`)."""
        return solve_in_window(run, make_op, lattice, h, kw, delta, solver, handover)

    def refine(self, coarse, p, fine):
        """The coarse solution interpolated onto the next finer lattice."""
        return coarse.prolong(p, fine)  # = coarse.interpolate(p, fine.x, fine.y) * fine.mask, by slices

    def check_solution(self, lattice, p):
        """Raise :class:`bem.RegionTooSmallError` when the contact reaches the border of the region."""
        touching = lattice.border & (p > 0)
        if touching.any():
            raise RegionTooSmallError(
                f"extent = {self._given!r} is not allowed for this load: the contact reaches the border of the "
                f"candidate region at {int(touching.sum())} node(s). Make extent larger (the contact must stay "
                "inside it) or reduce the load. For a rough surface patch whose contact spreads over the whole "
                "region, the model is a periodic cell: bem.solve_periodic, or bem.solve with domain=bem.PeriodicCell(...).")

    def grown(self, gap, attempt):
        """The enlarged region after the contact reached the border of this one, the ``attempt``-th
        enlargement of the solve; ``None`` where it does not grow (no ``grow``, or :data:`MAX_GROW`
        enlargements made). Raises :class:`bem.RegionTooSmallError` when the region has reached
        :func:`region_limit`."""
        if not self.grow:
            return None
        limit = region_limit(gap)
        grown = tuple(min(GROW * e, lim) for e, lim in zip(self.extent, limit))
        if attempt == MAX_GROW or grown == self.extent:
            if any(e >= lim for e, lim in zip(self.extent, limit)):
                hx, hy = inner_domain(gap)
                raise RegionTooSmallError(
                    f"extent = ({self.extent[0]:.6g}, {self.extent[1]:.6g}) cannot hold this load: the contact "
                    f"reaches the end of the gap's domain (|x| < {hx:.6g}, |y| < {hy:.6g}); reduce the load or "
                    "change the shape (e.g. a larger crown).")
            return None
        return HalfSpaceRegion(self.step, grown, grow=True)
