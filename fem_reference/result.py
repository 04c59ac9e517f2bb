"""The result of an FEM reference solve and the measures taken on the interface."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["FemResult", "STATUSES", "axis_pressure", "edge_radius"]

#: The outcomes the FEM reference reports in ``status``: the stopping rule was met
#: (``"converged"``), the Newton budget ran out (``"maxiter"``), the line search found no
#: descent (``"stalled"``), a residual was not finite (``"nonfinite"``), the interface
#: compliance or the Newton matrix was singular (``"singular"``), or the contact reaches the
#: outer boundary of the domain (``"boundary"``).
STATUSES = ("converged", "maxiter", "stalled", "nonfinite", "singular", "boundary")


def axis_pressure(r, p):
    """Pressure at the axis node from the next two nodes, ``p(r) ~ p0 + c r^2`` [pressure].

    The ring area of the axis node is 0 in the r-weighted lumped rule, so that node carries
    no force and its own overlap is not constrained; the pressure there is the even
    (``p(-r) = p(r)``) quadratic through the next two nodes.
    """
    r1, r2 = r[1] ** 2, r[2] ** 2
    return max((r2 * p[1] - r1 * p[2]) / (r2 - r1), 0.0)


def edge_radius(r, p, g, *, smooth):
    """Radius of the edge of the loaded zone ``p > 0``, interpolated between the nodes [length].

    Not the area-equivalent radius ``sqrt(A / pi)`` of ``bem.ContactResult.contact_radius``:
    the two are different estimators of the size of the contact.

    Definition: let ``k`` be the outermost interface node with ``p_k > 0``; the edge lies in
    ``[r_k, r_{k+1}]``:

    - with a layer, the overlap ``g`` crosses zero linearly there (``p = w^{-1}(g)`` and ``g``
      is smooth across the edge): ``r_k + (r_{k+1} - r_k) g_k / (g_k - g_{k+1})``;
    - smooth bodies (penalty only): ``g`` inside is just the penalty penetration, while the
      pressure has Hertz's square-root edge, so ``p^2`` is extrapolated linearly from the
      nodes ``k-1, k`` to zero, clipped to ``[r_k, r_{k+1}]``.

    Returns 0 without contact.
    """
    loaded = np.nonzero(p > 0)[0]
    if loaded.size == 0:
        return 0.0
    k = int(loaded[-1])
    if k + 1 >= r.size:
        return float(r[-1])
    lo, hi = r[k], r[k + 1]
    if smooth:
        if k >= 1 and p[k - 1] > p[k]:
            q0, q1 = p[k - 1] ** 2, p[k] ** 2
            edge = lo + q1 * (lo - r[k - 1]) / (q0 - q1)
        else:
            edge = 0.5 * (lo + hi)
    else:
        gk, gn = g[k], g[k + 1]
        edge = lo + (hi - lo) * gk / (gk - gn) if gk > gn else 0.5 * (lo + hi)
    return float(min(max(edge, lo), hi))


@dataclass
class FemResult:
    """Solution of the axisymmetric FEM reference problem.

    Attributes
    ----------
    r : ndarray, shape (n,)
        Radii of the interface node pairs, increasing [length].
    p : ndarray, shape (n,)
        Contact pressure at those nodes [pressure] (axis node: :func:`axis_pressure`).
    overlap : ndarray, shape (n,)
        Overlap ``g = delta - h - d`` of the node pairs [length]: the layer closure ``w(p)``
        in contact, minus the deformed gap where open (``< 0``).
    initial_gap : ndarray, shape (n,)
        Initial gap ``h(r, 0)`` at the nodes [length].
    approach : float
        Half-space approach ``delta`` [length] (truncation-corrected, see ``truncation``).
    force : float
        Total force ``sum A_i p_i`` (r-weighted lumped integral ``2 pi integral r p dr``) [force].
    force_reaction : float
        Force from the reactions of the top boundary, ``-sum (K u)_top,z`` [force].
    p_max : float
        Largest nodal pressure [pressure].
    edge_radius : float
        Edge of the loaded zone, interpolated between the nodes [length], see
        :func:`edge_radius`.
    converged : bool
        Whether Newton's stopping rule was met (and the contact stays inside the domain):
        ``status == "converged"``.
    message : str
        Why the solve stopped, for people to read.
    status : str
        The outcome, one of :data:`fem_reference.result.STATUSES`, for programs to read.
    iterations : int
        Newton steps (last mesh).
    timings : dict
        Wall-clock seconds: ``mesh``, ``assembly``, ``factorize``, ``compliance`` (interface
        compliance and truncation correction), ``newton``, ``recover`` (full field and
        reactions), ``solve`` (= factorize + compliance + newton + recover), ``total``.
        After a re-mesh or an edge band, ``mesh`` and ``total`` include every mesh, the others the last one.
    n_dofs : int
        Displacement DOFs of both bodies.
    n_elements : int
        Triangles of both bodies.
    n_interface_nodes : int
        Interface node pairs.
    n_elements_across_contact : float
        Interface elements between the axis and ``edge_radius``.
    penalty : dict
        ``factor`` (``k_pen a_est / E*``), ``stiffness`` ``k_pen`` [pressure/length],
        ``max_penetration`` (largest overlap beyond what the layer law itself allows: the
        whole overlap without a layer, the part past a rigid branch with one) [length],
        ``relative_penetration`` (that over ``approach``).
    truncation : dict
        ``compliance`` ``dc`` [length/force], ``approach_far`` (the top displacement
        ``delta_far = delta - dc P``) [length], ``correction`` (``dc P``) [length],
        ``applied`` (bool), ``radius``, ``depth`` [length].
    mesh : dict
        ``a_est`` [length], ``h_fine`` [length], ``n_contact_elements`` (elements across
        ``a_est``), ``domain_factor`` (domain radius over ``a_est``), ``remeshed`` (bool), ``edge``
        (``[r_e, k]`` of the edge band of ``refine_edge``, ``None`` without), ``n_across_coating``.
    history : dict
        Newton history (last mesh).
    E_star : float
        Effective modulus [pressure].
    model : fem_reference.model.AxiModel
        The assembled model of the last mesh.
    displacement_dofs : ndarray
        Displacement degrees of freedom of both bodies, the finite-element solution vector
        [length] (not the BEM's ``displacement``, the normal elastic displacement at the nodes).
    """

    r: np.ndarray
    p: np.ndarray
    overlap: np.ndarray
    initial_gap: np.ndarray
    approach: float
    force: float
    force_reaction: float
    p_max: float
    edge_radius: float
    converged: bool
    message: str
    iterations: int
    timings: dict
    n_dofs: int
    n_elements: int
    n_interface_nodes: int
    n_elements_across_contact: float
    penalty: dict
    truncation: dict
    mesh: dict
    E_star: float
    history: dict = field(default_factory=dict)
    model: object = field(default=None, repr=False)
    displacement_dofs: np.ndarray = field(default=None, repr=False)
    status: str = ""

    def __post_init__(self):
        if self.status not in STATUSES or self.converged != (self.status == "converged"):
            raise ValueError(f"status = {self.status!r} is not allowed with converged = {self.converged}: "
                             f"one of {STATUSES}, 'converged' exactly when converged")

    @property
    def wall_time_s(self):
        """Total wall-clock time of the solve [s] (the BEM result's name)."""
        return float(self.timings["total"])

    def pressure(self, x, y=0.0):
        """The interface pressure at ``r = hypot(x, y)`` [pressure], linear between the nodes, 0 beyond."""
        return np.interp(np.hypot(x, y), self.r, self.p, right=0.0)

    @property
    def residual(self):
        """Final relative Newton residual ``max|F1| / scale`` (:mod:`fem_reference.newton`)."""
        return float(self.history["residual"][-1]) if self.history.get("residual") else float("inf")

    def field(self):
        """Displacements, stresses and contact pressure as a mesh (:func:`fem_reference.fields.field_mesh`).

        ``bem.files.write_vtu(path, **result.field())`` writes the ParaView file.
        """
        from .fields import field_mesh

        return field_mesh(self.model, self.displacement_dofs, self.p)

    def summary(self):
        """Scalars as a JSON-ready dict."""
        return {
            "p_max": float(self.p_max), "force": float(self.force), "approach": float(self.approach),
            "edge_radius": float(self.edge_radius), "converged": bool(self.converged),
            "status": self.status, "message": self.message, "iterations": int(self.iterations),
            "n_dofs": int(self.n_dofs),
            "n_elements": int(self.n_elements),
            "n_elements_across_contact": float(self.n_elements_across_contact),
            "timings": {k: float(v) for k, v in self.timings.items()},
            "penalty": dict(self.penalty), "truncation": dict(self.truncation), "mesh": dict(self.mesh),
        }
