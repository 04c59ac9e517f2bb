"""Axisymmetric linear elasticity of the two bodies in scikit-fem, condensed onto the interface.

Displacement ``u = (u_r, u_z)``, quadratic Lagrange elements (``ElementTriP2``),
strains ``eps = (du_r/dr, du_z/dz, u_r/r, du_r/dz + du_z/dr)`` (the third one is
the hoop strain ``eps_tt``, the fourth the engineering shear ``gamma_rz``),
isotropic Hooke's law per body, and the ring volume element ``dV = 2 pi r dr dz``
(so nodal forces are total ring forces [force] and the total force of a
pressure ``p`` is ``2 pi integral r p dr``).

Boundary conditions (chosen to mimic two half-spaces loaded far away):

- axis ``r = 0``: ``u_r = 0`` (symmetry);
- bottom of the lower body ``z = -H``: ``u_z = 0``, ``u_r`` free (frictionless support);
- top of the upper body ``z = +H``: ``u_z = -delta_far``, ``u_r`` free (the top is pushed
  rigidly DOWN by ``delta_far`` relative to the bottom);
- outer sides ``r = R``: traction free; interface: the contact traction only.

Sign conventions: ``z`` points up, ``p >= 0`` is compressive; the contact pushes the
upper body up (+z nodal force ``f_i`` on its interface node ``i``) and the lower body
down (``-f_i``). The relative interface displacement is
``d_i = u_z^upper_i - u_z^lower_i = -delta_far + (C f)_i`` where ``C`` is the
interface compliance matrix computed here once; ``delta_far`` moves the upper body
rigidly, which is an exact solution of the unloaded problem.

Static condensation: the bulk stiffness ``K`` never changes, so the free-DOF block is
factorised once (SuperLU) and ``C = B^T K^{-1} B`` is obtained by one block solve
with one right-hand side per interface node; the nonlinear interface problem is then
solved on the interface unknowns only (:mod:`fem_reference.newton`).
"""

from __future__ import annotations

import logging
import math
import time

import numpy as np
from scipy.sparse.linalg import splu

from bem.checks import InputError, check_positive, check_range

__all__ = ["AxiModel", "lame", "check_materials"]

log = logging.getLogger(__name__)

_INTORDER = 4  # quadrature order of the stiffness (integrand ~ r * quadratic, plus u_r v_r / r)
_ORDERING = "MMD_AT_PLUS_A"  # K is SPD: symmetric ordering, measured half the fill of COLAMD


def lame(E, nu):
    """Lame constants ``(lambda, mu)`` [pressure] of Young's modulus ``E`` and Poisson's ratio ``nu``."""
    return E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), E / (2.0 * (1.0 + nu))


def _strain(u, r):
    """``(eps_rr, eps_zz, eps_tt, gamma_rz)`` of a vector field at quadrature points."""
    return (u.grad[0, 0], u.grad[1, 1], u[0] / r, u.grad[0, 1] + u.grad[1, 0])


def _stiffness_form():
    from skfem import BilinearForm

    @BilinearForm
    def stiffness(u, v, w):
        r = w.x[0]
        eu, ev = _strain(u, r), _strain(v, r)
        tr_u, tr_v = eu[0] + eu[1] + eu[2], ev[0] + ev[1] + ev[2]
        normal = eu[0] * ev[0] + eu[1] * ev[1] + eu[2] * ev[2]
        return (w.lam * tr_u * tr_v + 2.0 * w.mu * normal + w.mu * eu[3] * ev[3]) * (2.0 * np.pi * r)

    return stiffness


def _facet_nodes(mesh, facets):
    """Scalar P2 node indices (vertices and mid-edge nodes) of the given facets."""
    return np.unique(np.concatenate([mesh.facets[:, facets].ravel(), mesh.nvertices + facets]))


