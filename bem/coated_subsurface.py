"""Stresses below a coated body: in the coating, in the substrate and at the interface, from both sides.

:func:`coated_stress` evaluates the stress tensor of a coated body (:class:`bem.Coating` on the
body's substrate, recorded in ``result.bodies``) at given depths under the BEM pressure, by the
per-mode fields of :func:`bem.coating_fields.mode_fields` rotated into ``x, y``
(:mod:`bem.mode_sum`) and summed over the modes of the pyramid pressure on a periodic cell of the
triangular lattice: ``sigma = sum_G p_G T(G, z) exp(i G.x)``, ``p_G`` exact for the pyramid basis
(every alias of the lattice folded in, to ``|G| <= g_cut``).

A periodic cell (:func:`bem.solve_periodic`) is summed as it is; its uniform mode (the mean
pressure) leaves each material in uniaxial strain (periodic displacements: no mean in-plane strain).

A half-space region is not periodic, and a periodic sum of its pressure would carry the images'
stresses, which decay only like ``1/distance^2``. Its stress is therefore split (docs/method.md,
section 7.3) into parts computed exactly in real space by :func:`bem.subsurface_stress`
(homogeneous half-spaces) and a remainder whose transfer function vanishes at ``q = 0`` and decays
like ``exp(-q t)``, summed on a zero-padded cell: ::

    substrate (z >= t):  sigma = B_s(z) + Delta,
    coating (z <= t):    sigma = B_c(z) + M(B_s(z + t)) - B_c(z + t) + Delta,

``B_s``, ``B_c`` the homogeneous half-space stresses with the substrate's and the coating's Poisson
ratio and ``M`` the coating's stresses that take the substrate's in-plane strain and the same
``sigma_zz``, ``sigma_xz``, ``sigma_yz`` (:func:`coating_of_substrate`): long waves see through the
coating, which follows the substrate's surface strain. The remainder's kernel decays like
``1/r^3``; its images on the cell, ``pad`` times the loaded box, are the method's error
(tests/bem/test_coated_stress.py).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from .checks import InputError, check_finite_array, check_range
from .coating import Coating
from .coating_fields import mode_fields
from .mode_sum import mode_stress
from .result import ContactResult
from .stress import VOIGT, subsurface_stress, von_mises_voigt

__all__ = ["CoatedStress", "coated_stress", "coating_of_substrate"]

#: ``|G| d`` beyond which a remainder that decays like ``exp(-|G| d)`` (times a quadratic) is below 1e-12.
_DECAY = 36.0
#: Largest ``|G|`` summed [1/step]: four radii of the lattice's Brillouin zone.
G_MAX = 8 * math.pi


def coating_of_substrate(sigma, coating, E_substrate, nu_substrate):
    """The coating's stresses that share the substrate's in-plane strain and its ``zz``, ``yz``, ``xz`` stresses.

    Parameters
    ----------
    sigma : ndarray, shape (..., 6)
        Stresses in the substrate (Voigt :data:`bem.stress.VOIGT`) [pressure].
    coating : bem.Coating
        The coating (``E``, ``nu``).
    E_substrate, nu_substrate : float
        The substrate's Young's modulus [pressure] (``math.inf``: rigid, no strain) and Poisson's ratio.

    Returns
    -------
    ndarray, shape (..., 6)
        ``sigma_ab = lam' (e_xx + e_yy) delta_ab + 2 mu e_ab + nu / (1 - nu) sigma_zz delta_ab``
        (``a, b`` in ``x, y``; ``lam' = E nu / (1 - nu^2)``, ``2 mu = E / (1 + nu)``, the coating's), the
        other three components of ``sigma``.
    """
    xx, yy, zz, yz, xz, xy = np.moveaxis(np.asarray(sigma), -1, 0)
    E, nu, nus = coating.E, coating.nu, nu_substrate
    exx = (xx - nus * (yy + zz)) / E_substrate
    eyy = (yy - nus * (xx + zz)) / E_substrate
    exy = (1 + nus) * xy / E_substrate
    lam, two_mu, r = E * nu / (1 - nu * nu), E / (1 + nu), nu / (1 - nu)
    return np.stack([lam * (exx + eyy) + two_mu * exx + r * zz, lam * (exx + eyy) + two_mu * eyy + r * zz,
                     zz, yz, xz, two_mu * exy], axis=-1)


def _boussinesq(q, z, nu):
    """``Szz, Ssz, Sss, Snn`` of the homogeneous half-space under ``cos(q s)`` at depth ``z``."""
    e = np.exp(-q * z)
    return {"Szz": -(1 + q * z) * e, "Ssz": -q * z * e, "Sss": -(1 - q * z) * e, "Snn": -2 * nu * e}


def _mapped(S, coating, E_s, nu_s):
    """:func:`coating_of_substrate` of the mode amplitudes (in the frame ``s, n``: ``xx = ss``, ``yy = nn``)."""
    v = np.stack([S["Sss"], S["Snn"], S["Szz"], 0 * S["Szz"], S["Ssz"], 0 * S["Szz"]], axis=-1)
    out = coating_of_substrate(v, coating, E_s, nu_s)
    return {"Sss": out[..., 0], "Snn": out[..., 1], "Szz": out[..., 2], "Ssz": out[..., 4]}


@dataclass
class CoatedStress:
    """Stresses in a coated body below the contact (result of :func:`coated_stress`).

    Attributes
    ----------
    x, y : ndarray, shape (M,)
        Horizontal positions [length] (the candidate nodes unless given).
    z : ndarray, shape (n_z,)
        Depths below the surface [length], as given.
    sigma : ndarray, shape (n_z, M, 6)
        Stress tensor [pressure], Voigt :data:`bem.stress.VOIGT`, compression negative, body frame
        (``z`` into the body). A depth ``z <= t`` is in the coating (``z = t``: its side), deeper in
        the substrate.
    von_mises : ndarray, shape (n_z, M)
        ``sqrt(3 J2)`` [pressure].
    in_coating : ndarray of bool, shape (n_z,)
        Whether each depth lies in the coating.
    interface_coating, interface_substrate : ndarray, shape (M, 6)
        The stress tensor at the interface ``z = t`` on the coating's and on the substrate's side
        [pressure]: the traction ``zz``, ``xz``, ``yz`` is continuous, ``xx``, ``yy``, ``xy`` jump.
        ``interface_substrate`` is ``None`` on a rigid substrate.
    max_von_mises_coating, max_von_mises_substrate : float
        Largest von Mises stress in each material [pressure], over the depths in it and its side of
        the interface (sampled, not refined); the substrate's is ``None`` when it is rigid.
    location_of_max_coating, location_of_max_substrate : tuple of float
        ``(x, y, z)`` of those maxima [length] (``None`` with the maximum).
    coating : bem.Coating
        The coating; ``E_substrate``, ``nu_substrate`` the substrate's constants.
    body : int
        1 or 2.
    on_nodes : bool
        Whether the points are the candidate nodes (else linear interpolation between nodes).
    wall_time_s : float
        Time of the computation [s].
    meta : dict
        ``step``, ``periodic``, ``cell`` (rows, columns of the cell summed), ``g_cut`` [1/step].
    """

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    sigma: np.ndarray
    von_mises: np.ndarray
    in_coating: np.ndarray
    interface_coating: np.ndarray
    interface_substrate: np.ndarray
    max_von_mises_coating: float
    location_of_max_coating: tuple
    max_von_mises_substrate: float
    location_of_max_substrate: tuple
    coating: Coating
    E_substrate: float
    nu_substrate: float
    body: int
    on_nodes: bool
    wall_time_s: float
    meta: dict = field(default_factory=dict)

    def interface_traction(self, side="coating"):
        """``zz``, ``xz``, ``yz`` (``sigma_zz``, ``sigma_xz``, ``sigma_yz``) and ``shear`` (``hypot(xz, yz)``) at the
        interface [pressure], shape (M,) each, from the ``side`` ``"coating"`` or ``"substrate"`` (equal to round-off)."""
        s = {"coating": self.interface_coating, "substrate": self.interface_substrate}[side]
        return {"zz": s[:, 2], "xz": s[:, 4], "yz": s[:, 3], "shear": np.hypot(s[:, 4], s[:, 3])}

    def layers(self):
        """The depths with the interface from both sides, sorted: ``(z, sigma, von_mises, in_coating)``.

        Returns
        -------
        z : ndarray, shape (L,)
            The depths ``z`` [length] with the interface depth ``t`` on the coating's side and, below a
            substrate that is not rigid, again on the substrate's side (once each), increasing; at ``z = t``
            the coating's side comes first.
        sigma : ndarray, shape (L, M, 6)
            The stress tensor at those depths [pressure].
        von_mises : ndarray, shape (L, M)
            ``sqrt(3 J2)`` [pressure].
        in_coating : ndarray of bool, shape (L,)
            Whether each row lies in the coating.
        """
        t = self.coating.thickness
        rows = [(float(d), not c, self.sigma[k]) for k, (d, c) in enumerate(zip(self.z, self.in_coating))]
        if not np.any(self.z == t):
            rows.append((t, False, self.interface_coating))
        if self.interface_substrate is not None:
            rows.append((t, True, self.interface_substrate))
        rows.sort(key=lambda row: row[:2])
        sigma = np.stack([row[2] for row in rows])
        return (np.array([row[0] for row in rows]), sigma, von_mises_voigt(sigma),
                np.array([not row[1] for row in rows]))

    def nearest(self, x0=0.0, y0=0.0):
        """Index of the point nearest to ``(x0, y0)`` [length]."""
        return int(np.argmin((self.x - x0) ** 2 + (self.y - y0) ** 2))

    def summary(self):
        """Scalars as a JSON-ready dict: the maxima per material and the interface's extreme tractions."""
        tr = self.interface_traction("coating")
        k_shear, k_zz = int(np.argmax(tr["shear"])), int(np.argmin(tr["zz"]))
        return {"body": self.body, "max_von_mises_coating": self.max_von_mises_coating,
                "location_of_max_coating": [float(v) for v in self.location_of_max_coating],
                "max_von_mises_substrate": self.max_von_mises_substrate,
                "location_of_max_substrate": (None if self.location_of_max_substrate is None
                                              else [float(v) for v in self.location_of_max_substrate]),
                "interface_max_shear": float(tr["shear"][k_shear]),
                "location_of_interface_max_shear": [float(self.x[k_shear]), float(self.y[k_shear])],
                "interface_min_sigma_zz": float(tr["zz"][k_zz]),
                "interface_max_sigma_zz": float(np.max(tr["zz"])),
                "n_depths": int(self.z.size), "n_points": int(self.x.size), "wall_time_s": self.wall_time_s}


