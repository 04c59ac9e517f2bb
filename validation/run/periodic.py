"""The domain of a periodic scene: the cell of a rough surface pressed by a flat (:class:`bem.PeriodicCell`).

:class:`Cell` is one of the two domains of :func:`validation.run.execute_scene` (the other is
the region of an isolated contact, :class:`validation.run.region.Region`): it says what
:func:`bem.solve` solves (the scene's cell, :mod:`validation.scene.rough`, its nodal gap and its
load) and makes the ``periodic`` part of the run result:
``mean_pressure``, ``contact_fraction``, ``mean_gap``, ``n_spots`` (the contact spots,
:func:`contact_spots`), ``spots`` and ``surface`` (docs/results.md).
"""

from __future__ import annotations

import numpy as np

from .parts import PeriodicPart, SpotSummary

__all__ = ["Cell", "contact_spots", "lattice_neighbours"]


def lattice_neighbours(shape):
    """Index arrays of three of the six neighbours of every node of a periodic brick array.

    Node ``(q, r)`` of row ``r`` (``x = q + (r mod 2)/2`` steps) touches ``(q +- 1, r)`` and, in
    the rows ``r +- 1``, the two nodes half a step to either side: ``(q - 1, r + 1)`` and
    ``(q, r + 1)`` for even ``r``, ``(q, r + 1)`` and ``(q + 1, r + 1)`` for odd ``r``; indices
    wrap around the cell. The other three are these seen from the neighbour.

    Returns
    -------
    idx : ndarray of int, shape ``shape``
        The flat index of every node.
    neighbours : tuple of three ndarray of int, shape ``shape``
        The flat index of the neighbour at ``(q + 1, r)`` and of the two in row ``r + 1`` (as above).
    """
    n_rows, n_cols = shape
    idx = np.arange(n_rows * n_cols).reshape(shape)
    up = np.roll(idx, -1, axis=0)
    odd = (np.arange(n_rows) % 2 == 1)[:, None]
    diagonal = np.where(odd, np.roll(up, -1, axis=1), np.roll(up, 1, axis=1))
    return idx, (np.roll(idx, -1, axis=1), up, diagonal)


