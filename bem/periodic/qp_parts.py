"""Parts of the periodic cell's constrained CG (:mod:`bem.periodic.qp`) with one form on NumPy and one on
every other array namespace (the same quantities, by the operations each namespace has; the rounding each
states)."""

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

    A brick array, 0 off its contact: on NumPy in single precision (a gather from it costs less time than looking
    the new contact's nodes up among the last one's, for 4 bytes a node); on other namespaces in double precision
    (a node selection of :class:`bem.backend.Backend` may be a boolean array there).

    Parameters
    ----------
    bk : bem.backend.Backend
        The backend of the iteration.
    shape : tuple of int
        The shape of the cell's brick arrays.
    """

    def __init__(self, bk, shape):
        self.bk, self.shape = bk, shape
        self.values = None

    def keep(self, nodes, z):
        """Keep ``z`` (1-D), the values at the node selection ``nodes``."""
        bk = self.bk
        if not bk.is_numpy:
            self.values = bk.spread(self.shape, nodes, z)
            return
        if self.values is None:
            self.values = np.empty(self.shape, dtype=np.float32)
        self.values.fill(0.0)  # a fill of the brick: faster than zeroing the last contact's nodes
        self.values.reshape(-1)[nodes] = z.astype(np.float32)

    def at(self, nodes):
        """The kept ``z`` at the node selection ``nodes`` (1-D, float64), 0 where it was not kept."""
        bk = self.bk
        if self.values is None:
            return bk.xp.zeros(bk.count(nodes), dtype=bk.xp.float64)
        z = bk.take(self.values, nodes)
        return z.astype(np.float64) if bk.is_numpy else z
