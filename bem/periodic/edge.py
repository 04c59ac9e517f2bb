"""The cell's preconditioner corrected at the edges of the contact (its regional form on the contact).

The constrained CG of :mod:`bem.periodic.qp` preconditions the gap ``r`` on the contact ``A`` by ``M_AA r``:
``M``, the inverse of the whole cell's operator, restricted to ``A`` (one transform pair). ``M_AA`` exceeds the
exact ``C_AA^-1`` by ``M_AI M_II^-1 M_IA`` (``I`` the nodes off the contact), a term that lives on the edges of
the contact spots and grows with the lattice: the condition number of the preconditioned contact rises with
``log N`` (``docs/performance.md``, "The rate of the finest cell").

``M``'s off-diagonal entries are negative but for two small shells (the six nearest nodes ``-0.155 M_nn``, the
next two shells ``+0.009`` and ``+0.005 M_nn``, the rest negative and falling as the distance cubed), so its
quadratic form on a pressure ``x`` on ``A`` (0 elsewhere) is about ``x.M x = 1/2 sum_{a, b in A} -M_ab (x_a -
x_b)^2 + sum_{a in A} (M 1)_a x_a^2 - sum_{a in A} (M 1_I)_a x_a^2``: the last sum, each contact node's coupling
to the nodes off the contact, ``(M 1_I)_a = sum_{i in I} M_ai`` (negative), weighs the pressure's jump to 0 across
the edge. Without it the form is the regional one, pairs of contact nodes only: the intrinsic ``H^1/2(A)`` form,
the space of the gap on the contact, against the form of the pressure extended by zero. The correction takes
``theta`` (:data:`THETA`) of that sum away, and keeps every diagonal entry at least ``beta / C_nn``
(:data:`FLOOR`; ``1 / C_nn`` is the exact inverse at a node alone in contact):

    z = M_AA r + c r,    c_a = max(theta (M (1_I - f))_a, beta / C_nn - M_nn),

``f`` the share of the cell's nodes off the contact (the mean taken away, so that ``M``'s value at frequency 0
does not enter), ``M_nn`` its diagonal. On the contact of the cell of ``benchmarks/periodic_spectrum.py``, held
fixed, the condition number is 9.2, 9.5, 9.8 and 10.3 at 65k, 262k, 1M and 4.2M nodes against 12.2, 14.4, 16.8
and 19.3 with ``M_AA`` alone. ``theta = 0.9`` conditions these self-affine contacts a little better and the contacts
of smooth surfaces worse than ``M_AA`` alone; ``0.7`` conditions both better (the dense spectra of
``tests/bem/test_periodic_edge.py``; the iterations in ``docs/performance.md``).

While the contact set moves, the correction's longer steps at the edges move it more (more iterations), so the
correction is made from the first step that changes at most :data:`SETTLED` of the contact's nodes, and made again
once the nodes changed since exceed :data:`REMAKE` of them; between, the nodes that stay in contact keep their ``c``
and a node that entered takes 0 (``M_AA``'s own diagonal). Making it takes a transform pair in single precision,
``M (1_A - |A| / N)``, and once a solve ``M_nn``, the mean of ``M``'s symbol; ``c`` is held at the contact's nodes
only (float32).
A step whose corrected ``z`` is not a descent direction (``r.z <= 0``) takes the uncorrected one.

With a compliance ``D`` per node (a Newton step's model, :func:`bem.kalker.compliance_preconditioner`) ``M`` inverts
``C + lam`` for the median ``lam`` of ``D`` on the stiff contact and preconditions those nodes only (Jacobi at the
nodes whose ``D`` dominates, the soft ones): ``A`` is the stiff contact, the soft nodes count as off it, and ``c`` is
0 at them. On the six model QPs of the finest level of the root-layer cell of ``benchmarks/periodic_rough.py`` at
1024^2, each from Newton's start and to Newton's tolerance, 45 iterations against 52 uncorrected (and, each to
``1e-9``, 120 against 153). Where the soft nodes are more than half of the contact when it settles, the stiff contact
is islands among nodes that carry pressure, not the edge of the pressure, and no correction is made in that solve:
on the model QPs of a bilinear law soft below its knee (``5 C_nn`` there, 70 % of the contact soft) at 256^2,
corrected, 237 iterations to ``1e-9`` against 211 (a root law, 4-7 % soft: 132 against 161; a power law of exponent
0.3, 22-27 % soft: 185 against 212).
"""

from __future__ import annotations

from .qp_parts import KeptOnContact
from .symbol import Symbol, mirrored_sum

__all__ = ["FLOOR", "REMAKE", "SETTLED", "THETA", "EdgeCorrection"]

#: share of each contact node's coupling to the nodes off the contact taken out of ``M``'s diagonal
THETA = 0.7
#: the corrected diagonal is at least ``FLOOR / C_nn``
FLOOR = 0.85
#: the correction starts at the first step that changes at most this share of the contact's nodes
SETTLED = 3e-3
#: and is made again once the nodes changed since exceed this share of the contact's nodes
REMAKE = 2e-3


