"""The domain of an isolated contact: a rectangular region of the half-space (:class:`bem.HalfSpaceRegion`).

:class:`Region` is one of the two domains of :func:`validation.run.execute_scene` (the other is
the periodic cell, :class:`validation.run.periodic.Cell`): it says what :func:`bem.solve` solves
(the scene's gap, its load, the candidate region of ``bem.step`` and ``bem.extent``) and makes the
parts of the run result that belong to a bounded contact (the region's extent, the contact's
extent, the axial profile). An automatic region (``bem.extent_auto``, sized by
:mod:`validation.scene.sizing`) grows in :func:`bem.solve` when the contact reaches its border
(:class:`bem.HalfSpaceRegion`, ``grow=True``); a region the scene gives stays as it is.
"""

from __future__ import annotations

import numpy as np

import bem

from .parts import AxialProfile
from .result import axial_profile

__all__ = ["Region"]


class Region:
    """The scene's problem on its candidate region (module docstring).

    Parameters
    ----------
    scene : validation.scene.Scene
        A validated scene of an isolated contact.

    Attributes
    ----------
    step : float
        Lattice step [length].
    gap : bem.gaps.Gap
        The initial gap ``h(x, y)``.
    load : dict
        The load keywords of :func:`bem.solve`: ``force`` and ``approach`` (one is ``None``).
    bem_domain : bem.HalfSpaceRegion
        The region of the scene (``bem.step``, ``bem.extent``), growing when automatic.
    """

    def __init__(self, scene):
        self.scene = scene
        self.step = scene.bem["step"]
        self.gap = scene.gap
        self.load = dict(scene.load)
        self.bem_domain = bem.HalfSpaceRegion(self.step, tuple(scene.bem["extent"]), grow=scene.bem["extent_auto"])

    def parts(self, res):
        """The parts of the run result that belong to a bounded contact (:func:`validation.run.result.build_result`).

        Returns
        -------
        dict
            ``bem``: the region's fields of :class:`validation.run.parts.BemPart` (``extent``: the
            region solved on, ``nodes_across_contact``); ``contact_extent`` (farthest loaded node
            along x and y), ``profile`` (:class:`validation.run.parts.AxialProfile` of
            :func:`validation.run.result.axial_profile`) and ``periodic`` (``None``).
        """
        loaded = res.p > 0
        return {"bem": {"extent": list(res.domain.extent), "nodes_across_contact": 2 * res.contact_radius / res.step},
                "contact_extent": {axis: float(np.abs(coord[loaded]).max(initial=0.0))
                                   for axis, coord in (("x", res.x), ("y", res.y))},
                "profile": AxialProfile(**axial_profile(res)), "periodic": None}

    def field(self, res):
        """Extra nodal fields of ``bem_field.vtu`` (:func:`bem.files.write_result_vtu`): the initial gap."""
        return {"initial_gap": self.gap(res.x, res.y)}
