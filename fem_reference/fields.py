"""Nodal stress recovery and the field of an FEM solution as a mesh for the ParaView (.vtu) writer.

Stresses (Hooke's law per body, axisymmetric)::

    sigma_rr = lam tr(eps) + 2 mu eps_rr       sigma_zz = lam tr(eps) + 2 mu eps_zz
    sigma_tt = lam tr(eps) + 2 mu u_r / r      sigma_rz = mu (du_r/dz + du_z/dr)
    von_mises = sqrt(((s_rr - s_zz)^2 + (s_zz - s_tt)^2 + (s_tt - s_rr)^2) / 2 + 3 s_rz^2)

are evaluated at the quadrature points and L2-projected onto the continuous quadratic
space of each body (:func:`nodal_stresses`; the bodies share no node, so nothing is averaged
across the contact interface, but a coating and its substrate share the nodes of their bond,
where the projection takes a mean of the two materials' jumping stresses). One-sided recovery
(:func:`one_sided_stresses`): each element's own stress at its six nodes, averaged over the
chosen elements that share a node (one material: a coating's elements, or its substrate's), so
that each side of a bond keeps its own value. ``tr(eps) = eps_rr + eps_zz + eps_tt``; tension
positive.
"""

from __future__ import annotations


import numpy as np
from scipy.sparse.linalg import splu

from bem.coating_fields import von_mises


__all__ = ["nodal_stresses", "one_sided_stresses", "body_stresses", "field_mesh", "STRESS_NAMES"]

STRESS_NAMES = ("sigma_rr", "sigma_zz", "sigma_tt", "sigma_rz", "von_mises")


def _quadrature_stresses(model, u, basis=None, lam=None, mu=None):
    """``(s_rr, s_zz, s_tt, s_rz)`` at the points of ``basis`` (default: the model's quadrature).

    On the axis (``r = 0``, where ``u_r = 0``) the hoop strain ``u_r / r`` is its limit ``du_r/dr``.
    """
    from .model import _strain

    basis = model.basis if basis is None else basis
    ui = basis.interpolate(u)
    r = np.asarray(basis.global_coordinates())[0]
    on_axis = r == 0.0
    e_rr, e_zz, e_tt, g_rz = _strain(ui, np.where(on_axis, 1.0, r))
    e_tt = np.where(on_axis, e_rr, e_tt)
    lam = model.lam_w if lam is None else lam
    mu = model.mu_w if mu is None else mu
    tr = lam * (e_rr + e_zz + e_tt)
    return tr + 2 * mu * e_rr, tr + 2 * mu * e_zz, tr + 2 * mu * e_tt, mu * g_rz


def nodal_stresses(model, u):
    """Projected nodal stresses [pressure] on the scalar quadratic nodes of ``model``.

    Parameters
    ----------
    model : fem_reference.model.AxiModel
        The assembled model.
    u : ndarray, shape (model.n_dofs,)
        Displacement [length].

    Returns
    -------
    dict
        ``sigma_rr``, ``sigma_zz``, ``sigma_tt``, ``sigma_rz``, ``von_mises``: arrays of shape
        ``(model.scalar_basis.N,)``.
    """
    from skfem import BilinearForm, LinearForm, asm

    @BilinearForm
    def mass(a, b, w):
        return a * b

    @LinearForm
    def load(v, w):
        return w.s * v

    basis = model.scalar_basis
    lu = splu(asm(mass, basis).tocsc())
    out = {}
    for name, s in zip(STRESS_NAMES[:4], _quadrature_stresses(model, u)):
        out[name] = lu.solve(asm(load, basis, s=s))
    out["von_mises"] = von_mises(out["sigma_rr"], out["sigma_tt"], out["sigma_zz"], out["sigma_rz"])
    return out


