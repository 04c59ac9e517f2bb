"""The layer law of a rough surface: its mean gap against the mean pressure, as a tabulated ``w(p)``.

A rough surface pressed against a flat closes its mean gap as the load grows. On one periodic
cell (:func:`bem.solve_periodic`) with the initial gap ``h = max z - z``
(:meth:`bem.rough.LatticeHeights.gap`: the highest node touches first, ``h = 0`` there) and
the mean pressure ``pbar``, the mean gap (mean-plane separation) is

    ubar(pbar) = mean(h) - delta(pbar),

``delta`` the approach (the displacements have zero mean over the cell). At first touch
(``pbar -> 0+``: one node touches, nothing deforms) it is

    ubar(0+) = mean(h) = max z - mean z,

the height of the highest summit above the mean plane. The layer law is the closure of the
mean gap,

    w(pbar) = ubar(0+) - ubar(pbar) = delta(pbar),

with the real contact fraction ``A/A0`` (nodes with ``p > 0``) and the interfacial stiffness
``K = -d pbar / d ubar`` [pressure/length] beside it. Used as a layer between two smooth bodies
(:class:`bem.layers.Tabulated`), the roughness closes as it does on the cell under the local
pressure. The elastic energy of a law is convex when ``w`` is non-decreasing, which
:class:`~bem.layers.Tabulated` requires: a ladder whose mean gap rises with the pressure by more
than the solver's tolerance ``rtol ubar(0+)`` is refused by name; smaller rises (the rounding of
a mean gap of zero in full contact) are levelled, ``w_k = max_(j <= k) (ubar(0+) - ubar(p_j))``.
Two rough surfaces in contact are their sum (:func:`bem.rough.combined`) with the effective
modulus ``E*`` of the pair.

**Plastic asperities.** With a ``hardness`` ``H`` every solve of the ladder caps the pressure
at ``H`` (:func:`bem.solve`, elastic-perfectly-plastic): a node at ``H`` flows and its
overlap is the plastic flattening of the asperity. The approach, hence the closure, then
includes the flattening, ``ubar = mean(h) - delta`` is the mean gap of the flattened surface
(smaller than the elastic one at the same pressure), and ``A/A0`` grows. A cell's mean
pressure is at most ``H`` (every node flowing), so the ladder must lie below ``H``. The law
records ``H`` and the share of the cell that flows at each pressure (``plastic_fraction``).

The ladder of mean pressures is solved in order, each solve started from the previous
pressure field scaled by the ratio of the mean pressures (with a hardness, from the solver's own
start where the nodes that field loads cannot carry the next pressure below ``0.8 H``). A step that does not converge stops
the ladder with :class:`LadderNotConverged`: no table is made from it.

**The start of the ladder.** Below its first pressure ``p_1`` the table is a straight line
through ``(0, 0)``: the share ``w(p_1)/w(p_n)`` of the ladder's closure is interpolated, not
solved. A surface whose few highest points close first (spikes, particles) can put most of its
closure there. With ``max_interpolated = s`` the ladder is extended downwards, by the factor
``max(p_2/p_1, 2)`` a step (at most :data:`MAX_EXTENSION` steps), until
``w(p_1) <= s w(p_n)``; the law records the share reached, the rule and the pressures added.

**Persson's theory beside it** (:mod:`bem.rough.persson`): the contact fraction and the mean
gap of the same cell's spectrum, up to the lattice's wave number ``pi/c`` (``c`` the lattice
step), at :data:`PERSSON_POINTS` pressures across the ladder, are recorded with the law.

The table file (TOML) holds a ``[layer]`` table a scene's ``[layer]`` takes as it is
(``law = "tabulated"``, ``p``, ``w``) and a ``[topography]`` table with the ladder's data,
the surface statistics, what was done to the surface (``[topography.preparation]``), the
start rule (``[topography.ladder_start]``), Persson's prediction (``[topography.persson]``) and
the contactlab version; :func:`bem.rough.read_layer_law` reads it back.
Timings: ``benchmarks/layer_from_topography.py``.
"""