def contact_spots(contact):
    """Label the contact spots of a periodic cell: connected clusters of nodes in contact.

    Two nodes in contact belong to the same spot when they are neighbours on the triangular
    lattice (its six nearest nodes), across the cell's edges too (the cell repeats).

    Parameters
    ----------
    contact : array_like of bool, shape (n_rows, n_cols)
        Brick array of the nodes in contact (:class:`bem.periodic.PeriodicCell` layout),
        ``n_rows`` even.

    Returns
    -------
    labels : ndarray of int, shape (n_rows, n_cols)
        ``0 .. n - 1`` the spot of each node in contact (numbered in the order of their first
        node), ``-1`` elsewhere.
    n : int
        Number of spots.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    c = np.asarray(contact, dtype=bool)
    idx, neighbours = lattice_neighbours(c.shape)
    flat = c.ravel()
    rows = [idx[c]]
    cols = [idx[c]]
    for nb in neighbours:
        keep = c & flat[nb]
        rows.append(idx[keep])
        cols.append(nb[keep])
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    graph = coo_matrix((np.ones(rows.size, dtype=np.int8), (rows, cols)), shape=(c.size, c.size))
    _, comp = connected_components(graph, directed=False)
    labels = np.full(c.size, -1, dtype=np.int64)
    if flat.any():
        _, first, inverse = np.unique(comp[flat], return_index=True, return_inverse=True)
        order = np.argsort(np.argsort(first))  # spots numbered by their first node
        labels[flat] = order[inverse.ravel()]
        return labels.reshape(c.shape), int(first.size)
    return labels.reshape(c.shape), 0


def _spot_summary(labels, n, node_area):
    sizes = np.bincount(labels[labels >= 0], minlength=n) if n else np.zeros(0, dtype=int)
    return {"count": n, "largest_area": float(sizes.max(initial=0) * node_area),
            "mean_area": float(sizes.mean() * node_area) if n else 0.0,
            "single_node": int(np.count_nonzero(sizes == 1))}


class Cell:
    """The periodic cell of a rough surface pressed by a flat (:class:`bem.PeriodicCell`).

    ``load.force`` is the force on one cell, solved as the mean pressure ``force / (Lx Ly)``.

    Parameters
    ----------
    scene : validation.scene.Scene
        A validated periodic scene (:mod:`validation.scene.rough`).
    messages : list of str
        The run's messages; the notes on the surface's cell (a large edge jump, a stretched lattice)
        are appended.

    Attributes
    ----------
    step : float
        Lattice step [length].
    gap : ndarray
        The initial gap at the cell's nodes (brick array) [length].
    load : dict
        The load keywords of :func:`bem.solve`: ``mean_pressure`` and ``approach`` (one is ``None``).
    bem_domain : bem.PeriodicCell
        The cell of the scene's lattice (``bem.cell_nodes``).
    spots : ndarray of int or None
        The contact spot of each node (:func:`contact_spots`) of the last :meth:`parts`.
    """

    def __init__(self, scene, messages):
        import bem

        self.scene = scene
        self.lattice = lattice = scene.gap.lattice
        self.step = lattice.step
        self.gap = lattice.gap()
        load = scene.load
        area = lattice.size[0] * lattice.size[1]
        mean_pressure = load.get("mean_pressure") or (None if load["force"] is None else load["force"] / area)
        self.load = {"mean_pressure": mean_pressure, "approach": load["approach"]}
        self.bem_domain = bem.PeriodicCell(lattice.step, *self.gap.shape[::-1])
        self.spots = None
        messages.extend(_surface_notes(scene))

    def parts(self, res):
        """The parts of the run result that belong to a periodic cell (:func:`validation.run.result.build_result`).

        Returns
        -------
        dict
            ``bem``: the cell's field of :class:`validation.run.parts.BemPart` (``size``);
            ``periodic`` (:class:`validation.run.parts.PeriodicPart`: the spots, the surface's
            statistics); ``contact_extent`` and ``profile`` (``None``).
        """
        cell, lattice, stats = res.lattice, self.lattice, self.scene.gap.surface.stats
        labels, n = contact_spots(res.p.reshape(cell.shape) > 0)
        self.spots = labels
        made = self.scene.gap.cell
        surface = dict(stats.as_dict(), stretch_y=lattice.stretch_y, stretch_large=bool(lattice.stretch_large),
                       cell=made.cell, spike_points=made.spikes.count, spikes_removed=made.spikes_removed,
                       spikes=made.spikes.as_dict())
        periodic = PeriodicPart(mean_pressure=res.mean_pressure, contact_fraction=res.contact_fraction,
                                mean_gap=res.mean_gap, n_spots=n,
                                spots=SpotSummary(**_spot_summary(labels, n, cell.node_area)), surface=surface)
        return {"bem": {"size": list(cell.size)}, "contact_extent": None, "profile": None, "periodic": periodic}

    def field(self, res):
        """Extra nodal fields of ``bem_field.vtu`` (:func:`bem.files.write_result_vtu`): the initial gap and
        the contact spot of each node (``-1``: no contact)."""
        return {"initial_gap": self.scene.gap.nodal_gap(), "contact_spot": self.spots.ravel()}


def _surface_notes(scene):
    """What the run says about the surface's cell: a large edge jump (the one statement of the seam of a scene's
    cell, the library's warning kept quiet), a lattice that stretches it."""
    lattice, stats = scene.gap.lattice, scene.gap.surface.stats
    unit = f" {scene.units.length}" if scene.units.length else ""
    notes = []
    if stats.edge_jump_large:
        notes.append(f"the surface's cell has a large edge jump ({stats.edge_jump:.4g}{unit} against a grid step of "
                     f"{stats.grid_step:.4g}{unit}, rms height {stats.rms_height:.4g}{unit}): its repetition has a "
                     "step at the cell's edges (gap.cell = \"mirror\" makes a cell without one)")
    if lattice.stretch_large:
        notes.append(f"the lattice stretches the surface along y by {lattice.stretch_y:.4f}: choose bem.cell_nodes "
                     "for which the cell's rows fit (docs/rough.md)")
    return notes
