"""A constrained CG written here, that restarts its conjugate directions whenever nodes enter the contact.

Polonsky & Keer's loop (doi:10.1016/S0043-1648(99)00113-1) under force control with a preconditioner, on the
nodes ``mask`` of a brick array: the direction ``t = z + beta t_old`` on the contact with the Fletcher-Reeves
coefficient ``beta = g.z / g_old.z_old``, reset to 0 after a step at which nodes entered; the step ``g.t / t.C t``
projected onto ``p >= 0``; an entering node (``p = 0``, ``g < 0``) takes half its Jacobi estimate
``-g / C_nn`` times ``min(tau, 1)`` (``precondition=None``: ``-tau g``, at most ``-g / C_nn``); the force restored
by scaling. The yardstick of the solvers that keep their
directions when the contact changes (Polak-Ribiere+).
"""

from __future__ import annotations

import numpy as np


def restarted_cg(matvec, precondition, diagonal, h, mask, target, *, rtol=1e-10, maxiter=2000):
    """``(p, iterations)`` of the QP ``min 1/2 p.C p + p.h`` over ``p >= 0`` with ``sum p = target`` on ``mask``.

    Stops where ``max(max_{p>0} |g|, max_{p=0} (-g)_+) <= rtol max |C p|`` with ``g = C p + h - delta`` and
    ``delta`` the mean of ``C p + h`` on the contact.
    """
    p = np.where(mask, target / np.count_nonzero(mask), 0.0)
    t = np.zeros_like(p)
    gz_old, restart = 1.0, True
    for k in range(maxiter):
        u = matvec(p)
        on = p > 0
        g = u + h
        g -= g[on].mean()
        g[~mask] = 0.0
        if max(np.abs(g[on]).max(), -g[mask & ~on].min(initial=0.0)) <= rtol * np.abs(u).max():
            return p, k
        z = np.where(on, g if precondition is None else precondition(np.where(on, g, 0.0)), 0.0)
        z[on] -= z[on].mean()
        gz = float(np.sum(g[on] * z[on]))
        t = np.where(on, z + (0.0 if restart else gz / gz_old) * t, 0.0)
        t[on] -= t[on].mean()
        gz_old = gz
        r = matvec(t)
        r[on] -= r[on].mean()
        tau = float(np.sum(g[on] * t[on]) / np.sum(r[on] * t[on]))
        entering = mask & ~on & (g < 0)
        p = np.where(on, np.maximum(p - tau * t, 0.0), p)
        if precondition is None:  # Polonsky and Keer: -tau g, at most the Jacobi estimate
            p[entering] = -min(tau, 1.0 / diagonal) * g[entering]
        else:
            p[entering] = -0.5 * min(tau, 1.0) * g[entering] / diagonal
        restart = bool(entering.any())
        p *= target / p.sum()
    raise AssertionError("the restarted constrained CG did not converge")