from __future__ import annotations

import importlib.metadata
import logging
from dataclasses import dataclass, field

import numpy as np
import tomli_w

from ..checks import InputError, check_choice, check_finite_array, check_positive, check_range, check_rtol, fail
from ..files import write_text
from ..layers import Tabulated
from ..options import METHODS
from .surface import RoughSurface, SurfaceStats

__all__ = ["TopographyLaw", "LadderNotConverged", "layer_from_topography", "MAX_EXTENSION", "PERSSON_POINTS"]

log = logging.getLogger(__name__)

#: most pressures added below the ladder by ``max_interpolated``
MAX_EXTENSION = 40
#: pressures of Persson's prediction recorded with a law
PERSSON_POINTS = 48


class LadderNotConverged(RuntimeError):
    """A step of the pressure ladder did not converge; ``result`` is its :class:`bem.PeriodicContactResult`."""

    def __init__(self, message, index, mean_pressure, result):
        super().__init__(message)
        self.index, self.mean_pressure, self.result = index, mean_pressure, result


@dataclass(frozen=True)
class TopographyLaw:
    """The layer law of a rough surface and the ladder it comes from (module docstring).

    Attributes
    ----------
    law : bem.layers.Tabulated
        ``w(pbar)`` through the ladder's points (and ``(0, 0)``).
    mean_pressure : ndarray
        The ladder ``pbar_k`` [pressure].
    closure : ndarray
        ``w_k = ubar(0+) - ubar(pbar_k)`` [length].
    mean_gap : ndarray
        ``ubar(pbar_k)`` [length].
    first_touch_gap : float
        ``ubar(0+) = mean(h)`` [length].
    contact_fraction : ndarray
        ``A/A0`` at each step [-].
    stiffness : ndarray
        ``K = -d pbar/d ubar = d pbar/d w`` [pressure/length], second-order differences on the
        ladder (``numpy.gradient``); ``inf`` where the ladder is in full contact on both sides of a pressure.
    iterations : ndarray
        Solver iterations of each step.
    E_star : float
        Effective modulus [pressure].
    cell : dict
        ``n_cols``, ``n_rows``, ``step`` [length], ``stretch_y`` of the lattice cell, ``method``
        and ``rtol`` of the solves.
    stats : SurfaceStats
        Of the surface the law comes from.
    version : str
        The contactlab version that made it.
    preparation : dict
        What was done to the surface (:meth:`bem.rough.PatchCell.record`), empty if not given.
    ladder_start : dict
        ``interpolated_share`` ``w(p_1)/w(p_n)`` [-], ``max_interpolated`` (the rule, absent
        without one), ``added`` (pressures added below the ladder asked for).
    persson : dict
        Persson's prediction for the cell's spectrum (module docstring): ``mean_pressure``,
        ``contact_fraction``, ``mean_gap`` (arrays), ``gamma``, ``rms_slope`` (of the spectrum);
        elastic (it knows no hardness).
    hardness : float or None
        The hardness ``H`` of the solves [pressure] (module docstring); ``None``: elastic.
    plastic_fraction : ndarray or None
        The share of the cell at the pressure ``H`` at each step [-] (``plastic_area / A0``);
        ``None`` for an elastic law.
    """

    law: Tabulated
    mean_pressure: np.ndarray
    closure: np.ndarray
    mean_gap: np.ndarray
    first_touch_gap: float
    contact_fraction: np.ndarray
    stiffness: np.ndarray
    iterations: np.ndarray
    E_star: float
    cell: dict
    stats: SurfaceStats
    version: str
    preparation: dict = field(default_factory=dict)
    ladder_start: dict = field(default_factory=dict)
    persson: dict = field(default_factory=dict)
    hardness: float | None = None
    plastic_fraction: np.ndarray | None = None

    def layer_table(self):
        """The scene's ``[layer]`` table: ``{"law": "tabulated", "p": [...], "w": [...]}``."""
        return self.law.to_dict()

    def save(self, path):
        """Write the table file (TOML, module docstring) whole or not at all; returns its path."""
        data = {k: self._plain(getattr(self, k)) for k in ("mean_pressure", "closure", "mean_gap", "contact_fraction",
                                                           "stiffness", "iterations")}
        data.update(first_touch_gap=self.first_touch_gap, E_star=self.E_star, version=self.version, **self.cell)
        if self.hardness is not None:  # TOML has no null: an elastic law has neither key
            data.update(hardness=self.hardness, plastic_fraction=self._plain(self.plastic_fraction))
        data["surface"] = {k: v for k, v in self.stats.as_dict().items() if v is not None}  # TOML has no null
        for name in ("preparation", "ladder_start", "persson"):
            if getattr(self, name):
                data[name] = {k: self._plain(v) if isinstance(v, np.ndarray) else v
                              for k, v in getattr(self, name).items()}
        head = ("# contactlab layer law of a rough surface: w(p) = ubar(0+) - ubar(p), ubar the mean gap of the\n"
                "# periodic cell under the mean pressure p; [layer] is a scene's [layer] table (docs/rough.md).\n")
        if self.ladder_start:
            rule = self.ladder_start.get("max_interpolated")
            head += (f"# Below the first pressure p_1 = {self.mean_pressure[0]:.6g} the law is a straight line "
                     "through\n"
                     f"# (0, 0): {100 * self.ladder_start['interpolated_share']:.3g} % of the closure w(p_n)"
                     + ("" if rule is None else f" (at most {100 * rule:g} %)") + ".\n")
        if self.hardness is not None:
            head += (f"# Plastic asperities: the pressure is capped at the hardness H = {self.hardness:.6g}; "
                     f"at p_n {100 * self.plastic_fraction[-1]:.3g} %\n# of the cell flows.\n")
        return write_text(path, head + "\n" + tomli_w.dumps({"layer": self.layer_table(), "topography": data}))

    @staticmethod
    def _plain(a):
        return np.asarray(a).tolist()


