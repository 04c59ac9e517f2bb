"""The domain of an isolated contact: a rectangular region of the half-space (:func:`bem.solve`).

:class:`Region` is one of the two domains of :func:`validation.run.execute_scene` (the other is
the periodic cell, :class:`validation.run.periodic.Cell`): it solves the scene's problem for a
given layer (and, for a layer of the paper's parameters, the calibration solves), and makes the
parts of the run result that belong to a bounded contact (the extent of the region, the contact's
extent, the axial profile). An automatic region (``bem.extent_auto``) grows by
:data:`GROWTH` when the contact reaches its border, at most :data:`MAX_GROWTH` times and never
beyond :func:`validation.scene.sizing.region_limit`; a region the scene gives stays as it is.
"""

from __future__ import annotations

import logging

import numpy as np

import bem

from ..scene.sizing import inner_domain, region_limit, solver_keywords
from .calibrate import CalibrationError
from .parts import AxialProfile
from .result import axial_profile

__all__ = ["Region", "GROWTH", "MAX_GROWTH", "CALIBRATION_KEYS"]

log = logging.getLogger(__name__)

#: an automatic region grows by this factor each time the contact reaches its border ...
GROWTH = 1.5
#: ... at most this many times
MAX_GROWTH = 3
#: the options of the scene's ``[bem]`` that the calibration solves take over; they solve with
#: ``method = "newton"`` and its defaults otherwise, whatever the scene's method
CALIBRATION_KEYS = ("rtol", "precondition", "nested")


class Region:
    """The scene's problem on its candidate region (``bem.step``, ``bem.extent``), enlarged when automatic.

    Parameters
    ----------
    scene : validation.scene.Scene
        A validated scene of an isolated contact.
    messages : list of str
        The run's messages; an enlargement of the region appends one.

    Attributes
    ----------
    step : float
        Lattice step [length].
    extent : tuple of float
        Half-widths of the region [length]: the scene's, or the enlarged region of the last solve
        (the calibration's region carries over to the solve that follows).
    calibration_solves : int
        Number of :meth:`calibrate` calls.
    """

    def __init__(self, scene, messages):
        self.scene, self.messages = scene, messages
        opts = scene.bem
        self.step = opts["step"]
        self.extent = tuple(opts["extent"])
        self.calibration_solves = 0
        problem = dict(E_star=scene.E_star, **scene.load, step=self.step)
        self._solve_kw = dict(problem, **solver_keywords(opts))
        self._calibration_kw = dict(problem, method="newton", **{k: opts[k] for k in CALIBRATION_KEYS if k in opts})

    def solve(self, layer, callback=None):
        """:func:`bem.solve` of the scene's problem with ``layer`` and the scene's solver options."""
        return self._solve(layer, callback, self._solve_kw)

    def calibrate(self, layer):
        """A calibration solve (:func:`validation.run.calibrate.resolve_layer`) with the robust solver.

        Raises
        ------
        validation.run.calibrate.CalibrationError
            The solve did not converge (the layer's parameters would be wrong).
        """
        self.calibration_solves += 1
        res = self._solve(layer, None, self._calibration_kw)
        if not res.converged:
            raise CalibrationError(
                f"the calibration of the layer law ({layer!r}) did not converge with method 'newton': "
                f"{res.message}. The run stops: the layer parameters would be wrong.")
        return res

    def _solve(self, layer, callback, kw):
        for attempt in range(MAX_GROWTH + 1):
            try:
                return bem.solve(self.scene.gap, layer=layer, extent=self.extent, callback=callback, **kw)
            except bem.RegionTooSmallError:
                if not (self.scene.bem["extent_auto"] and self._grow(attempt)):
                    raise
        raise AssertionError("unreachable")  # pragma: no cover

    def _grow(self, attempt):
        """Enlarge :attr:`extent` after the ``attempt``-th solve reached its border: whether it grew.

        Raises
        ------
        bem.RegionTooSmallError
            The region cannot grow: it reaches the gap's domain.
        """
        hx, hy = inner_domain(self.scene.gap)
        limit = region_limit(self.scene.gap)
        grown = tuple(min(GROWTH * e, lim) for e, lim in zip(self.extent, limit))
        if attempt == MAX_GROWTH or grown == self.extent:
            if any(e >= lim for e, lim in zip(self.extent, limit)):
                raise bem.RegionTooSmallError(
                    f"bem.extent = ({self.extent[0]:.6g}, {self.extent[1]:.6g}) cannot hold this load: "
                    f"the contact reaches the end of the gap's domain (|x| < {hx:.6g}, |y| < {hy:.6g}); "
                    "reduce the load or change the shape (e.g. a larger crown).") from None
            return False
        msg = (f"the contact reached the border of the automatic candidate region; extent enlarged "
               f"from ({self.extent[0]:.4g}, {self.extent[1]:.4g}) to ({grown[0]:.4g}, {grown[1]:.4g})")
        log.info(msg)
        self.messages.append(msg)
        self.extent = grown
        return True

    def parts(self, res):
        """The parts of the run result that belong to a bounded contact (:func:`validation.run.result.build_result`).

        Returns
        -------
        dict
            ``bem``: the region's fields of :class:`validation.run.parts.BemPart` (``extent``,
            ``nodes_across_contact``); ``contact_extent`` (farthest loaded node along x and y),
            ``profile`` (:class:`validation.run.parts.AxialProfile` of
            :func:`validation.run.result.axial_profile`) and ``periodic`` (``None``).
        """
        loaded = res.p > 0
        return {"bem": {"extent": list(self.extent), "nodes_across_contact": 2 * res.contact_radius / res.step},
                "contact_extent": {axis: float(np.abs(coord[loaded]).max(initial=0.0))
                                   for axis, coord in (("x", res.x), ("y", res.y))},
                "profile": AxialProfile(**axial_profile(res)), "periodic": None}

    def field(self, res):
        """Extra nodal fields of ``bem_field.vtu`` (:func:`bem.files.write_result_vtu`): the initial gap."""
        return {"initial_gap": self.scene.gap(res.x, res.y)}
