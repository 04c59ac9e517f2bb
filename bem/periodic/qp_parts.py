"""Parts of the periodic cell's constrained CG (:mod:`bem.periodic.qp`) with one form on NumPy and one on
every other array namespace (the same numbers, by the operations each namespace has)."""

from __future__ import annotations

import numpy as np

__all__ = ["LastPreconditionedGap", "weighted_square"]


def weighted_square(bk, d, t):
    """``sum d t^2`` of two 1-D arrays of the backend ``bk`` as a Python float (NumPy: ``einsum``, no threaded BLAS).

    Parameters
    ----------
    bk : bem.backend.Backend
        The arrays' backend.
    d, t : array
        Weights (a compliance per node [length/pressure]) and values (a search direction [pressure]).
    """
    if bk.is_numpy:
        return float(np.einsum("i,i,i->", d, t, t))
    return float(bk.xp.sum(d * t * t))


class LastPreconditionedGap:
    """The last preconditioned gap ``z`` of the iteration on its contact, read at the nodes of the next contact
    (0 at the nodes that were off it): the ``z_old`` of the Polak-Ribiere+ coefficient.

    On NumPy its (sorted) flat nodes and values, looked up by ``searchsorted``; on other namespaces a brick
    array, 0 off its contact (a node selection of :class:`bem.backend.Backend` may be a boolean array there).

    Parameters
    ----------
    bk : bem.backend.Backend
        The backend of the iteration.
    shape : tuple of int
        The shape of the cell's brick arrays.
    """

    def __init__(self, bk, shape):
        self.bk, self.shape = bk, shape
        self.nodes = self.values = None

    def keep(self, nodes, z):
        """Keep ``z`` (1-D), the values at the node selection ``nodes``."""
        if self.bk.is_numpy:
            self.nodes, self.values = nodes, z.copy()
        else:
            self.values = self.bk.spread(self.shape, nodes, z)

    def at(self, nodes):
        """The kept ``z`` at the node selection ``nodes`` (1-D, float64), 0 where it was not kept."""
        bk = self.bk
        if self.values is None:
            return bk.xp.zeros(bk.count(nodes), dtype=bk.xp.float64)
        if not bk.is_numpy:
            return bk.take(self.values, nodes)
        if not self.nodes.size:
            return np.zeros(nodes.size)
        pos = np.searchsorted(self.nodes, nodes)
        np.minimum(pos, self.nodes.size - 1, out=pos)
        return np.where(self.nodes[pos] == nodes, self.values[pos], 0.0)
