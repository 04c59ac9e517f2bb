"""The public entry point :func:`solve` of the axisymmetric FEM reference.

Truncation of the half-spaces. The FEM bodies are finite (``R = H = domain_factor a_est``)
and supported far away, so they are stiffer than half-spaces: the displacement of the
top relative to the bottom (``delta_far``) is smaller than the half-space approach
``delta`` (the displacement of the contact relative to points at infinity) by a term
``~ P / (E* R)``. Near the contact, the difference between the two fields is a smooth
field of the load's resultant ``P`` only (varying over the scale ``R``), i.e. to
leading order a rigid shift ``dc P``. ``dc`` [length/force] is measured once per mesh
with the factorised stiffness (:meth:`fem_reference.model.AxiModel.reference_correction`:
the centre displacement under a smooth reference load against its closed-form
half-space value), and the interface compliance used by Newton is
``C + dc 1 1^T``: ``delta`` is then the half-space approach the BEM computes, and
the top is moved by ``delta_far = delta - dc P``. Measured (Hertz, 16 elements
across ``a``): the raw ``delta_far`` is 2.8 % (``domain_factor = 15``) and 1.04 % (``domain_factor = 40``)
below Hertz's approach, i.e. ``~0.42 a / R``; the corrected ``delta`` is within 0.003 % and
0.012 %. Under force control the correction only shifts ``delta`` (the pressure is
identical); under approach control without it the force would come out ~1.5 % high
(``P ~ delta^(3/2)``). The truncation changes the peak pressure by < 1e-4
(domain_factor 15 vs 40).
"""

from __future__ import annotations

import logging
import math
import time

import numpy as np

from bem.checks import (check_bool, check_callable, check_gap_values, check_int, check_layer, check_load,
                        check_positive, check_rtol, fail)
from bem.layers import beyond_table
from bem.materials import effective_modulus
from bem.reference import estimate_contact_radius

from .interface import InterfaceLaw
from .mesh import AxiMesh, build_mesh
from .model import AxiModel, check_coatings, check_materials
from .newton import solve_interface
from .result import FemResult, axis_pressure, edge_radius
from .sizes import N_ACROSS_COATING

__all__ = ["solve"]

log = logging.getLogger(__name__)

#: re-mesh (once) when the computed radius leaves [_LOW, _HIGH] * a_est
_LOW, _HIGH = 0.6, 1.25


def _gap_at(gap, r):
    """``h(r, 0)`` at the interface nodes [length], checked by :func:`bem.checks.check_gap_values`."""
    y = np.zeros_like(r)
    return check_gap_values(gap(r, y), {"x": r, "y": y}, region="on the interface")


def _start(layer, h_edge, force, a_est):
    """Starting approach under force control: Hertz ``2 h(a)``, or ``h(a) + w(mean p)``."""
    if layer is None:
        return 2.0 * h_edge
    w = float(layer.w(force / (math.pi * a_est**2)))
    return h_edge + (w if math.isfinite(w) else h_edge)


def _one_mesh(amesh, gap, materials, E_star, layer, penalty, force, approach, truncation_correction, rtol,
              maxiter):
    """Assemble, condense and solve on one mesh; returns (model, solution, extras)."""
    t0 = time.perf_counter()
    E1, nu1, E2, nu2, coating1, coating2 = materials
    model = AxiModel(amesh, E1=E1, nu1=nu1, E2=E2, nu2=nu2, coating1=coating1, coating2=coating2)
    t1 = time.perf_counter()
    C = model.interface_compliance()
    dc = model.reference_correction(E_star, amesh.a_est) if truncation_correction else 0.0
    t2 = time.perf_counter()
    h = _gap_at(gap, model.r)
    law = InterfaceLaw(layer, penalty * E_star / amesh.a_est)
    delta0 = None
    if force is not None:
        delta0 = _start(layer, float(np.interp(amesh.a_est, model.r, h)), force, amesh.a_est)
    sol = solve_interface(C + dc, model.weights, h, law, force=force, approach=approach, delta0=delta0,
                          rtol=rtol, maxiter=maxiter)
    t3 = time.perf_counter()
    timings = {"assembly": model.timings["assembly"], "factorize": model.timings["factorize"],
               "compliance": t2 - t1, "newton": t3 - t2, "model_total": t1 - t0}
    return model, sol, h, law, dc, timings


