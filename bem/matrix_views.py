"""The influence operator as a dense matrix and as a SciPy ``LinearOperator``, on the flattened candidate nodes.

The dense matrix is built from the influence template at every node pair, independently of the FFT products of
:class:`bem.InfluenceOperator`, so that the two can be checked against each other (small problems only).
"""

from __future__ import annotations

import math

import numpy as np

from .template import template

__all__ = ["dense", "linear_operator"]


def dense(lattice, E_star, table=None):
    """The dense matrix ``C`` [length/pressure] over the flattened candidate nodes of ``lattice``.

    Parameters
    ----------
    lattice : bem.lattice.Lattice
        The candidate lattice.
    E_star : float
        Effective modulus [pressure].
    table : ndarray, optional
        A coefficient table at every lattice offset (a coated body, :func:`bem.coated_kernel.coated_table`):
        its entry at each node pair's offset. Default: :func:`bem.template.template` at each pair (eq. 6).

    Raises
    ------
    MemoryError
        Above 20000 candidate nodes.
    """
    mask = lattice.mask
    x = lattice.x[mask] / lattice.step
    y = lattice.y[mask] / lattice.step
    if x.size > 20000:
        raise MemoryError(f"dense C for {x.size} nodes would need {8 * x.size**2 / 1e9:.1f} GB")
    if table is not None:
        n = np.rint(np.abs(y[:, None] - y[None, :]) / (math.sqrt(3.0) / 2)).astype(int)
        m = np.rint(2 * np.abs(x[:, None] - x[None, :])).astype(int)
        return table[n, (m - n % 2) // 2]
    scale = lattice.step / (math.pi * E_star)
    return scale * template(x[:, None] - x[None, :], y[:, None] - y[None, :])


def linear_operator(op):
    """``scipy.sparse.linalg.LinearOperator`` of the products of ``op`` (:class:`bem.InfluenceOperator`) on the
    flattened candidate nodes."""
    from scipy.sparse.linalg import LinearOperator

    mask = op.lattice.mask
    n = int(mask.sum())

    def mv(v):
        p = np.zeros(op.lattice.shape)
        p[mask] = np.ravel(v)
        return op.matvec(p)[mask]

    return LinearOperator((n, n), matvec=mv, rmatvec=mv, dtype=float)
