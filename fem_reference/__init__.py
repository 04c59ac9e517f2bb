"""Axisymmetric FEM reference for the layered contact of two elastic bodies (docs/method.md section 4).

gmsh meshes of the two bodies in the (r, z) half-plane (:mod:`fem_reference.mesh`),
axisymmetric linear elasticity in scikit-fem with quadratic triangles
(:mod:`fem_reference.model`), the interface layer law of :mod:`bem.layers` as a penalty
(:mod:`fem_reference.interface`), Newton's method on the statically condensed interface
problem (:mod:`fem_reference.newton`), and the recovered stresses and the field as a mesh
(:mod:`fem_reference.fields`). It returns data and writes no files: the ParaView file is
written by :func:`bem.files.write_vtu` (``write_vtu(path, **result.field())``). Heavy
packages are imported inside the functions.
"""

from .mesh import AxiMesh, build_mesh
from .result import STATUSES, FemResult
from .solve import solve

__all__ = ["solve", "FemResult", "STATUSES", "build_mesh", "AxiMesh"]