def _body(result, body):
    """``(body, coating, E_s, nu_s)`` of the coated body asked for (the only coated one by default)."""
    bodies = result.bodies
    coated = [] if bodies is None else [i for i in (1, 2) if getattr(bodies, f"coating{i}") is not None]
    if not coated:
        raise InputError("result is not allowed: neither body is coated (result.bodies has no coating); "
                         "use bem.subsurface_stress(result, z, nu=...).")
    if body is None:
        if len(coated) > 1:
            raise InputError("body = None is not allowed: both bodies are coated, name one (body=1 or body=2).")
        body = coated[0]
    if body not in (1, 2) or isinstance(body, bool):
        raise InputError(f"body = {body!r} is not allowed: it must be 1 or 2.")
    if body not in coated:
        raise InputError(f"body = {body!r} is not allowed: that body is not coated; its stresses are "
                         f"bem.subsurface_stress(result, z, nu=result.bodies.nu{body}).")
    return body, getattr(bodies, f"coating{body}"), getattr(bodies, f"E{body}"), getattr(bodies, f"nu{body}")


def _cell(result, pad):
    """The pressure on a cell: ``(grid, embed)``; ``embed`` maps cell fields back to the result's brick array."""
    from .periodic import PeriodicContactResult
    from scipy.fft import next_fast_len

    grid = result.grid()
    if isinstance(result, PeriodicContactResult):
        return grid, lambda f: f
    lat = result.lattice
    loaded = np.argwhere(grid != 0)
    if loaded.size == 0:
        loaded = np.zeros((1, 2), dtype=int)
    (r0, q0), (r1, q1) = loaded.min(axis=0), loaded.max(axis=0)
    n_lat_rows, n_lat_cols = lat.shape
    # a cell that holds the region and puts every image of the load pad - 1 loaded boxes beyond it
    n_rows = next_fast_len(int(n_lat_rows + math.ceil((pad - 1) * (r1 - r0 + 1))) + 1)
    n_rows += n_rows % 2
    n_cols = next_fast_len(int(n_lat_cols + math.ceil((pad - 1) * (q1 - q0 + 1))))
    off = int(lat.parity[0])  # cell row parity = lattice row parity: a translation by a lattice vector
    cell = np.zeros((n_rows, n_cols))
    cell[off: off + n_lat_rows, :n_lat_cols] = grid
    return cell, lambda f: f[..., off: off + n_lat_rows, :n_lat_cols]


