"""Reference solutions: closed forms and a-priori estimates, free of any solver.

Every closed form is a result with the names every solver result uses
(:class:`bem.ContactResult`, :class:`fem_reference.FemResult`): ``p_max``,
``contact_radius``, ``contact_area``, ``approach``, ``force``, ``pressure(x, y)``,
``converged`` (always true) and ``message``; so a comparison needs no adapter.

- :mod:`bem.reference.hertz`: Hertz contact of a paraboloid and of an elliptic paraboloid;
- :mod:`bem.reference.layer_limit`: the layer-dominated (rigid-body) limit;
- :mod:`bem.reference.westergaard`: Westergaard's wavy (periodic) contact;
- :mod:`bem.reference.estimate`: the expected contact radius of an axisymmetric gap, which
  sizes the BEM region and the FEM mesh before any solve.
"""

from .estimate import estimate_contact_radius, hertz_radius, layer_radius
from .hertz import HertzElliptic, HertzSphere, hertz_elliptic, hertz_sphere
from .layer_limit import (
           RigidLayerParaboloid,
           rigid_layer_force,
           rigid_layer_paraboloid,
           rigid_layer_pressure,
)
from .westergaard import Westergaard, westergaard

__all__ = ["Westergaard", "westergaard", "HertzSphere", "HertzElliptic", "RigidLayerParaboloid", "hertz_sphere", "hertz_elliptic",
           "rigid_layer_pressure", "rigid_layer_paraboloid", "rigid_layer_force", "estimate_contact_radius",
           "hertz_radius", "layer_radius"]
