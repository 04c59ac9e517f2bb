"""contactlab BEM: frictionless normal contact of elastic half-spaces with an interface layer.

Boundary elements on the elastic half-space with piecewise-linear (pyramid)
pressure on a regular triangular lattice, closed-form influence coefficients,
FFT-fast products, and Kalker's variational principle generalised to a
nonlinear interface layer (paper sections 4-5, docs/method.md), solved by :func:`solve`
over a domain: a region of the half-space (:class:`HalfSpaceRegion`) or a periodic cell of a
rough surface (:class:`PeriodicCell`; :func:`solve_periodic` is an alias); the stresses below the
surface under the computed pressure (:func:`subsurface_stress`).
"""

from . import checks, gaps, layers
from .errors import InputError, RegionTooSmallError
from .coating import Bodies, Coating
from .lattice import Lattice
from .materials import effective_modulus
from .operator import InfluenceOperator, diagonal_coefficient
from .result import STATUSES, ContactResult
from .options import METHODS, OPTIONS
from .periodic import PeriodicCell, PeriodicContactResult, PeriodicOperator, solve_periodic
from .region import HalfSpaceRegion
from .solve import solve
from .stress import SubsurfaceStress, subsurface_stress
from .coated_subsurface import CoatedStress, coated_stress
from .template import template

__all__ = ["solve", "solve_periodic", "Bodies", "Coating", "HalfSpaceRegion", "PeriodicCell", "PeriodicOperator", "PeriodicContactResult",
           "subsurface_stress", "SubsurfaceStress", "coated_stress", "CoatedStress", "template", "Lattice", "InfluenceOperator",
           "ContactResult", "STATUSES", "METHODS", "OPTIONS", "RegionTooSmallError", "InputError", "checks", "diagonal_coefficient",
           "effective_modulus", "gaps", "layers"]