def solve(gap, *, E1, nu1, E2, nu2, coating1=None, coating2=None, force=None, approach=None, layer=None, a_est=None,
          n_contact_elements=24, domain_factor=40.0, fine_radius=1.5, growth=0.25, mesh=None, penalty=1e5,
          truncation_correction=True, remesh=True, refine_edge=None, n_across_coating=N_ACROSS_COATING, rtol=1e-9,
          maxiter=60):
    """Axisymmetric FEM reference solution of the layered contact of two elastic bodies.

    Body 1 (``E1, nu1``) is the upper body ``z >= 0``, body 2 the lower one; the interface
    carries the layer law of :mod:`bem.layers` as a penalty (:mod:`fem_reference.interface`);
    Newton's method on the condensed interface problem (:mod:`fem_reference.newton`).

    Parameters
    ----------
    gap : callable
        Initial gap ``h(x, y)`` [length], axisymmetric; evaluated as ``h(r, 0)``.
    E1, nu1, E2, nu2 : float
        Young's moduli [pressure] and Poisson's ratios (``-1 < nu <= 0.499``); of the
        substrate where the body is coated.
    coating1, coating2 : bem.coating.Coating, optional
        A coating bonded to body 1 or 2 (``nu <= 0.499``), meshed as its own material with
        at least ``fem_reference.sizes.N_ACROSS_COATING`` elements across its thickness in the
        contact zone. ``E_star`` (penalty scale, radius estimate) stays the substrates'.
    force, approach : float
        Exactly one: total force ``P`` [force] (force control: ``delta`` is an extra
        unknown of Newton's method) or half-space approach ``delta`` [length].
    layer : bem.layers.Layer, optional
        Interface law ``w(p)``; ``None`` for smooth bodies (pure penalty).
    a_est : float, optional
        Expected contact radius [length] that sizes the mesh; default
        :func:`bem.reference.estimate_contact_radius`.
    n_contact_elements, domain_factor, fine_radius, growth : optional
        Mesh options of :func:`fem_reference.build_mesh` (elements across ``a_est``, domain
        size and fine-zone radius in units of ``a_est``, size grading).
    mesh : fem_reference.mesh.AxiMesh, optional
        A prebuilt mesh (then ``a_est`` and the mesh options are taken from it and no
        re-meshing happens).
    penalty : float
        Dimensionless penalty ``k_pen a_est / E*`` (``k_pen`` [pressure/length]).
    truncation_correction : bool
        Report and impose the half-space approach (module docstring); ``False`` uses the
        raw top displacement as ``approach``.
    remesh : bool
        Re-mesh once around the computed radius when it leaves ``[0.6, 1.25] a_est``.
    refine_edge : int, optional
        ``k >= 2``: solve once more on a mesh whose interface elements within ``h_fine`` of the
        computed contact edge are ``k`` times smaller (:func:`fem_reference.build_mesh`'s ``edge``),
        which places the edge of a smooth contact far better than the nodes' spacing. ``None``: no
        edge band. Not with a prebuilt ``mesh``.
    n_across_coating : int
        Elements across a coating's thickness in the fine zone (at least
        ``fem_reference.sizes.N_ACROSS_COATING``).
    rtol : float
        Newton stopping rule (:mod:`fem_reference.newton`), in ``(0, bem.checks.RTOL_MAX]`` as for
        :func:`bem.solve`: a looser one accepts a wrong answer as converged.
    maxiter : int
        Newton-step limit.

    Returns
    -------
    FemResult
        ``converged = False`` with a ``message`` when the stopping rule was not met or the
        contact reaches the outer boundary; the fields are then the last finite iterate.

    Raises
    ------
    bem.InputError
        A bad argument, before any work (the checks of :mod:`bem.checks`: "name = value is
        not allowed: rule"), or a gap that is not finite on the interface.
    """
    t_start = time.perf_counter()
    check_callable("gap", gap)
    check_materials(E1, nu1, E2, nu2)
    thickness = tuple(None if c is None else getattr(c, "thickness", c) for c in (coating1, coating2))
    check_coatings(coating1, coating2, thickness)
    force, approach = check_load(force, approach)
    layer = check_layer("layer", layer)
    penalty = check_positive("penalty", penalty)
    rtol = check_rtol("rtol", rtol)
    maxiter = check_int("maxiter", maxiter)
    truncation_correction = check_bool("truncation_correction", truncation_correction)
    remesh = check_bool("remesh", remesh)
    if refine_edge is not None:
        refine_edge = check_int("refine_edge", refine_edge, minimum=2)
    n_across_coating = check_int("n_across_coating", n_across_coating, minimum=N_ACROSS_COATING)
    if mesh is not None and not isinstance(mesh, AxiMesh):
        fail("mesh", mesh, "a fem_reference.mesh.AxiMesh (from fem_reference.build_mesh) or None")
    if mesh is not None:
        check_coatings(coating1, coating2, mesh.coating_thickness)
        if refine_edge is not None:
            fail("refine_edge", refine_edge, "None with a prebuilt mesh (the edge band is meshed here)")
    E_star = effective_modulus(E1, nu1, E2, nu2)
    if mesh is None and a_est is None:
        a_est = estimate_contact_radius(gap, E_star=E_star, force=force, approach=approach, layer=layer)
    elif mesh is None:
        a_est = check_positive("a_est", a_est)
    options = dict(n_contact_elements=n_contact_elements, domain_factor=domain_factor, fine_radius=fine_radius,
                   growth=growth, coating_thickness=thickness, n_across_coating=n_across_coating)
    remeshed, edge, mesh_time = False, None, 0.0
    for attempt in range(3):
        amesh = mesh if mesh is not None and not remeshed and edge is None else build_mesh(a_est, edge=edge, **options)
        mesh_time += amesh.mesh_time_s if amesh is not mesh else 0.0
        model, sol, h, law, dc, timings = _one_mesh(
            amesh, gap, (E1, nu1, E2, nu2, coating1, coating2), E_star, layer, penalty, force, approach,
            truncation_correction, rtol, maxiter)
        p = sol.p.copy()
        p[0] = axis_pressure(model.r, p)
        a_c = edge_radius(model.r, p, sol.g, smooth=layer is None)
        if (attempt == 0 and remesh and mesh is None and sol.converged
                and not (_LOW * a_est <= a_c <= _HIGH * a_est) and a_c > 0):
            log.info("contact radius %.4g is outside [%.2f, %.2f] a_est (a_est = %.4g): re-meshing",
                     a_c, _LOW, _HIGH, a_est)
            a_est, remeshed = a_c, True
            continue
        if (refine_edge is not None and edge is None and sol.converged
                and 0.0 < a_c < amesh.fine_radius and p[-1] == 0.0):
            log.info("re-meshing with elements %d times smaller around the edge r = %.4g", refine_edge, a_c)
            edge = (a_c, refine_edge)
            continue
        if refine_edge is not None and edge is None:
            log.warning("refine_edge = %d not applied: the first solve %s", refine_edge,
                        "did not converge" if not sol.converged else f"has its edge at r = {a_c:.4g}, outside the "
                        f"fine zone (0, {amesh.fine_radius:.4g})")
        break
    return _finish(model, sol, p, h, a_c, law, dc, timings, mesh_time, t_start, penalty, E_star,
                   layer, remeshed, amesh)