def _check(result, z, pad, x, y):
    if not isinstance(result, ContactResult):
        raise InputError(f"result = {type(result).__name__} is not allowed: it must be a bem.ContactResult "
                         "(the return value of bem.solve).")
    pad = check_range("pad", pad, 2.0, 64.0)
    z = check_finite_array("z", z)
    if z.ndim > 1:
        raise InputError(f"z has shape {z.shape} which is not allowed: it must be a number or a 1-D array of depths.")
    z = np.atleast_1d(z).copy()
    if (z < 0).any():
        k = int(np.flatnonzero(z < 0)[0])
        raise InputError(f"z[{k}] = {float(z[k])!r} is not allowed: depths must be >= 0 (below the surface).")
    if (x is None) != (y is None):
        raise InputError(f"x = {x!r}, y = {y!r} is not allowed: give both x and y or neither.")
    return z, pad


def coated_stress(result, z, *, body=None, x=None, y=None, pad=4.0):
    """Stress tensor at depths ``z`` in a coated body, and at its coating/substrate interface from both sides.

    Parameters
    ----------
    result : bem.ContactResult
        A solution of :func:`bem.solve` or :func:`bem.solve_periodic` with a coated body
        (``result.bodies``); the materials are read there.
    z : float or array_like, shape (n_z,)
        Depths below the surface [length], ``>= 0``, any order; ``z <= t`` in the coating.
    body : {1, 2}, optional
        The coated body; default the coated one (required when both are).
    x, y : array_like, shape (M,), optional
        Horizontal points [length]; default every candidate node. Between nodes the values are
        interpolated linearly.
    pad : float
        A half-space region's cell spans the region plus ``pad - 1`` times the loaded box each way,
        in ``[2, 64]``; not used for a periodic cell.

    Returns
    -------
    CoatedStress
        The tensor, von Mises, the interface tensors from both sides and the maxima per material.

    Raises
    ------
    bem.InputError
        ``result`` not a ContactResult or without a coated body, ``body`` not 1 or 2 or not coated,
        a depth negative or not finite, depths in a rigid substrate, ``pad`` out of range,
        ``x``/``y`` not both given, unequal or outside the region.
    """
    t0 = time.perf_counter()
    z, pad = _check(result, z, pad, x, y)
    body, coating, E_s, nu_s = _body(result, body)
    t = coating.thickness
    in_coating = z <= t
    if math.isinf(E_s) and not in_coating.all():
        k = int(np.flatnonzero(~in_coating)[0])
        raise InputError(f"z[{k}] = {float(z[k])!r} is not allowed: body {body}'s substrate is rigid (E{body} = inf) "
                         f"and has no stresses; depths must be at most the coating thickness {t!r}.")
    from .periodic import PeriodicContactResult

    periodic = isinstance(result, PeriodicContactResult)
    lat, c = result.lattice, result.lattice.step
    on_nodes = x is None
    if on_nodes:
        x, y = np.array(result.x, dtype=float), np.array(result.y, dtype=float)
    else:
        x, y = (check_finite_array(n, v, ndim=1) for n, v in (("x", x), ("y", y)))
        if x.shape != y.shape:
            raise InputError(f"x has shape {x.shape} and y has shape {y.shape} which is not allowed: "
                             "they must have the same shape.")
    cell, embed = _cell(result, pad)
    mats = (coating, E_s, nu_s)
    # the depths: those asked for, then the interface from each side
    depths = np.concatenate([z, [t, t]])
    sides = ["coating" if v else "substrate" for v in in_coating] + ["coating", "substrate"]
    if math.isinf(E_s):
        depths, sides = depths[:-1], sides[:-1]

    def pointwise(fields):  # (6, brick) -> (6, M)
        if on_nodes:
            return fields[:, lat.mask]
        return np.stack([lat.interpolate(f, x, y) for f in fields])

    out = np.zeros((depths.size, x.size, 6))
    if not periodic:
        kw = {} if on_nodes else {"x": x, "y": y}
        homogeneous = replace(result, bodies=None)  # the pressure on homogeneous half-spaces of each nu
        zc = depths[[s == "coating" for s in sides]]
        zs = depths[[s == "substrate" for s in sides]]
        if zc.size:
            bc = subsurface_stress(homogeneous, np.concatenate([zc, zc + t]), nu=coating.nu, **kw).sigma
            bs = subsurface_stress(homogeneous, zc + t, nu=nu_s, **kw).sigma
            out[[s == "coating" for s in sides]] = (bc[:zc.size] - bc[zc.size:]
                                                     + coating_of_substrate(bs, *mats))
        if zs.size:
            out[[s == "substrate" for s in sides]] = subsurface_stress(homogeneous, zs, nu=nu_s, **kw).sigma
    g_cuts = []
    for k, (depth, side) in enumerate(zip(depths, sides)):
        if periodic:
            decay = depth
        else:
            decay = min(2 * t - depth, depth + t) if side == "coating" else depth
        g_cut = min(_DECAY * c / decay if decay > 0 else math.inf, G_MAX)
        g_cuts.append(g_cut)

        def radial(k_lat, depth=depth, side=side):
            q = k_lat / c
            S = mode_fields(q, [depth], *mats, side=side)
            S = {name: S[name][:, 0] for name in ("Szz", "Ssz", "Sss", "Snn")}
            if periodic:
                return S
            if side == "substrate":
                ref = _boussinesq(q, depth, nu_s)
            else:
                near, far = _boussinesq(q, depth, coating.nu), _boussinesq(q, depth + t, coating.nu)
                mapped = _mapped(_boussinesq(q, depth + t, nu_s), *mats)
                ref = {n: near[n] + mapped[n] - far[n] for n in near}
            return {n: S[n] - ref[n] for n in S}

        zero = None
        if periodic:
            nu = coating.nu if side == "coating" else nu_s
            zero = [-nu / (1 - nu), -nu / (1 - nu), -1.0, 0.0, 0.0, 0.0]
        out[k] += pointwise(embed(mode_stress(cell, radial, g_cut, zero=zero))).T
    n_z = z.size
    sigma, vm = out[:n_z], von_mises_voigt(out)
    iface_c = out[n_z]
    iface_s = out[n_z + 1] if out.shape[0] > n_z + 1 else None  # a rigid substrate has no stresses
    maxima = []
    for material in ("coating", "substrate"):
        rows = [k for k, s in enumerate(sides) if s == material]
        if not rows:  # a rigid substrate
            maxima.append((None, None))
            continue
        sub = vm[rows]
        kk, n = np.unravel_index(int(np.argmax(sub)), sub.shape)
        maxima.append((float(sub[kk, n]), (float(x[n]), float(y[n]), float(depths[rows[kk]]))))
    return CoatedStress(
        x=x, y=y, z=z, sigma=sigma, von_mises=vm[:n_z], in_coating=in_coating, interface_coating=iface_c,
        interface_substrate=iface_s, max_von_mises_coating=maxima[0][0], location_of_max_coating=maxima[0][1],
        max_von_mises_substrate=maxima[1][0], location_of_max_substrate=maxima[1][1], coating=coating,
        E_substrate=E_s, nu_substrate=nu_s, body=body, on_nodes=on_nodes, wall_time_s=time.perf_counter() - t0,
        meta={"step": c, "periodic": periodic, "cell": tuple(cell.shape), "g_cut": g_cuts, "voigt": VOIGT})