class EdgeCorrection:
    """The correction ``c r`` of the module docstring for one solve of the cell's QP.

    Parameters
    ----------
    bk : bem.backend.Backend
        The backend of the iteration.
    apply_m : callable
        ``apply_m(r32, out)``: ``M r`` of a float32 brick array into the float32 brick array ``out`` (which may be
        ``r32``), returned (the QP's preconditioner; off NumPy a new array).
    shape : tuple of int
        The shape of the cell's brick arrays.
    diagonal : float
        ``C_nn`` of the operator the preconditioner inverts, with the compliance it inverts added (a uniform one, or
        the median of one per node) [length/pressure].
    symbol : bem.periodic.symbol.Symbol or tuple
        ``M``'s symbol (on NumPy a :class:`~bem.periodic.symbol.Symbol`, elsewhere its blocks ``(D, B)``), whose
        diagonal blocks' mean is ``M_nn``.
    scratch : callable, optional
        ``scratch()``: a float32 brick array that making the correction may overwrite (the QP's work array, free
        while the preconditioned gap is corrected), or None; default (or None from it) new arrays.
    """

    def __init__(self, bk, apply_m, shape, diagonal, symbol, scratch=None):
        self.bk, self.apply_m, self.shape, self.diagonal = bk, apply_m, tuple(shape), float(diagonal)
        self.scratch, self.symbol = scratch, symbol
        self.kept = KeptOnContact(bk, shape, hold=False)  # c at the nodes of the contact of the last step
        self.on, self.off = False, False  # made; not to be made in this solve (a contact mostly soft)
        self.floor = None  # FLOOR / C_nn - M_nn
        self.changed = 0  # nodes changed since the correction was made

    def _m_nn(self):
        """``M_nn`` [pressure/length]: the mean of the symbol's diagonal blocks over the whole spectrum."""
        n_cols = self.shape[1]
        if isinstance(self.symbol, Symbol):
            return self.symbol.diagonal(n_cols)
        d = self.symbol[0]
        return mirrored_sum(self.bk.xp, d, n_cols) / (d.shape[0] * n_cols)

    def _brick(self, value):
        """A float32 brick array of the cell filled with ``value`` (in the scratch array where there is one)."""
        xp = self.bk.xp
        v = None if self.scratch is None else self.scratch()
        if v is None:
            return xp.full(self.shape, value, dtype=xp.float32)
        v.fill(value)
        return v

    def _make(self, idx, soft):
        bk, xp = self.bk, self.bk.xp
        single = xp.float32
        if self.floor is None:
            self.floor = FLOOR / self.diagonal - self._m_nn()
        n = bk.count(idx) - (0 if soft is None else int(xp.count_nonzero(soft)))  # |A|
        share = n / (self.shape[0] * self.shape[1])
        v = bk.put(self._brick(-share), idx, 1.0 - share)  # 1_A - |A| / N
        if soft is not None:
            v = bk.put(v, bk.subset(idx, soft), -share)
        c = bk.take(self.apply_m(v, v), idx)  # M (1_A - f_A) = -M (1_I - f) at the contact: -1 / theta times c
        c *= -THETA
        c = xp.maximum(c, xp.asarray(self.floor, dtype=single))
        self.kept.keep(idx, c if soft is None else xp.where(soft, xp.asarray(0.0, dtype=single), c))
        self.on, self.changed = True, 0

    def _at(self, idx, contact):
        """``c`` at the contact's nodes ``idx`` (float64): the nodes of the last step's contact keep theirs, an
        entering node takes 0 (``M_AA``'s own diagonal) until the correction is made again; kept again at ``idx``,
        so that the next step's contact maps from this one."""
        c = self.kept.at(idx, contact)
        if idx is not self.kept.nodes:
            self.kept.keep(idx, c)
        return c

    def applied(self, z, r, idx, changes, contact=None, soft=None):
        """``z + c r`` at the contact's nodes ``idx`` where the correction is on; the uncorrected ``z`` before it
        starts and where ``r.(z + c r)`` is not positive.

        Parameters
        ----------
        z, r : array
            ``M_AA r`` and the gap ``r`` at the contact's nodes (1-D, float64).
        idx : node selection
            The contact's nodes.
        changes : list of int
            The nodes that entered or left the contact at each step of the solve so far (the first entry counts
            from no earlier contact).
        contact : bem.periodic.qp_parts.ContactNodes, optional
            The QP's contact, ``idx`` its last read (on NumPy its step maps the correction onto ``idx``).
        soft : array of bool, optional
            At the contact's nodes, those the preconditioner takes by Jacobi, not by ``M`` (a compliance per node):
            off ``A``, ``c = 0`` there. Default: none.

        Returns
        -------
        array
            The preconditioned gap (a new array where corrected; ``z`` itself otherwise).
        """
        bk = self.bk
        n = bk.count(idx)
        if not self.on:
            if self.off or len(changes) < 2 or changes[-1] > SETTLED * n:
                return z
            if soft is not None and 2 * int(bk.xp.count_nonzero(soft)) > n:  # mostly soft: none in this solve
                self.off = True
                return z
        else:
            self.changed += changes[-1]
        if not self.on or self.changed > REMAKE * n:
            self._make(idx, soft)
        corrected = self._at(idx, contact) * r
        corrected += z
        return corrected if bk.dot(r, corrected) > 0 else z