def _finish(model, sol, p, h, a_c, law, dc, timings, mesh_time, t_start, penalty, E_star, layer,
            remeshed, amesh):
    t0 = time.perf_counter()
    A = model.weights
    force = float(np.sum(A * sol.p))
    delta_far = sol.delta - dc * force
    u = model.displacement(A * sol.p, delta_far)
    reaction = model.reaction_force(u)
    timings = dict(timings, mesh=mesh_time, recover=time.perf_counter() - t0)
    converged, message, status = sol.converged, sol.message, sol.status
    if p[-1] > 0:
        converged, status = False, "boundary"
        message = "the contact reaches the outer boundary r = R: increase domain_factor"
    g = sol.g[A > 0]  # the axis node (ring area 0) carries no force: its overlap is free
    if layer is None:
        penetration = float(max(g.max(), 0.0))
    elif law.rigid_limit() is not None:
        penetration = float(max((g - law.rigid_limit()[0]).max(), 0.0))
    else:
        penetration = 0.0
    fem_mesh = model.amesh.mesh
    corner_r = np.unique(fem_mesh.p[0, fem_mesh.facets[:, fem_mesh.boundaries["interface_upper"]]])
    timings["solve"] = timings["factorize"] + timings["compliance"] + timings["newton"] + timings["recover"]
    timings.pop("model_total")
    timings["total"] = time.perf_counter() - t_start
    result = FemResult(
        r=model.r.copy(), p=p, overlap=sol.g.copy(), initial_gap=h, approach=float(sol.delta), force=force,
        force_reaction=reaction, p_max=float(p.max()), edge_radius=a_c, converged=converged,
        message=message, status=status, iterations=sol.iterations, timings=timings, n_dofs=model.n_dofs,
        n_elements=amesh.n_elements, n_interface_nodes=int(model.r.size),
        n_elements_across_contact=float(np.interp(a_c, corner_r, np.arange(corner_r.size))),
        penalty={"factor": penalty, "stiffness": law.k_pen, "max_penetration": penetration,
                 "relative_penetration": penetration / abs(sol.delta) if sol.delta else math.inf},
        truncation={"compliance": dc, "correction": dc * force, "approach_far": delta_far,
                    "applied": bool(dc != 0.0), "radius": amesh.radius, "depth": amesh.depth},
        mesh={"a_est": amesh.a_est, "h_fine": amesh.h_fine, "n_contact_elements": amesh.n_contact_elements,
              "domain_factor": amesh.radius / amesh.a_est, "remeshed": remeshed,
              "edge": None if amesh.edge is None else list(amesh.edge), "n_across_coating": amesh.n_across_coating},
        E_star=E_star, history=sol.history, model=model, displacement_dofs=u,
    )
    if not converged:
        log.warning("FEM reference did not converge: %s", message)
    elif (note := beyond_table(layer, result.p_max)) is not None:
        log.warning("FEM reference: %s", note)
    return result