class AxiModel:
    """Assembled and factorised two-body axisymmetric model.

    Parameters
    ----------
    amesh : fem_reference.mesh.AxiMesh
        The mesh.
    E1, nu1 : float
        Young's modulus [pressure] and Poisson's ratio of the UPPER body (``z >= 0``).
    E2, nu2 : float
        The same for the LOWER body (``z <= 0``); with a coating, ``E`` and ``nu`` are the
        substrate's.
    coating1, coating2 : bem.coating.Coating, optional
        The coating of the upper and the lower body, bonded to it; its thickness must be the
        mesh's (``amesh.coating_thickness``).

    Attributes
    ----------
    basis : skfem.Basis
        Vector P2 basis; DOF ``2 n + c`` is component ``c`` (0: r, 1: z) of scalar node ``n``.
    K : scipy.sparse.csr_matrix
        Stiffness of both bodies without boundary conditions [force/length].
    r : ndarray, shape (n_if,)
        Radii of the interface node pairs, increasing [length].
    weights : ndarray, shape (n_if,)
        Lumped ring areas ``A_i = 2 pi integral phi_i r dr`` of the interface nodes
        [length^2] (row sums of the ring mass matrix of the quadratic interface elements):
        ``2 pi L ra/6``, ``2 pi L (ra + rb)/3`` (mid-node), ``2 pi L rb/6`` per element
        ``[ra, rb]``; ``sum(A_i q(r_i)) = 2 pi integral q r dr`` exactly for a piecewise
        quadratic ``q``, so ``A * p`` is the consistent load of the interpolated pressure.
        The axis node gets ``A_0 = 0``: it carries no force, and its pressure is reported
        by extrapolation (:func:`fem_reference.result.axis_pressure`). (Diagonal/HRZ
        lumping would give it a positive area, but then a point force on the axis, whose
        displacement is log-singular, was measured to spoil the centre displacement by 4 %.)
    timings : dict
        ``assembly`` and ``factorize`` wall-clock times [s].
    """

    def __init__(self, amesh, *, E1, nu1, E2, nu2, coating1=None, coating2=None):
        from skfem import Basis, ElementTriP2, ElementVector, asm

        check_materials(E1, nu1, E2, nu2)
        self.coatings = check_coatings(coating1, coating2, amesh.coating_thickness)
        E, nu = np.array([E1, E2], dtype=float), np.array([nu1, nu2], dtype=float)
        self.amesh, self.E, self.nu = amesh, E, nu
        mesh = amesh.mesh
        t0 = time.perf_counter()
        self.basis = Basis(mesh, ElementVector(ElementTriP2()), intorder=_INTORDER)
        self.scalar_basis = Basis(mesh, ElementTriP2(), intorder=_INTORDER)
        self._check_numbering()
        E_el, nu_el = E[amesh.body], nu[amesh.body]
        for index, coating in enumerate(self.coatings):
            if coating is not None:
                inside = amesh.coated & (amesh.body == index)
                E_el[inside], nu_el[inside] = coating.E, coating.nu
        lam, mu = lame(E_el, nu_el)
        zero = self.basis.zero_w()
        self.lam_w, self.mu_w = zero + lam[:, None], zero + mu[:, None]
        self.K = asm(_stiffness_form(), self.basis, lam=self.lam_w, mu=self.mu_w).tocsr()
        t1 = time.perf_counter()
        self._boundary_conditions()
        self._interface()
        K_ff = self.K[self.free][:, self.free].tocsc()
        self.lu = splu(K_ff, permc_spec=_ORDERING)
        t2 = time.perf_counter()
        self.timings = {"assembly": t1 - t0, "factorize": t2 - t1}
        log.info("model: %d DOFs (%d free), %d interface pairs; assembly %.2f s, factorisation %.2f s",
                 self.n_dofs, self.free.size, self.r.size, t1 - t0, t2 - t1)

    @property
    def n_dofs(self):
        """Total number of displacement DOFs (both bodies)."""
        return int(self.basis.N)

    def _check_numbering(self):
        nv, nf = self.amesh.mesh.nvertices, self.amesh.mesh.nfacets
        expect_v = 2 * np.arange(nv)
        expect_f = 2 * (nv + np.arange(nf))
        if not (np.array_equal(self.basis.nodal_dofs[0], expect_v)
                and np.array_equal(self.basis.facet_dofs[0], expect_f)
                and self.basis.N == 2 * self.scalar_basis.N):
            raise RuntimeError("unexpected scikit-fem DOF numbering of ElementVector(ElementTriP2)")

    def _nodes(self, name):
        return _facet_nodes(self.amesh.mesh, self.amesh.mesh.boundaries[name])

    def _boundary_conditions(self):
        axis = np.union1d(self._nodes("axis_upper"), self._nodes("axis_lower"))
        self.top_z = 2 * self._nodes("top") + 1
        bottom_z = 2 * self._nodes("bottom") + 1
        fixed = np.unique(np.concatenate([2 * axis, self.top_z, bottom_z]))
        self.free = np.setdiff1d(np.arange(self.n_dofs), fixed)
        upper_nodes = np.unique(self.scalar_basis.element_dofs[:, self.amesh.body == 0])
        self.upper_z = 2 * upper_nodes + 1

    def _interface(self):
        mesh = self.amesh.mesh
        x = self.scalar_basis.doflocs
        pairs = []
        for name in ("interface_upper", "interface_lower"):
            nodes = self._nodes(name)
            pairs.append(nodes[np.argsort(x[0, nodes], kind="stable")])
        up, lo = pairs
        scale = self.amesh.radius
        if (up.size != lo.size or np.abs(x[:, up] - x[:, lo]).max() > 1e-12 * scale
                or np.abs(x[1, up]).max() > 1e-12 * scale):
            raise RuntimeError("the interface nodes of the two bodies do not match")
        self.r = x[0, up].copy()
        self.node_up, self.node_lo = up, lo
        self.dof_up, self.dof_lo = 2 * up + 1, 2 * lo + 1
        # lumped ring areas of the quadratic interface elements
        pos = np.full(self.scalar_basis.N, -1)
        pos[up] = np.arange(up.size)
        facets = mesh.boundaries["interface_upper"]
        ra, rb = x[0, mesh.facets[0, facets]], x[0, mesh.facets[1, facets]]
        ia, ib = pos[mesh.facets[0, facets]], pos[mesh.facets[1, facets]]
        im = pos[mesh.nvertices + facets]
        L = np.abs(rb - ra)
        A = np.zeros(up.size)
        np.add.at(A, ia, 2.0 * np.pi * L * ra / 6.0)
        np.add.at(A, ib, 2.0 * np.pi * L * rb / 6.0)
        np.add.at(A, im, 2.0 * np.pi * L * (ra + rb) / 3.0)
        self.weights = A
        free_pos = np.full(self.n_dofs, -1)
        free_pos[self.free] = np.arange(self.free.size)
        self._fup, self._flo = free_pos[self.dof_up], free_pos[self.dof_lo]
        if (self._fup < 0).any() or (self._flo < 0).any():
            raise RuntimeError("an interface z-DOF is constrained")

    def _load(self, f):
        """Free-DOF load of nodal interface forces ``f`` (columns), +z on upper, -z on lower."""
        f = np.atleast_2d(np.asarray(f, dtype=float).T).T
        b = np.zeros((self.free.size, f.shape[1]))
        b[self._fup] += f
        b[self._flo] -= f
        return b

    def interface_compliance(self):
        """Dense ``C`` [length/force]: ``d = u_z^upper - u_z^lower = C f`` at the interface pairs.

        Returns
        -------
        ndarray, shape (n_if, n_if)
            Symmetric positive definite; one solve with the factorised bulk per interface pair.
        """
        n = self.r.size
        C = np.empty((n, n))
        b = np.zeros(self.free.size)
        for j in range(n):  # single-RHS solves: SuperLU's multi-RHS solve is slower (measured)
            b[self._fup[j]], b[self._flo[j]] = 1.0, -1.0
            x = self.lu.solve(b)
            b[self._fup[j]] = b[self._flo[j]] = 0.0
            C[:, j] = x[self._fup] - x[self._flo]
        return 0.5 * (C + C.T)

    def displacement(self, f, delta_far):
        """Full displacement vector [length] for interface forces ``f`` [force] and top motion.

        Parameters
        ----------
        f : ndarray, shape (n_if,)
            Nodal ring forces ``A_i p_i`` at the interface pairs [force].
        delta_far : float
            Downward displacement of the top of the upper body relative to the bottom [length].
        """
        u = np.zeros(self.n_dofs)
        u[self.free] = self.lu.solve(self._load(f))[:, 0]
        u[self.upper_z] -= delta_far
        return u

    def reaction_force(self, u):
        """Compressive force transmitted through the top boundary [force]: ``-sum (K u)_top,z``."""
        return float(-np.sum((self.K @ u)[self.top_z]))

    def reference_correction(self, E_star, b):
        """Truncation compliance ``dc`` [length/force] of the finite bodies (see :mod:`fem_reference.solve`).

        Loads the interface with ``q(r) = (1 - r^2/b^2)^2`` (``r < b``), whose half-space
        relative displacement at the centre is ``u(0) = (2/E*) integral_0^b q dr =
        16 b / (15 E*)`` for the force ``P = pi b^2 / 3``, i.e. ``c_hs = 16 / (5 pi b E*)``.
        With coatings ``c_hs`` is ``(48 / (pi b)) integral_0^inf (s1 + s2)(x / b) J3(x) / x^3 dx``
        (:func:`bem.coating.mode_compliance`; the same value for homogeneous bodies, where
        ``integral J3(x) / x^3 dx = 1/15``). Returns ``dc = c_hs - c_fem`` where ``c_fem = (C f)_0 / sum(f)`` is the same
        quantity of the truncated, far-supported FEM bodies (``dc > 0``: they are stiffer),
        with the nodal loads ``f = weights * q`` (row-sum weights: the consistent load of the
        quadratic interpolant of ``q``). Measured: ``dc`` changes by < 1 % between
        ``b = a`` and ``b = 4 a``, i.e. it is a property of the truncation, not of the load.
        """
        q = np.where(self.r < b, (1.0 - (self.r / b) ** 2) ** 2, 0.0)
        f = self.weights * q
        u = self.lu.solve(self._load(f))[:, 0]
        c_fem = (u[self._fup[0]] - u[self._flo[0]]) / f.sum()
        if any(c is not None for c in self.coatings):
            c_hs = _coated_centre_compliance(self, b)
        else:
            c_hs = 16.0 / (5.0 * math.pi * b * E_star)
        return c_hs - c_fem


