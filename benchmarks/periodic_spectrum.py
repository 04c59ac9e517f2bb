"""Benchmark: why the finest cell takes its iterations (the spectrum of the preconditioned contact).

On the finest cell the constrained conjugate gradients of :mod:`bem.periodic.qp` reduce the KKT residual
by about the same factor at every iteration, whether or not the contact set still moves: the rate is the
preconditioner's. This script measures that rate on the contact set of the converged solution, held fixed.

For each size ``N`` the rough cell of :mod:`cases` (``periodic``, mean pressure ``0.01 E*``) is solved
(KKT residual ``1e-12``); on its contact ``A`` the linear problem of the last iterations,
``C_AA p = delta - h_A`` with ``sum p`` fixed (the force), is solved by preconditioned conjugate
gradients written here, from the uniform pressure on ``A`` to a residual ``1e-8`` of the first, with

- ``cell``: the preconditioner of the cell's QP, ``z = M_AA r`` (``M = (C + C_nn 11'/N)^-1`` on the
  whole cell, restricted to ``A``: one transform pair);
- ``halo``: ``M_AA - M_AH diag(M_HH)^-1 M_HA`` with ``H`` the non-contact nodes next to the contact
  (a Schur correction of ``M_AA`` towards the exact ``C_AA^-1 = M_AA - M_AI M_II^-1 M_IA``,
  ``I`` every node off the contact: two transform pairs);
- ``edge``: ``M_AA + diag(c)``, the correction of :mod:`bem.periodic.edge` that the cell's QP makes once the
  contact settles, ``c_a = max(theta (M (1_I - f))_a, beta / C_nn - M_nn)`` (one transform pair, as ``cell``; the
  correction made once for the fixed contact).
- ``two-level``: ``edge`` and a coarse correction on the contact within square blocks of ``N / 32 x N / 32`` nodes
  (``Z``: a column per block, 1 on its contact nodes; ``E = Z' C_AA Z``, made here by a product per block), in the
  deflated form ``z = (I - Q C_AA) P r + Q r``, ``Q = Z E^-1 Z'``, ``P`` the ``edge`` preconditioner, from a start
  whose residual has no part on the blocks (``Z' r = 0``, kept by every step): the blocks' collective modes, which
  ``P`` overestimates, leave the spectrum. Three transform pairs an iteration (``P``, the product of ``P r`` and the
  step's own) and the coarse operator's ``|blocks|`` products, which the QP would make again whenever the contact
  moves: a measurement of what the coarse modes cost, not a preconditioner of the library.

The coefficients of the conjugate gradients give the Lanczos estimates of the extreme eigenvalues of
the preconditioned operator (``lambda_min``, ``lambda_max``, their ratio ``kappa``); the Ritz vector of
the largest tells where the slow modes live: its share of the squared norm on the contact's edge
nodes (nodes with a neighbour off the contact) against the edge nodes' share of the contact.

Run: ``python benchmarks/periodic_spectrum.py --out benchmarks/results/periodic_spectrum [--sizes 256 512 1024]``
(``spectrum.json``, ``spectrum.md`` and ``spectrum.png`` in ``--out``).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]

import cases  # noqa: E402

import bem  # noqa: E402
import bem.periodic.edge as edge  # noqa: E402
from bem.periodic.influence import PeriodicOperator  # noqa: E402
from validation.run.periodic import contact_spots, lattice_neighbours  # noqa: E402

PRECONDITIONERS = ("cell", "halo", "edge", "two-level")
BLOCKS = 32  # blocks of the two-level preconditioner along each side of the cell
RTOL = 1e-8


def edges_and_halo(contact):
    """``(edge, halo)``: contact nodes with a neighbour off the contact; non-contact nodes next to the contact."""
    c = contact.ravel()
    edge, halo = np.zeros_like(c), np.zeros_like(c)
    idx, neighbours = lattice_neighbours(contact.shape)
    for nb in (n.ravel() for n in neighbours):  # three of the six neighbours; the other three seen from them
        split = c != c[nb]  # node and neighbour on either side of the contact's edge
        for inside, outside in ((idx.ravel(), nb), (nb, idx.ravel())):
            across = split & c[inside]  # inside in contact, outside not
            edge[inside[across]] = True
            halo[outside[across]] = True
    return edge.reshape(contact.shape), halo.reshape(contact.shape)


def preconditioner(op, contact, kind):
    """``z(r)`` on the contact's nodes (flat), the zero-sum projection applied after."""
    M = op.preconditioner()
    e = np.zeros(op.lattice.shape)
    e[0, 0] = 1.0
    m_nn = float(M(e)[0, 0])  # M's diagonal
    if kind == "halo":
        halo = edges_and_halo(contact)[1]
    elif kind in ("edge", "two-level"):  # bem.periodic.edge's correction, in double precision here
        off = (~contact).astype(float)
        c = np.maximum(edge.THETA * M(off - off.mean())[contact], edge.FLOOR / float(op.diagonal) - m_nn)

    def apply(r):
        v = np.zeros(contact.shape)
        v[contact] = r
        w = M(v)
        if kind == "halo":
            w -= M(np.where(halo, w, 0.0) / m_nn)
        z = w[contact] + (c * r if kind in ("edge", "two-level") else 0.0)
        return z - z.mean()

    return apply


