"""Nodal stress recovery and the field of an FEM solution as a mesh for the ParaView (.vtu) writer.

Stresses (Hooke's law per body, axisymmetric)::

    sigma_rr = lam tr(eps) + 2 mu eps_rr       sigma_zz = lam tr(eps) + 2 mu eps_zz
    sigma_tt = lam tr(eps) + 2 mu u_r / r      sigma_rz = mu (du_r/dz + du_z/dr)
    von_mises = sqrt(((s_rr - s_zz)^2 + (s_zz - s_tt)^2 + (s_tt - s_rr)^2) / 2 + 3 s_rz^2)

are evaluated at the quadrature points and L2-projected onto the continuous quadratic
space of each body (the bodies share no node, so nothing is averaged across the
interface). ``tr(eps) = eps_rr + eps_zz + eps_tt``; tension positive.
"""

from __future__ import annotations


import numpy as np
from scipy.sparse.linalg import splu


__all__ = ["nodal_stresses", "body_stresses", "field_mesh", "STRESS_NAMES"]

STRESS_NAMES = ("sigma_rr", "sigma_zz", "sigma_tt", "sigma_rz", "von_mises")


def _quadrature_stresses(model, u):
    from .model import _strain

    ui = model.basis.interpolate(u)
    r = np.asarray(model.basis.global_coordinates())[0]
    e_rr, e_zz, e_tt, g_rz = _strain(ui, r)
    lam, mu = model.lam_w, model.mu_w
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
    s_rr, s_zz, s_tt, s_rz = (out[k] for k in STRESS_NAMES[:4])
    out["von_mises"] = np.sqrt(0.5 * ((s_rr - s_zz) ** 2 + (s_zz - s_tt) ** 2 + (s_tt - s_rr) ** 2)
                               + 3.0 * s_rz**2)
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