def _coated_centre_compliance(model, b):
    """``u(0) / P`` of two half-spaces, coated or not, under ``q = (1 - r^2/b^2)^2`` [length/force].

    The coatings' own half-spaces (``s_inf``, the symbol's high-frequency limit) integrate in closed
    form (``integral J3(x) / x^3 dx = 1/15``); the rest decays as ``exp(-2 x t / b)`` and is
    integrated by 16-point Gauss-Legendre panels of width at most 1 up to ``x t / b = 30``.
    """
    from scipy.special import jv

    from bem.coating import mode_compliance

    bodies = list(zip(model.E, model.nu, model.coatings))
    s_inf = sum((1 - c.nu**2) / c.E if c is not None else (1 - nu**2) / E for E, nu, c in bodies)
    x_max = 30.0 * b / min(c.thickness for _, _, c in bodies if c is not None)
    nodes, weights = np.polynomial.legendre.leggauss(16)
    edges = np.linspace(0.0, x_max, int(math.ceil(x_max)) + 1)
    half = 0.5 * np.diff(edges)[:, None]
    x = 0.5 * (edges[:-1] + edges[1:])[:, None] + half * nodes
    s = sum(mode_compliance(x / b, E, nu, c) for E, nu, c in bodies)
    rest = float(np.sum((s - s_inf) * jv(3, x) / x**3 * weights * half))
    return 48.0 / (math.pi * b) * (s_inf / 15.0 + rest)