def contact_operator(op, contact):
    """``C_A(x)``: ``C_AA x`` on the contact's nodes (flat) less its mean (the force constraint: the mean is the
    change of ``delta``)."""

    def C_A(x):
        v = np.zeros(contact.shape)
        v[contact] = x
        y = op.matvec(v)[contact]
        return y - y.mean()

    return C_A


def coarse_correction(op, contact):
    """``Q r = Z E^-1 Z' r`` of the ``two-level`` preconditioner on the contact's nodes (flat, zero-sum), ``Z`` the
    contact of each block of ``N / BLOCKS`` nodes a side (its zero-sum part), ``E = Z' C_AA Z`` (a product a block)."""
    rows, cols = np.nonzero(contact)
    side = max(1, contact.shape[1] // BLOCKS)
    _, label = np.unique((rows // side) * (contact.shape[1] // side + 1) + cols // side, return_inverse=True)
    n_blocks = int(label.max()) + 1

    def spread(y):  # Z y, its mean taken out (the force constraint)
        v = y[label]
        return v - v.mean()

    C_A = contact_operator(op, contact)
    E = np.empty((n_blocks, n_blocks))
    for j in range(n_blocks):
        E[:, j] = np.bincount(label, weights=C_A(spread(np.eye(1, n_blocks, j)[0])), minlength=n_blocks)
    inverse = np.linalg.pinv(0.5 * (E + E.T), rcond=1e-10, hermitian=True)  # one zero mode: the constant
    return (lambda r: spread(inverse @ np.bincount(label, weights=r - r.mean(), minlength=n_blocks))), n_blocks


def fixed_contact_cg(op, contact, h, force_sum, precondition, maxiter=500, coarse=None):
    """Conjugate gradients for ``C_AA p = delta - h_A``, ``sum p = force_sum``, from the uniform ``p``.

    ``coarse``: ``Q`` of :func:`coarse_correction`, the start corrected by ``Q r`` and ``precondition`` deflated,
    ``(I - Q C_AA) precondition + Q``. Returns the iterations, the relative residuals, the Lanczos tridiagonal's
    eigenvalues and the Ritz vector of the largest one on the contact's nodes.
    """
    m = int(np.count_nonzero(contact))
    C_A = contact_operator(op, contact)
    x = np.full(m, force_sum / m)
    r = -(h[contact] + C_A(x))
    r -= r.mean()
    if coarse is not None:  # a start with Z' r = 0, and the deflated preconditioner
        x += (q := coarse(r))
        r -= C_A(q)
        smoother = precondition

        def precondition(r):
            z = smoother(r)
            return z + coarse(r - C_A(z))

    r0 = np.linalg.norm(r)
    z = precondition(r)
    d, rz = z.copy(), float(r @ z)
    alphas, betas, vectors, history = [], [], [], [1.0]
    for k in range(1, maxiter + 1):
        vectors.append((-1) ** (k - 1) * z / math.sqrt(rz))  # Lanczos: z normalised, signs alternating
        q = C_A(d)
        a = rz / float(d @ q)
        x += a * d
        r -= a * q
        alphas.append(a)
        history.append(float(np.linalg.norm(r) / r0))
        if history[-1] < RTOL:
            break
        z = precondition(r)
        rz_new = float(r @ z)
        betas.append(rz_new / rz)
        rz = rz_new
        d = z + betas[-1] * d
    diagonal = [1 / alphas[0]] + [1 / a + b / a0 for a, a0, b in zip(alphas[1:], alphas[:-1], betas)]
    off = [math.sqrt(b) / a for a, b in zip(alphas[:-1], betas)]
    eig, Y = np.linalg.eigh(np.diag(diagonal) + np.diag(off, 1) + np.diag(off, -1))
    top = np.array(vectors).T @ Y[:, -1]
    return k, history, eig, top


def case(n):
    """The rows of one size: the converged contact, then each preconditioner on it."""
    cell, h = cases.periodic_cell(n)
    t0 = time.perf_counter()
    res = bem.solve_periodic(h, step=cell.step, E_star=1.0, mean_pressure=cases.PBAR, rtol=1e-12)
    p = res.p.reshape(cell.shape)
    contact = p > 0
    edge, _ = edges_and_halo(contact)
    _, n_spots = contact_spots(contact)
    op = PeriodicOperator(cell, 1.0)
    base = dict(n=n, nodes=cell.n_nodes, solve_iterations=res.iterations, solve_s=round(time.perf_counter() - t0, 2),
                contact_fraction=round(float(contact.mean()), 4), spots=n_spots,
                edge_share_of_contact=round(float(edge[contact].mean()), 3))
    rows = []
    for kind in PRECONDITIONERS:
        t0 = time.perf_counter()
        coarse, n_blocks = coarse_correction(op, contact) if kind == "two-level" else (None, None)
        k, _, eig, top = fixed_contact_cg(op, contact, h, p.sum(), preconditioner(op, contact, kind), coarse=coarse)
        w = top**2 / float(top @ top)
        if kind == "cell":
            shown = contact, w
        rows.append(dict(base, preconditioner=kind, pairs_per_iteration=3 if kind in ("halo", "two-level") else 2,
                         coarse_products=n_blocks or 0, iterations=k,
                         seconds=round(time.perf_counter() - t0, 2), lambda_min=round(float(eig[0]), 3),
                         lambda_max=round(float(eig[-1]), 2), kappa=round(float(eig[-1] / eig[0]), 2),
                         top_share_on_edges=round(float(w[edge[contact]].sum()), 3)))
    return rows, shown


def markdown(rows):
    head = ("| N | contact | spots | edge nodes / contact | preconditioner | transform pairs / iteration "
            "| products to make it | iterations | lambda_min | lambda_max | kappa | top mode on edges |")
    lines = [head, "|" + "---|" * 12]
    for r in rows:
        lines.append(f"| {r['n']}^2 | {r['contact_fraction']} | {r['spots']} | {r['edge_share_of_contact']} | "
                     f"{r['preconditioner']} | {r['pairs_per_iteration']} | {r['coarse_products']} | "
                     f"{r['iterations']} | {r['lambda_min']} | {r['lambda_max']} | {r['kappa']} | "
                     f"{r['top_share_on_edges']} |")
    return "\n".join(lines) + "\n"


def plot(rows, shown, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_m, ax_k) = plt.subplots(1, 2, figsize=(11, 4.6))
    contact, w = shown  # the slowest mode of the preconditioner "cell"
    size = min(96, contact.shape[0])
    amp = np.zeros(contact.shape)
    amp[contact] = w
    r0, c0 = np.unravel_index(int(np.argmax(amp)), amp.shape)  # the window centred on the mode's largest node
    shift = (size // 2 - r0 + (r0 % 2), size // 2 - c0)  # an even row shift keeps the rows' parities
    amp, on = (np.roll(a, shift, axis=(0, 1))[:size, :size] for a in (amp, contact))
    ax_m.imshow(~on, cmap="Greys", vmin=0, vmax=4, interpolation="nearest")
    im = ax_m.imshow(np.ma.masked_where(~on, amp / amp.max()), cmap="magma_r", vmin=0, vmax=1,
                     interpolation="nearest")
    fig.colorbar(im, ax=ax_m, label="squared amplitude / its maximum in the window")
    ax_m.set_title(f"slowest mode (largest eigenvalue, preconditioner 'cell'): {size} x {size} nodes\n"
                   f"of the {contact.shape[0]}^2 cell around its largest value; grey: off the contact", fontsize=9)
    ax_m.set_xlabel("column")
    ax_m.set_ylabel("row")
    for i, (kind, marker) in enumerate(zip(PRECONDITIONERS, "os^D")):  # one colour a preconditioner
        rs = sorted((r for r in rows if r["preconditioner"] == kind), key=lambda r: r["nodes"])
        nodes = [r["nodes"] for r in rs]
        ax_k.plot(nodes, [r["kappa"] for r in rs], marker + "-", color=f"C{i}", label=f"{kind}: kappa")
        ax_k.plot(nodes, [r["iterations"] for r in rs], marker + "--", mfc="none", color=f"C{i}",
                  label=f"{kind}: iterations to 1e-8")
    ax_k.set_xscale("log")
    ax_k.set_xlabel("nodes of the cell")
    ax_k.grid(True, which="both", alpha=0.3)
    top = max(max(r["kappa"], r["iterations"]) for r in rows)
    ax_k.set_ylim(0, 1.5 * top)  # room above the curves for the legend
    ax_k.legend(fontsize=8, ncol=2, loc="upper left")
    ax_k.set_title("preconditioned contact operator, contact held fixed", fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, 0.97))  # room for the two-line title
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="results folder")
    parser.add_argument("--sizes", nargs="+", type=int, default=[256, 512, 1024])
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    rows, shown = [], None
    for n in args.sizes:
        new, shown = case(n)  # the last size's mode is shown in the figure
        rows += new
        for r in new:
            print(json.dumps(r), flush=True)
    data = json.dumps(dict(machine=cases.machine(), rows=rows), indent=1)
    cases.write_whole(os.path.join(args.out, "spectrum.json"), data)
    cases.write_whole(os.path.join(args.out, "spectrum.md"), markdown(rows))
    plot(rows, shown, os.path.join(args.out, "spectrum.png"))
    print(markdown(rows))


if __name__ == "__main__":
    main()