def one_sided_stresses(model, u, elements):
    """Nodal stresses [pressure] from the chosen elements only, on the scalar quadratic nodes.

    Each chosen element's stress (Hooke's law of its own material) is evaluated at its own six
    nodes; a node's value is the mean over the chosen elements that hold it. Chosen as the
    elements of one material, the stresses at a bond are that material's side of the jump.

    Parameters
    ----------
    model : fem_reference.model.AxiModel
        The assembled model.
    u : ndarray, shape (model.n_dofs,)
        Displacement [length].
    elements : ndarray of bool, shape (n_elements,)
        The elements to recover from (e.g. ``model.amesh.coated & (model.amesh.body == 1)``).

    Returns
    -------
    dict
        ``sigma_rr``, ``sigma_zz``, ``sigma_tt``, ``sigma_rz``, ``von_mises``: arrays of shape
        ``(model.scalar_basis.N,)``, NaN at the nodes of no chosen element; ``nodes``: the bool
        mask of the nodes that have a value.
    """
    from skfem import Basis, ElementTriP2, ElementVector

    elements = np.nonzero(np.asarray(elements, dtype=bool))[0]
    element = ElementTriP2()
    points = np.ascontiguousarray(element.doflocs.T)  # the six reference nodes, in local DOF order
    basis = Basis(model.amesh.mesh, ElementVector(element), quadrature=(points, np.full(6, 1.0 / 12.0)),
                  elements=elements)
    lam, mu = (np.asarray(w)[elements, :1] + np.zeros((1, 6)) for w in (model.lam_w, model.mu_w))
    dofs = model.scalar_basis.element_dofs[:, elements]  # (6, n_chosen): node of local DOF j
    n = model.scalar_basis.N
    count = np.bincount(dofs.ravel(), minlength=n)
    out = {}
    with np.errstate(invalid="ignore", divide="ignore"):
        for name, s in zip(STRESS_NAMES[:4], _quadrature_stresses(model, u, basis, lam, mu)):
            out[name] = np.bincount(dofs.ravel(), weights=np.asarray(s).T.ravel(), minlength=n) / count
    out["von_mises"] = von_mises(out["sigma_rr"], out["sigma_tt"], out["sigma_zz"], out["sigma_rz"])
    out["nodes"] = count > 0
    return out


def body_stresses(model, u):
    """Recovered nodal stresses of each body, upper first, on its own nodes.

    Parameters
    ----------
    model : fem_reference.model.AxiModel
    u : ndarray, shape (model.n_dofs,)
        Displacement [length].

    Returns
    -------
    list of dict
        One dict per body (upper, lower): ``r`` and ``depth = |z|`` below the interface
        [length], ``von_mises`` and ``max_shear = (s1 - s3) / 2`` [pressure], the principal
        stresses being ``sigma_tt`` and those of the ``(r, z)`` block.
    """
    s = nodal_stresses(model, u)
    basis = model.scalar_basis
    r, z = basis.doflocs
    centre = 0.5 * (s["sigma_rr"] + s["sigma_zz"])
    radius = np.hypot(0.5 * (s["sigma_rr"] - s["sigma_zz"]), s["sigma_rz"])
    principal = np.stack([centre + radius, centre - radius, s["sigma_tt"]])
    shear = 0.5 * (principal.max(axis=0) - principal.min(axis=0))
    out = []
    for index in range(2):
        nodes = np.unique(basis.element_dofs[:, model.amesh.body == index])
        out.append({"r": r[nodes], "depth": np.abs(z[nodes]), "von_mises": s["von_mises"][nodes],
                    "max_shear": shear[nodes]})
    return out


def field_mesh(model, u, pressure):
    """The whole field as a mesh with point and cell data, for :func:`bem.files.write_vtu`.

    Parameters
    ----------
    model : fem_reference.model.AxiModel
        The model.
    u : ndarray
        Displacement [length].
    pressure : ndarray, shape (n_if,)
        Contact pressure at the interface pairs [pressure].

    Returns
    -------
    dict
        ``points`` ``(r, z, 0)`` [length]; ``cells`` (6-node triangles); ``point_data``:
        ``displacement`` (``u_r, u_z, 0``) [length], the stresses of :func:`nodal_stresses` and
        ``contact_pressure`` (0 off the interface) [pressure]; ``cell_data``: ``body`` (0
        upper, 1 lower). ``bem.files.write_vtu(path, **field_mesh(...))`` writes it.
    """
    basis = model.scalar_basis
    x = basis.doflocs
    points = np.column_stack([x[0], x[1], np.zeros(x.shape[1])])
    fields = nodal_stresses(model, u)
    disp = np.column_stack([u[0::2], u[1::2], np.zeros(x.shape[1])])
    p_nodes = np.zeros(x.shape[1])
    p_nodes[model.node_up] = pressure
    p_nodes[model.node_lo] = pressure
    return {"points": points, "cells": [("triangle6", np.ascontiguousarray(basis.element_dofs.T, dtype=np.int64))],
            "point_data": {"displacement": disp, **fields, "contact_pressure": p_nodes},
            "cell_data": {"body": [model.amesh.body.astype(np.int32)]}}