def check_coatings(coating1, coating2, thickness):
    """The two coatings, checked against the mesh's coating thicknesses; raise ``InputError``."""
    from bem.coating import Coating

    out = []
    for k, (name, coating) in enumerate((("coating1", coating1), ("coating2", coating2))):
        if coating is not None and not isinstance(coating, Coating):
            raise InputError(f"{name} = {coating!r} is not allowed: it must be a bem.coating.Coating or None.")
        mesh_t = thickness[k]
        if (coating is None) != (mesh_t is None) or (coating is not None and coating.thickness != mesh_t):
            raise InputError(f"{name} = {coating!r} is not allowed: its thickness must be the mesh's coating "
                             f"thickness {mesh_t!r}.")
        if coating is not None and coating.nu > 0.499:
            raise InputError(f"{name}.nu = {coating.nu!r} is not allowed: it must be <= 0.499 (displacement FEM locks).")
        out.append(coating)
    return tuple(out)


def check_materials(E1, nu1, E2, nu2):
    """Validate the body constants; raise ``InputError`` naming the argument."""
    for name, value in (("E1", E1), ("E2", E2)):
        check_positive(name, value)
    for name, value in (("nu1", nu1), ("nu2", nu2)):
        if check_range(name, value, -1.0, 0.5, low_open=True, high_open=True) > 0.499:
            raise InputError(f"{name} = {value!r} is not allowed: it must be <= 0.499 (displacement FEM locks).")