def _version():
    try:
        return importlib.metadata.version("contactlab")
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


def _ladder(pressures):
    p = check_finite_array("pressures", pressures, ndim=1, min_size=2)
    if p[0] <= 0:
        fail("pressures[0]", float(p[0]), "> 0")
    bad = np.flatnonzero(np.diff(p) <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        fail(f"pressures[{i}]", float(p[i]), f"> pressures[{i - 1}] = {float(p[i - 1])!r} (strictly increasing)")
    return p


def _check_monotone(p, ubar, tol):
    """Refuse a ladder whose mean gap rises with the pressure by more than ``tol`` (``w`` must not decrease)."""
    rise = np.flatnonzero(np.diff(ubar) > tol)
    if rise.size:
        i = int(rise[0])
        raise InputError(
            f"pressures[{i}..{i + 1}] = ({float(p[i])!r}, {float(p[i + 1])!r}) are not allowed: the mean gap rises "
            f"from {float(ubar[i])!r} to {float(ubar[i + 1])!r} between them, more than the solver's tolerance "
            f"{tol:.3g}, and the closure w(p) must not decrease (a convex layer energy); solve with a smaller rtol "
            "or space the pressures further apart.")


def _hardness(hardness, p):
    """The checked hardness (``None``: elastic); the ladder must lie below it (module docstring)."""
    if hardness is None:
        return None
    hardness = check_positive("hardness", hardness)
    if p[-1] >= hardness:
        fail(f"pressures[{p.size - 1}]", float(p[-1]), f"< hardness = {hardness!r}: a cell's mean pressure is at "
                                                       "most the hardness, reached when every node flows")
    return hardness


def _guess(res, ratio, hardness, shape):
    """The start of the next step: the pressure of ``res`` scaled by the ratio of the mean pressures; with a
    hardness, none (the solver's own start) where the nodes it loads cannot carry it below ``0.8 H``."""
    guess = res.p.reshape(shape) * ratio
    if hardness is not None and np.count_nonzero(guess) * 0.8 * hardness < guess.sum():
        return None
    return guess


def _solve(solve_periodic, h, pbar, guess, options, k):
    """One step of the ladder (``k < 0``: the ``-k``-th pressure added below it), converged or raised."""
    res = solve_periodic(h, mean_pressure=pbar, x0=guess, **options)
    if not res.converged:
        where = f"step {k} of the ladder" if k >= 0 else f"pressure {-k} added below the ladder"
        raise LadderNotConverged(f"{where} (mean pressure {pbar!r}) did not converge: {res.message}; no layer law "
                                 "is made from it", k, pbar, res)
    return res


def _share(ubar0, first, last):
    """``w(p_1)/w(p_n)`` of two steps' results."""
    top = ubar0 - last.mean_gap
    return (ubar0 - first.mean_gap) / top if top > 0 else 0.0


def _persson(surface, E_star, p, q_max):
    """Persson's prediction for the cell's spectrum up to ``q_max`` across the ladder (module docstring)."""
    from . import persson

    full = persson.cell_spectrum(surface.heights, surface.size)
    keep = full.q <= q_max
    spectrum = persson.Spectrum(full.q[keep], full.weight[keep])
    pressure = np.geomspace(p[0], p[-1], PERSSON_POINTS)
    return dict(gamma=persson.GAMMA, rms_slope=spectrum.rms_slope, mean_pressure=pressure,
                contact_fraction=persson.contact_fraction(pressure, E_star, spectrum),
                mean_gap=persson.mean_gap(pressure, E_star, spectrum))


def layer_from_topography(surface, E_star, *, pressures, n_cols, method="newton", rtol=1e-8, maxiter=None,
                          progress=None, max_interpolated=None, preparation=None, hardness=None):
    """The layer law ``w(pbar)`` of a rough surface pressed against a flat (module docstring).

    Parameters
    ----------
    surface : RoughSurface
        One periodic cell (two rough surfaces: :func:`bem.rough.combined`).
    E_star : float
        Effective modulus of the pair [pressure], ``> 0``.
    pressures : array_like
        The ladder of mean pressures [pressure], ``> 0``, strictly increasing, at least two.
    n_cols : int
        Lattice nodes across the cell (:meth:`RoughSurface.to_lattice`).
    method : str
        A method of :func:`bem.solve_periodic` (``bem.METHODS``).
    rtol : float
        The solver's KKT tolerance, in ``(0, bem.checks.RTOL_MAX]`` (as :func:`bem.solve`).
    maxiter : int, optional
        The solver's iteration limit per step (its default if ``None``).
    progress : callable, optional
        Called after each step as ``progress(k, n, result)``, ``k = 1..n``, ``result`` the
        step's :class:`bem.PeriodicContactResult` (``n`` grows by the steps added below the ladder).
    max_interpolated : float, optional
        The largest share ``w(p_1)/w(p_n)`` of the closure left below the first pressure,
        ``0 < s < 1``: the ladder is extended downwards until it holds (module docstring; a
        warning is logged when :data:`MAX_EXTENSION` steps do not reach it). ``None``: the
        ladder as given (its share is recorded all the same).
    preparation : dict, optional
        What was done to the surface (:meth:`bem.rough.PatchCell.record`), recorded with the law.
    hardness : float, optional
        The hardness ``H`` [pressure], ``> 0`` and above the ladder: every solve caps the pressure
        at ``H`` (plastic asperities, module docstring). ``None``: elastic.

    Returns
    -------
    TopographyLaw

    Raises
    ------
    bem.InputError
        A bad argument, or a ladder whose mean gap rises with the pressure.
    LadderNotConverged
        A step did not converge (its index, pressure and result are attached).
    """
    from ..periodic import solve_periodic

    if not isinstance(surface, RoughSurface):
        fail("surface", type(surface).__name__, "a bem.rough.RoughSurface")
    E_star = check_positive("E_star", E_star)
    p = _ladder(pressures)
    check_choice("method", method, METHODS)
    rtol = check_rtol("rtol", rtol)
    if progress is not None and not callable(progress):
        fail("progress", progress, "callable or None")
    if max_interpolated is not None:
        max_interpolated = check_range("max_interpolated", max_interpolated, 0.0, 1.0, low_open=True, high_open=True)
    if preparation is not None and not isinstance(preparation, dict):
        fail("preparation", type(preparation).__name__, "a dict or None")
    hardness = _hardness(hardness, p)
    lattice = surface.to_lattice(n_cols)
    h = lattice.gap()
    ubar0 = float(h.mean())
    options = dict(step=lattice.step, E_star=E_star, method=method, rtol=rtol,
                   **({} if maxiter is None else {"maxiter": maxiter}),
                   **({} if hardness is None else {"hardness": hardness}))
    ladder, guess = [], None  # (pressure, result)
    for k, pbar in enumerate(p):
        ladder.append((float(pbar), _solve(solve_periodic, h, float(pbar), guess, options, k)))
        guess = _guess(ladder[-1][1], p[k + 1] / pbar, hardness, h.shape) if k + 1 < p.size else None
        if progress is not None:
            progress(k + 1, p.size, ladder[-1][1])
    factor, added, lowest = max(float(p[1] / p[0]), 2.0), [], ladder[0]  # added: below the ladder, highest first
    while (max_interpolated is not None and len(added) < MAX_EXTENSION
           and _share(ubar0, lowest[1], ladder[-1][1]) > max_interpolated):
        pbar = lowest[0] / factor
        lowest = (pbar, _solve(solve_periodic, h, pbar, lowest[1].p.reshape(h.shape) / factor, options,
                               -len(added) - 1))
        added.append(lowest)
        if progress is not None:
            progress(p.size + len(added), p.size + len(added), lowest[1])
    steps = added[::-1] + ladder
    p = np.array([pk for pk, _ in steps])
    mean_gap = np.array([res.mean_gap for _, res in steps], dtype=float)
    fraction = np.array([res.contact_fraction for _, res in steps], dtype=float)
    iterations = np.array([res.iterations for _, res in steps], dtype=int)
    plastic = None if hardness is None else np.array([res.plastic_fraction for _, res in steps], dtype=float)
    _check_monotone(p, mean_gap, rtol * ubar0)
    full = fraction == 1.0  # every node touches: the elastic mean gap is closed, whatever the rounding says
    if plastic is not None:
        full &= plastic == 0  # a flattened surface closes beyond its mean plane
    closure = np.where(full, ubar0, np.maximum.accumulate(ubar0 - mean_gap))  # levels rises within the tolerance
    flat = full & np.r_[full[0], full[:-1]] & np.r_[full[1:], full[-1]]  # full contact on either side: rigid
    slope = np.gradient(closure, p)
    stiffness = np.full(p.size, np.inf)
    np.divide(1.0, slope, out=stiffness, where=(slope > 0) & ~flat)
    cell = dict(n_cols=lattice.n_cols, n_rows=lattice.n_rows, step=lattice.step, stretch_y=lattice.stretch_y,
                method=method, rtol=rtol)
    start = dict(interpolated_share=float(closure[0] / closure[-1]) if closure[-1] > 0 else 0.0, added=len(added))
    if max_interpolated is not None:
        start["max_interpolated"] = max_interpolated
        if start["interpolated_share"] > max_interpolated:
            log.warning("%s: %.3g of the closure lies below the first pressure %.4g after %d pressures added below "
                        "the ladder (max_interpolated = %g): the law is a straight line there", surface.stats.source,
                        start["interpolated_share"], p[0], len(added), max_interpolated)
    return TopographyLaw(Tabulated(p, closure), p, closure, mean_gap, ubar0, fraction, stiffness, iterations, E_star,
                         cell, surface.stats, _version(), dict(preparation or {}), start,
                         _persson(surface, E_star, p, np.pi / lattice.step), hardness, plastic)
