"""Parts of the periodic cell's constrained CG (:mod:`bem.periodic.qp`) with one form on NumPy and one on
every other array namespace (the same quantities, by the operations each namespace has; the rounding each
states)."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["ContactBrick", "ContactNodes", "EARLY", "ENTER_SHARE", "KeptOnContact", "Projection", "STEP_SHARE",
           "StepArrays", "early_steps", "most_open", "weighted_square"]

#: while the contact moves in the first EARLY iterations, the step is STEP_SHARE of the minimum along the direction
#: and only the nodes whose gap is below ENTER_SHARE times the most negative one enter (measured in
#: docs/performance.md, "Newton's step in fewer passes, and the first steps of the cell's QP")
EARLY, STEP_SHARE, ENTER_SHARE = 12, 0.9, 0.3


def early_steps(k, record, excluded):
    """Whether iteration ``k`` is one of the first :data:`EARLY` and the last step changed the contact (``record``:
    the loop's :class:`bem.cg_rules.Record`), unless ``excluded`` (a compliance per node, a hardness)."""
    changes = record.history["changes"]
    return k <= EARLY and bool(changes) and changes[-1] > 0 and not excluded


def most_open(bk, nodes, gap):
    """The node selection ``nodes`` (of the backend ``bk``) and their gaps ``gap`` (1-D, negative) where the gap is
    below :data:`ENTER_SHARE` times the most negative one."""
    keep = gap < ENTER_SHARE * float(bk.xp.min(gap))
    return bk.subset(nodes, keep), gap[keep]


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


class ContactNodes:
    """The contact ``p > 0`` of the iterate as the constrained CG reads it, and how it changed.

    After a step on the contact's nodes that no node entered and after which every one of them kept a positive
    pressure (:meth:`stepped`), the next contact is the same: :meth:`read` gives the same node selection and the
    step's pressures there, with no comparison over the cell, no selection and no gather, and the step may keep
    what it made on the contact (``kept``). After any other step on NumPy the next contact is made from the step's
    arrays (its nodes with a positive pressure, and the entering ones merged in order): the same selection and
    pressures as a comparison over the cell, in a pass over the contact.

    Parameters
    ----------
    bk : bem.backend.Backend
        The backend of the iteration.
    p : array
        The starting pressure (brick array).
    merge : callable, optional
        The compiled merge of :mod:`bem.periodic.passes` (``merge(idx, values, stayed, new, new_values, out_idx,
        out_values, at) -> n``): with it the next contact is written into the one of two pairs of arrays the
        object holds that does not hold the present contact, rather than into new ones (their pages are not mapped
        again at every change of a large contact); without it by ``numpy.insert``. The same selection and values
        either way.
    """

    def __init__(self, bk, p, merge=None):
        self.bk, self.merge = bk, merge
        self._pairs = [None, None]  # the arrays of the contacts made from the step (with merge)
        self.was_on = p > 0  # the contact of the last count of changes
        self.n_was = int(bk.xp.count_nonzero(self.was_on))
        self.steady, self.idx, self.on, self.p_c, self.kept = False, None, None, None, (None, None)
        self.next = self.moved = None  # the contact made from the last step; its nodes that left and entered
        self.from_step = None  # (stayed, at, entering) where the contact of the last read was made from the step

    def read(self, p):
        """``(idx, p_c)``: the contact's node selection and the pressures there."""
        if self.steady:
            return self.idx, self.p_c
        if self.next is not None:
            (self.idx, p_c, *self.from_step), self.next = self.next, None
            return self.idx, p_c
        self.on, self.moved, self.from_step = p > 0, None, None
        self.idx = self.bk.select(self.on)  # from the boolean mask (faster than flatnonzero(p) on NumPy)
        return self.idx, self.bk.take(p, self.idx)

    def changes(self):
        """``(n, changes)``: the contact nodes of the last :meth:`read` and the nodes that entered or left it since
        the last call."""
        bk = self.bk
        n = bk.count(self.idx)
        if self.steady:  # was_on is this contact
            return n, 0
        kept = int(bk.xp.count_nonzero(bk.take(self.was_on, self.idx)))  # nodes in both contacts
        changes = (n - kept) + (self.n_was - kept)
        if self.moved is None:
            self.was_on = self.on
        else:  # the contact of the last read came from the step (no mask of it): was_on follows it in place
            left, entering = self.moved
            self.was_on.reshape(-1)[left] = False
            self.was_on.reshape(-1)[entering] = True
            self.moved = None
        self.n_was = n
        return n, changes

    def stepped(self, p_c, entered, entering=None, p_o=None):
        """Note a step that left the pressures ``p_c`` at the nodes of the last :meth:`read` (``entered``: nodes
        entered elsewhere, ``p_o`` at the nodes ``entering``; every other node at 0)."""
        positive = p_c > 0
        self.steady = not entered and bool(self.bk.xp.all(positive))
        self.p_c = p_c if self.steady else None  # not held beside the next contact
        if self.steady or not self.bk.is_numpy:
            return
        left = self.idx[~positive]
        new, p_new = (entering[on := p_o > 0], p_o[on]) if entered else (left[:0], p_c[:0])
        if self.merge is not None:  # the sorted merge of two disjoint sorted selections, into held arrays
            out_idx, out_p = self._pair(int(np.count_nonzero(positive)) + new.size, p_c.dtype)
            at = np.empty(new.size, dtype=np.intp)  # where the entering nodes go among those that stayed
            n = self.merge(self.idx, p_c, positive, new, p_new, out_idx, out_p, at)
            idx, p_c = out_idx[:n], out_p[:n]
        else:
            idx, p_c = self.idx[positive], p_c[positive]
            at = np.searchsorted(idx, new)
            if new.size:
                idx, p_c = np.insert(idx, at, new), np.insert(p_c, at, p_new)
        self.next, self.moved = (idx, p_c, positive, at, new), (left, new)

    def _pair(self, n, dtype):
        """Arrays of at least ``n`` node indices and values for the next contact: the pair not holding the present
        one (made anew, with an eighth to spare, where it is too small)."""
        i = int(self._pairs[0] is not None and np.may_share_memory(self._pairs[0][0], self.idx))
        pair = self._pairs[i]
        if pair is None or pair[0].size < n or pair[1].dtype != dtype:
            self._pairs[i] = None  # let go before the new pair is made
            size = n + n // 8
            pair = self._pairs[i] = np.empty(size, dtype=self.idx.dtype), np.empty(size, dtype=dtype)
        return pair

    def over(self, idx, make, old=None):
        """Values at the contact's nodes ``idx``: ``make(nodes)``, a gather at the given nodes; where the contact of
        the last :meth:`read` was made from the step and ``old`` holds the values at the nodes of the contact before
        it, ``old`` at the nodes that stayed and ``make`` at the entering nodes only, merged in order."""
        if self.from_step is None or old is None:
            return make(idx)
        positive, at, new = self.from_step
        kept = old[positive]
        return np.insert(kept, at, make(new)) if new.size else kept


class ContactBrick:
    """A float32 brick array holding values at some nodes and 0 elsewhere: the gap on the contact for the
    preconditioner, then the search direction.

    On NumPy one buffer, refilled: a write at the node selection of the last write (the same object) needs no
    fill, as every node it holds is written again; other namespaces get a new array at every write. ``last``
    is the last write's values rounded to single precision (the brick's values at its nodes).

    Parameters
    ----------
    bk, shape
        The backend of the iteration and the shape of the cell's brick arrays (as for
        :class:`KeptOnContact`).
    write : callable, optional
        The compiled write of :mod:`bem.periodic.step_passes` (``write(brick, nodes, values, fill) -> last``, on
        NumPy): the fill and the put in one pass on the threads; the same values as without it.
    """

    def __init__(self, bk, shape, write=None):
        self.bk, self.shape, self._write = bk, shape, write
        self.values = np.zeros(shape, dtype=np.float32) if bk.is_numpy else bk.xp.zeros(shape, dtype=bk.xp.float32)
        self.nodes = self.last = None

    def write(self, nodes, values):
        """The brick with ``values`` (1-D) at the node selection ``nodes``, rounded to float32, 0 elsewhere."""
        bk = self.bk
        if not bk.is_numpy:
            xp = bk.xp
            self.last = xp.astype(values, xp.float32)
            self.values = bk.put(xp.zeros(self.shape, dtype=xp.float32), nodes, self.last)
            return self.values
        fill = nodes is not self.nodes  # a fill: faster than zeroing the nodes of the last write
        if self._write is not None:
            self.last = self._write(self.values, nodes, values, fill)
        else:
            if fill:
                self.values.fill(0.0)
            self.last = values.astype(np.float32)  # rounded first: a faster scatter, the same values
            self.values.reshape(-1)[nodes] = self.last
        self.nodes = nodes
        return self.values

    def write_move(self, at, values, entering=None, entering_values=None):
        """The last write changed where a step's move differs from the direction (NumPy only): ``values`` at the
        last write's nodes where the boolean ``at`` (one entry a node) is true, then ``entering_values`` added at the
        node selection ``entering`` (nodes off the last write, or among ``at``), rounded to float32; the brick, or
        None (nothing written) where a value is not below half the largest float32 (their sum stays finite).
        :meth:`restore` undoes it."""
        edits = [values] if entering is None else [values, entering_values]
        if not all(bool(np.all(np.abs(v) < np.finfo(np.float32).max / 2)) for v in edits):  # False for NaN too
            return None
        flat = self.values.reshape(-1)
        flat[self.nodes[at]] = values.astype(np.float32)
        if entering is not None:
            flat[entering] += entering_values.astype(np.float32)
        self._move = at, entering
        return self.values

    def restore(self):
        """The brick as the last :meth:`write` left it, after :meth:`write_move`."""
        at, entering = self._move
        flat = self.values.reshape(-1)
        if entering is not None:
            flat[entering] = 0.0
        flat[self.nodes[at]] = self.last[at]


class KeptOnContact:
    """Values kept at the nodes of a contact, read at the nodes of a later contact (0 at the nodes that were off it):
    the last preconditioned gap ``z_old`` of the Polak-Ribiere+ coefficient, the correction of
    :class:`bem.periodic.edge.EdgeCorrection`.

    On NumPy in single precision: at the kept node selection itself (the same object: the contact did not
    change) the kept values; at a contact made from the step (:meth:`ContactNodes.over`) the kept values at the
    nodes that stayed and a lookup at the entering ones; at other nodes a gather from a brick array that holds
    them, 0 off their nodes (faster than looking the new contact's nodes up among the last one's, for 4 bytes a
    node), filled at the first such read after a keep (``hold``: held to the next, else made for that read only). On
    other namespaces in double precision, a brick array at every keep (a node selection of
    :class:`bem.backend.Backend` may be a boolean array there).

    Parameters
    ----------
    bk : bem.backend.Backend
        The backend of the iteration.
    shape : tuple of int
        The shape of the cell's brick arrays.
    hold : bool
        Whether the NumPy form holds its brick array between reads.
    """

    def __init__(self, bk, shape, hold=True):
        self.bk, self.shape, self.hold = bk, shape, hold
        self.values = self.nodes = self.z = None
        self.filled = False

    def keep(self, nodes, z):
        """Keep ``z`` (1-D), the values at the node selection ``nodes`` (copied)."""
        bk, self.nodes = self.bk, nodes
        if not bk.is_numpy:
            self.values = bk.spread(self.shape, nodes, z)
            return
        self.z, self.filled = z.astype(np.float32), False

    def at(self, nodes, contact=None):
        """The kept values at the node selection ``nodes`` (1-D, float64), 0 where not kept; ``contact`` the
        :class:`ContactNodes` of ``nodes``, whose selection at the last keep was the contact before its last step."""
        bk = self.bk
        if not bk.is_numpy:
            return bk.take(self.values, nodes) if self.values is not None else bk.xp.zeros(
                bk.count(nodes), dtype=bk.xp.float64)
        if self.z is None:
            return np.zeros(bk.count(nodes), dtype=np.float64)
        if nodes is self.nodes:
            return self.z.astype(np.float64)
        if contact is not None and contact.from_step is not None and self.nodes.size:  # a lookup at the entering nodes
            return contact.over(nodes, self._lookup, self.z).astype(np.float64)
        if not self.filled:
            if self.values is None:
                self.values = np.empty(self.shape, dtype=np.float32)
            self.values.fill(0.0)
            self.values.reshape(-1)[self.nodes] = self.z
            self.filled = True
        out = bk.take(self.values, nodes).astype(np.float64)
        if not self.hold:
            self.values, self.filled = None, False
        return out

    def _lookup(self, nodes):  # the kept values at a few sorted nodes, 0 where not kept
        at = np.minimum(np.searchsorted(self.nodes, nodes), self.nodes.size - 1)
        return np.where(self.nodes[at] == nodes, self.z[at], np.float32(0))


class Projection:
    """The direction ``m = M 1`` of the oblique projection ``z - m (1.z) / (1.m)`` of a QP with a compliance per node
    (:mod:`bem.periodic.qp`): ``M`` of the stiff nodes of a contact, held over its largest magnitude ``scale`` in half
    precision on NumPy (2 bytes a node), in single precision elsewhere (no float16 there). Any direction of nonzero
    sum on the contact keeps ``sum z = 0``; one made on an earlier contact of the same cell serves a later one.
    """

    def __init__(self):
        self.values, self.scale = None, 1.0

    def make(self, bk, m):
        """Hold ``m`` (a brick array of the cell); returns ``self``."""
        self.scale = float(bk.xp.max(bk.xp.abs(m))) or 1.0
        self.values = bk.xp.astype(m * (1.0 / self.scale), np.float16 if bk.is_numpy else bk.xp.float32)
        return self

    def at(self, bk, nodes):
        """``m`` at the node selection ``nodes`` (1-D, double precision)."""
        return bk.xp.astype(bk.take(self.values, nodes), bk.float64) * self.scale


class StepArrays:
    """The bytes of a complex128 spectrum of the cell that the products of every step write into, on NumPy: a
    complex128 spectrum or a float64 brick array (which fits there), or in each half of the bytes a complex64
    spectrum or a float32 brick array. One array for the solve instead of new arrays at every product: the pages of
    a new array above the allocator's mapping threshold (32 MB by default in glibc) are mapped and zeroed by the
    kernel at each allocation, a cost of the order of the transforms on large cells (``docs/performance.md``, "The
    arrays the cell's step reuses"). Off NumPy every method gives ``None`` (new arrays).

    Parameters
    ----------
    bk : bem.backend.Backend
        The backend of the iteration.
    shape : tuple of int
        The shape of the cell's brick arrays ``(n_rows, n_cols)``, ``n_rows`` even.
    """

    def __init__(self, bk, shape):
        self.bk, self.shape = bk, tuple(shape)
        self.spectrum_shape = (shape[0] // 2, 2, shape[1] // 2 + 1)
        self.bytes = np.empty(16 * math.prod(self.spectrum_shape), dtype=np.uint8) if bk.is_numpy else None

    def _half(self, second):
        half = self.bytes.size // 2
        return self.bytes[half:] if second else self.bytes[:half]

    def spectrum(self, dtype, second=False):
        """The array as a spectrum of the layout of :meth:`bem.periodic.PeriodicOperator.spectrum` in ``dtype``:
        complex128 in all the bytes, complex64 in their first half (``second``: in the second)."""
        if self.bytes is None:
            return None
        n = math.prod(self.spectrum_shape)
        data = self.bytes if np.dtype(dtype) == np.complex128 else self._half(second)
        return data.view(dtype)[:n].reshape(self.spectrum_shape)

    def brick32(self, second=True):
        """A float32 brick array in the second half of the bytes (``second=False``: the first)."""
        if self.bytes is None:
            return None
        return self._half(second)[: 4 * math.prod(self.shape)].view(np.float32).reshape(self.shape)

    def brick64(self):
        """A float64 brick array in all the bytes (where no spectrum is held: ``D p`` and the final ``C p``), or
        None off NumPy."""
        if self.bytes is None:
            return None
        return self.bytes[: 8 * math.prod(self.shape)].view(np.float64).reshape(self.shape)

    def single(self, v):
        """``v`` rounded to float32 (in :meth:`brick32` on NumPy)."""
        if self.bytes is None:
            return self.bk.xp.astype(v, self.bk.xp.float32)
        out = self.brick32()
        out[...] = v
        return out


def added_into(bk, x, y):
    """``x + y`` in ``x``'s precision (NumPy: into ``x``)."""
    return np.add(x, y, out=x) if bk.is_numpy else bk.xp.astype(x + y, x.dtype, copy=False)


def multiplied_into(bk, x, y):
    """``x y`` in ``x``'s precision (NumPy: into ``x``)."""
    return np.multiply(x, y, out=x) if bk.is_numpy else bk.xp.astype(x * y, x.dtype, copy=False)


def product_array(u, dtype, home=None):
    """The array a product of the whole cell goes into on NumPy: ``u`` where it has ``dtype``; else the bytes of
    ``home`` (the caller's float64 ``u0``, held with ``overwrite_u0``) as a ``dtype`` array of its shape; else None
    (a new array, the last ``u`` let go first)."""
    if u is not None and u.dtype == dtype:
        return u
    return None if home is None else home.reshape(-1).view(dtype)[: home.size].reshape(home.shape)
