"""The result object every BEM method returns."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["ContactResult", "STATUSES"]

#: The outcomes a solver reports in ``status``: the stopping rule was met (``"converged"``),
#: the iteration budget ran out (``"maxiter"``), the iteration stopped making progress
#: (``"stalled"``: no smaller increment for many iterations, no descent along the search
#: direction, or a search direction without positive curvature), the increments grew
#: (``"diverged"``), or a residual was not finite (``"nonfinite"``).
STATUSES = ("converged", "maxiter", "stalled", "diverged", "nonfinite")


@dataclass
class ContactResult:
    """Solution of the discrete contact problem on the candidate nodes.

    Attributes
    ----------
    x, y : ndarray, shape (N,)
        Candidate node coordinates [length].
    p : ndarray, shape (N,)
        Nodal pressures [pressure] (pyramid amplitudes).
    displacement : ndarray, shape (N,)
        Elastic displacement ``(C p)_n`` [length]: the normal surface displacements of the
        two half-spaces, summed (the layer's closure is not in it).
    closure : ndarray, shape (N,)
        Layer closure ``w(p_n)`` [length] (zeros without a layer).
    gap : ndarray, shape (N,)
        Deformed gap ``C p + w(p) + h - delta`` [length]; 0 in contact.
    approach : float
        Total approach ``delta`` [length].
    force : float
        Total force ``sqrt(3)/2 c^2 sum p`` [force] (eq. 9).
    p_max : float
        Largest nodal pressure [pressure].
    contact_area : float
        Number of nodes with ``p > 0`` times the node area ``sqrt(3)/2 c^2`` [length^2].
    converged : bool
        Whether the method met its stopping rule (``status == "converged"``).
    message : str
        Why the method stopped, for people to read.
    status : str
        The outcome, one of :data:`bem.result.STATUSES`, for programs to read.
    rtol : float
        The KKT tolerance the solve was asked for (``converged`` means ``kkt_residual <= rtol``).
    iterations : int
        Iterations of the method on the finest lattice: conjugate-gradient
        iterations of the QP (no layer, linear layer with ``"newton"`` or
        ``"kalker"``), Newton steps, or outer iterations of the paper's methods.
    kkt_residual : float
        :func:`bem.kkt.kkt_residual` of the returned state.
    n_matvec : int
        Products with the influence matrix ``C`` (FFT convolutions) on the finest lattice,
        inner solves included: the measure of work that does not depend on the method.
    n_transforms : int
        2-D FFTs of the finest lattice's arrays, forward or inverse, in either precision: those of the products
        with ``C`` (two each), of the preconditioner (two an application) and of the curvature of a step made
        without a product (one), inner solves included; not those that build the kernel's spectra or symbols.
        The work measure of a solver's iterations that :attr:`n_matvec` leaves out.
    history : dict
        Per-iteration lists (``residual``, ``p_max``, ``n_contact``, ``changes``
        and method-specific entries).
    method : str
        The method that produced the result.
    wall_time_s : float
        Wall-clock time of the solve [s].
    lattice : bem.lattice.Lattice
        The candidate lattice; :meth:`grid` maps nodal arrays back onto it.
    E_star : float
        Effective modulus [pressure].
    bodies : bem.Bodies or None
        The coated bodies (their moduli, Poisson ratios and coatings); ``None`` when neither body
        is coated (``E_star`` says all).
    domain : bem.HalfSpaceRegion or bem.PeriodicCell
        The domain solved on (a growing region: the one the contact fitted in).
    notes : list of str
        What the solve did besides iterating, for people (a region enlarged).
    hardness : float or None
        Hardness ``H`` of the surface [pressure], the bound ``p <= H`` (:mod:`bem.plastic`); ``None``:
        elastic.
    plastic_area : float
        Number of plastic nodes (``p = H``) times the node area [length^2]; 0 without a hardness.
    """

    x: np.ndarray
    y: np.ndarray
    p: np.ndarray
    displacement: np.ndarray
    closure: np.ndarray
    gap: np.ndarray
    approach: float
    force: float
    p_max: float
    contact_area: float
    converged: bool
    message: str
    iterations: int
    kkt_residual: float
    method: str
    wall_time_s: float
    lattice: object
    E_star: float
    history: dict = field(default_factory=dict)
    layer: object = None
    n_matvec: int = 0
    n_transforms: int = 0
    status: str = ""
    rtol: float = math.nan
    domain: object = None
    bodies: object = None
    notes: list = field(default_factory=list)
    hardness: float | None = None
    plastic_area: float = 0.0

    def __post_init__(self):
        if self.status not in STATUSES or self.converged != (self.status == "converged"):
            raise ValueError(f"status = {self.status!r} is not allowed with converged = {self.converged}: "
                             f"one of {STATUSES}, 'converged' exactly when converged")

    @property
    def contact_radius(self):
        """Radius of the circle of the same area, ``sqrt(A / pi)`` [length]."""
        return math.sqrt(self.contact_area / math.pi)

    @property
    def step(self):
        """Lattice step ``c`` [length]."""
        return self.lattice.step

    def grid(self, values=None):
        """Nodal values (default ``p``) as a brick array of ``lattice.shape`` (0 off the region)."""
        out = np.zeros(self.lattice.shape)
        out[self.lattice.mask] = self.p if values is None else values
        return out

    def pressure(self, x, y=0.0):
        """The piecewise-linear pressure field at arbitrary points ``(x, y)`` [pressure]."""
        return self.lattice.interpolate(self.grid(), x, y)

    def summary(self):
        """Scalars of the result as a JSON-ready dict."""
        return {
            "method": self.method,
            "converged": bool(self.converged),
            "status": self.status,
            "message": self.message,
            "p_max": float(self.p_max),
            "force": float(self.force),
            "approach": float(self.approach),
            "contact_area": float(self.contact_area),
            "contact_radius": float(self.contact_radius),
            "iterations": int(self.iterations),
            "n_matvec": int(self.n_matvec),
            "n_transforms": int(self.n_transforms),
            "kkt_residual": float(self.kkt_residual),
            "rtol": float(self.rtol),
            "wall_time_s": float(self.wall_time_s),
            "n_nodes": int(self.p.size),
            "n_contact": int(np.count_nonzero(self.p > 0)),
            "step": float(self.step),
            "hardness": None if self.hardness is None else float(self.hardness),
            "plastic_area": float(self.plastic_area),
            **self._coatings(),
        }

    def _coatings(self):
        """``coating1``, ``coating2`` (each ``{"thickness", "E", "nu"}`` or None) when a body is coated."""
        if self.bodies is None:
            return {}
        return {f"coating{i}": None if c is None else {"thickness": float(c.thickness), "E": float(c.E),
                                                        "nu": float(c.nu)}
                for i, c in ((1, self.bodies.coating1), (2, self.bodies.coating2))}
