"""Run a periodic scene: the cell of a rough surface pressed by a flat (:func:`bem.solve_periodic`).

:func:`execute_periodic` solves the scene's cell (:mod:`validation.scene.rough`) and returns a
:class:`validation.run.RunOutcome` whose :class:`validation.run.record.RunResult` holds the
periodic quantities in its ``periodic`` part: ``mean_pressure``, ``contact_fraction``,
``mean_gap``, ``n_spots`` (the contact spots, :func:`contact_spots`), ``spots`` and ``surface``
(docs/results.md).
"""

from __future__ import annotations

import logging
import time

import numpy as np

from ..provenance import provenance
from ..progress import stages_of
from .calibrate import resolve_layer
from .parts import PeriodicPart, SpotSummary
from .record import RunResult
from .result import bem_part, unit_symbols

__all__ = ["execute_periodic", "contact_spots", "periodic_result"]

log = logging.getLogger(__name__)
#: the entries of a periodic scene's ``bem`` options that describe the cell, not the solver
_CELL_KEYS = ("periodic", "cell_nodes", "step", "cell", "size", "extent", "extent_auto", "expected", "nodes_across",
              "n_nodes")


def _neighbours(shape):
    """Index arrays of three of the six neighbours of every node of a periodic brick array.

    Node ``(q, r)`` of row ``r`` (``x = q + (r mod 2)/2`` steps) touches ``(q +- 1, r)`` and, in
    the rows ``r +- 1``, the two nodes half a step to either side: ``(q - 1, r + 1)`` and
    ``(q, r + 1)`` for even ``r``, ``(q, r + 1)`` and ``(q + 1, r + 1)`` for odd ``r``; indices
    wrap around the cell. The other three are these seen from the neighbour.
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
    idx, neighbours = _neighbours(c.shape)
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


def periodic_result(scene, res, layer_info, *, times, messages, spots):
    """The :class:`validation.run.record.RunResult` of a periodic run (module docstring; docs/results.md)."""
    from ..io import to_jsonable

    cell, lattice, stats = res.lattice, scene.gap.lattice, scene.gap.surface.stats
    labels, n = spots
    surface = dict(stats.as_dict(), stretch_y=lattice.stretch_y, stretch_large=bool(lattice.stretch_large))
    bem = bem_part(res, E_star=scene.E_star, step=cell.step, size=list(cell.size), n_nodes=int(res.p.size),
                   n_contact=int(np.count_nonzero(res.p > 0)))
    periodic = PeriodicPart(mean_pressure=res.mean_pressure, contact_fraction=res.contact_fraction,
                            mean_gap=res.mean_gap, n_spots=n,
                            spots=SpotSummary(**_spot_summary(labels, n, cell.node_area)), surface=surface)
    top = to_jsonable({
        "scene": scene.name, "title": scene.title, "units": scene.units.label,
        "unit_symbols": unit_symbols(scene.units), "source": scene.source, "overrides": list(scene.overrides),
        "method": res.method,
        "p_max": res.p_max, "force": res.force, "approach": res.approach, "contact_area": res.contact_area,
        "contact_radius": None, "contact_extent": None,
        "iterations": res.iterations, "converged": bool(res.converged), "kkt_residual": res.kkt_residual,
        "message": res.message, "messages": list(messages), "wall_time_s_by_part": dict(times),
        "layer": layer_info, "alpha_b": None, "report": scene.report, "provenance": provenance(),
    })
    parts = {"bem": bem, "periodic": periodic}
    parts = {k: type(v).from_json(v.to_json(), where=k, source="the run") for k, v in parts.items()}
    return RunResult(**top, **parts, fem=None, fem_profile=None, analytic=None, comparison=None, scales=None,
                     profile=None, stress=None)


def execute_periodic(scene, *, progress=None):
    """Solve a periodic scene (:func:`bem.solve_periodic`); returns a :class:`validation.run.RunOutcome`.

    ``load.force`` is the force on one cell, solved as the mean pressure ``force / (Lx Ly)``.
    ``progress``: a :class:`validation.progress.Progress` holding the stage ``"bem"``, or a callback
    (:mod:`validation.progress`).
    """
    import bem

    from .runner import RunOutcome

    stages = stages_of(progress, ["bem"])

    t0 = time.perf_counter()
    messages = []
    lattice, opts, load = scene.gap.lattice, scene.bem, scene.load
    stats = scene.gap.surface.stats
    if stats.edge_jump_large:
        messages.append(f"the surface's cell has a large edge jump ({stats.edge_jump:.4g} against a grid step of "
                        f"{stats.grid_step:.4g}, rms height {stats.rms_height:.4g}): its repetition has a step at "
                        "the cell's edges")
    if lattice.stretch_large:
        messages.append(f"the lattice stretches the surface along y by {lattice.stretch_y:.4f}: choose bem.cell_nodes "
                        "for which the cell's rows fit (docs/rough.md)")
    layer, layer_info = resolve_layer(scene.layer_spec, step=lattice.step, E_star=scene.E_star, solve=None,
                                      layer=scene.layer)
    area = lattice.size[0] * lattice.size[1]
    mean_pressure = load.get("mean_pressure") or (None if load["force"] is None else load["force"] / area)
    kw = {k: v for k, v in opts.items() if k not in _CELL_KEYS}  # the solver options

    def callback(k, _p):
        stages.note(f"iteration {k}")

    stages("bem")
    t = time.perf_counter()
    res = bem.solve_periodic(lattice.gap(), step=lattice.step, E_star=scene.E_star, mean_pressure=mean_pressure,
                             approach=load["approach"], layer=layer,
                             callback=callback if stages.callback is not None else None, **kw)
    times = {"bem": time.perf_counter() - t, "fem": None, "layer_reference": None, "stress": None}
    if not res.converged:
        messages.append(f"BEM did not converge: {res.message}")
    spots = contact_spots(res.p.reshape(res.lattice.shape) > 0)
    times["total"] = time.perf_counter() - t0
    result = periodic_result(scene, res, layer_info, times=times, messages=messages, spots=spots)
    return RunOutcome(scene=scene, result=result, bem=res, layer=layer, spots=spots[0])
