"""Comparison metrics: BEM nodal pressures against the FEM profile ``p(r)`` and closed forms.

Three kinds of pressure source are compared:

- a BEM result (:class:`bem.ContactResult`): nodal pressures on the triangular lattice, all
  nodes carrying the same quadrature weight ``sqrt(3)/2 c^2`` (eq. 9);
- an FEM reference result (:class:`fem_reference.FemResult`): the axisymmetric profile
  ``p(r)`` at the interface nodes, linear between them;
- a closed form of :mod:`bem.reference` (:class:`~bem.reference.HertzSphere`,
  :class:`~bem.reference.RigidLayerParaboloid`, the non-axisymmetric
  :class:`~bem.reference.HertzElliptic`).

All three share the names ``pressure(x, y)``, ``p_max``, ``approach`` and ``force``, so each is
compared the same way. Their radii are two estimators with two names: the BEM's and the closed
forms' ``contact_radius`` (``sqrt(A / pi)``, the radius of the circle of the contact area; a
closed form's exact radius) and the FEM's ``edge_radius`` (the edge of the loaded zone,
interpolated between its nodes). A pair with the FEM on either side compares them as
``edge_radius_rel``, any other pair as ``contact_radius_rel``.

Relative L2 error of a candidate ``a`` against a reference ``b`` at the candidate's nodes
``n`` with quadrature weights ``A_n``::

    l2_rel = sqrt(sum A_n (p_a,n - p_b(x_n))^2 / sum A_n p_b(x_n)^2)

The sums run over the union of the two contact zones (``p_a > 0`` or ``p_b > 0``); outside
it both pressures vanish, so the union changes nothing but the point count. For the BEM
the weights are equal and the formula is ``||p_a - p_b||_2 / ||p_b||_2`` over the nodes;
for the FEM they are the ring areas of :func:`ring_weights`.
"""

from __future__ import annotations

import math

import numpy as np

from bem.checks import InputError, check_finite_array, check_positive
from bem.result import ContactResult
from fem_reference.result import FemResult

__all__ = ["axial_section", "ring_weights", "relative_l2", "pair_metrics", "compare",
           "PAIR_KEYS", "RADIUS_KEYS"]

#: keys every pair of :func:`pair_metrics` / :func:`compare` holds, besides one of :data:`RADIUS_KEYS`
PAIR_KEYS = ("l2_rel", "max_rel", "peak_rel", "approach_rel", "force_rel", "n_points")
#: the radius comparison of a pair: ``contact_radius_rel`` (``sqrt(A / pi)`` or a closed form's
#: radius on both sides) or ``edge_radius_rel`` (the FEM's interpolated edge on one side)
RADIUS_KEYS = ("contact_radius_rel", "edge_radius_rel")


def axial_section(x, y, values, *, tol=None):
    """``(xs, vs)``: the nodes ``(x, y)`` [length] on the line ``y = 0`` (``|y| <= tol``, default
    ``1e-9 max|x|``), sorted by ``x``, and their ``values`` (any unit)."""
    x, y, values = (np.asarray(v, dtype=float) for v in (x, y, values))
    if not (x.shape == y.shape == values.shape):
        raise InputError(f"x, y, values have shapes {x.shape}, {y.shape}, {values.shape} which is not allowed: "
                         "they must be equal.")
    tol = 1e-9 * float(np.abs(x).max(initial=1.0)) if tol is None else tol
    on = np.abs(y) <= tol
    if not on.any():
        raise InputError("x, y have no node on the axial section y = 0: the section needs nodes with |y| <= tol.")
    order = np.argsort(x[on], kind="stable")
    return x[on][order], values[on][order]


def ring_weights(r):
    """Ring areas ``A_i = 2 pi integral phi_i(r) r dr`` of the linear hats on the nodes ``r`` [length^2].

    ``r`` increasing, ``r >= 0``. The weights integrate any function linear between
    the nodes exactly: ``sum A_i f(r_i) = 2 pi integral_{r_0}^{r_last} f r dr``.
    """
    r = check_finite_array("r", r, ndim=1, min_size=2)
    dr = np.diff(r)
    if np.any(dr <= 0) or r[0] < 0:
        raise InputError("r is not allowed: it must be increasing and >= 0.")
    to_right = dr * (r[:-1] + 2.0 * r[1:]) / 6.0  # integral of the right node's hat on [r_i, r_i+1]
    to_left = dr * (2.0 * r[:-1] + r[1:]) / 6.0  # ... and of the left node's
    w = np.zeros_like(r)
    w[1:] += to_right
    w[:-1] += to_left
    return 2.0 * math.pi * w


def relative_l2(p, p_ref, weights=None):
    """``sqrt(sum w (p - p_ref)^2 / sum w p_ref^2)`` (equal weights by default).

    Returns ``None`` when the reference is identically 0 (the ratio is undefined).
    """
    p = np.asarray(p, dtype=float)
    p_ref = np.asarray(p_ref, dtype=float)
    w = np.ones_like(p) if weights is None else np.asarray(weights, dtype=float)
    den = float(np.sum(w * p_ref**2))
    return math.sqrt(float(np.sum(w * (p - p_ref) ** 2)) / den) if den > 0 else None


def _check_source(name, obj):
    """Every result and closed form shares the names read here (``bem.reference``)."""
    radius = "edge_radius" if isinstance(obj, FemResult) else "contact_radius"
    if not all(hasattr(obj, k) for k in ("pressure", "p_max", radius, "approach", "force")):
        raise InputError(
            f"{name} = {type(obj).__name__} is not allowed: it must be a bem.ContactResult, a "
            "fem_reference.FemResult or a bem.reference closed form (pressure, p_max, contact_radius, "
            "approach, force).")
    return obj


def _radius(obj):
    """The radius a source gives: the FEM's ``edge_radius``, any other's ``contact_radius`` [length]."""
    return obj.edge_radius if isinstance(obj, FemResult) else obj.contact_radius


def _nodes(obj):
    """Evaluation points ``(x, y, p, weights)`` of a BEM or FEM result."""
    if isinstance(obj, ContactResult):
        return obj.x, obj.y, obj.p, None
    return obj.r, np.zeros_like(obj.r), obj.p, ring_weights(obj.r)


def _rel(a, b):
    """Signed ``(a - b) / b``; ``None`` where undefined."""
    return float((a - b) / b) if b != 0 and math.isfinite(a) and math.isfinite(b) else None


def pair_metrics(candidate, reference):
    """Metrics of ``candidate`` (BEM or FEM result) against ``reference`` (any source).

    Pressures are compared at the candidate's nodes, the reference evaluated there (an FEM
    profile interpolated linearly in ``r``; a BEM field by its piecewise-linear pyramids).

    Returns
    -------
    dict
        ``l2_rel`` (module docstring; at the BEM nodes equal weights, at the FEM nodes ring
        areas), ``max_rel`` = ``max |p_a - p_b| / max p_b``, and the signed relative
        differences ``(a - b) / b`` of the peak pressure ``peak_rel``, the radius
        (``edge_radius_rel`` when either side is an FEM result: its interpolated edge against the
        other's radius; else ``contact_radius_rel``; module docstring), approach
        ``approach_rel`` and total force ``force_rel``; ``n_points``: nodes in the union
        of the contact zones. ``None`` marks an undefined value (reference 0).
    """
    a, b = _check_source("candidate", candidate), _check_source("reference", reference)
    if not isinstance(candidate, (ContactResult, FemResult)):
        raise InputError(f"candidate = {type(candidate).__name__} is not allowed: it must be a BEM or FEM result.")
    if isinstance(candidate, FemResult) and not getattr(b, "is_axisymmetric", True):
        raise InputError("reference = non-axisymmetric is not allowed with an FEM candidate: the FEM is axisymmetric.")
    x, y, p, w = _nodes(candidate)
    p_ref = np.asarray(b.pressure(x, y), dtype=float)
    union = (p > 0) | (p_ref > 0)
    diff = np.abs(p - p_ref)
    scale = float(p_ref.max(initial=0.0))
    radius_key = RADIUS_KEYS[isinstance(a, FemResult) or isinstance(b, FemResult)]
    return {
        "l2_rel": relative_l2(p[union], p_ref[union], None if w is None else w[union]),
        "max_rel": float(diff.max(initial=0.0)) / scale if scale > 0 else None,
        "peak_rel": _rel(a.p_max, b.p_max),
        radius_key: _rel(_radius(a), _radius(b)),
        "approach_rel": _rel(a.approach, b.approach),
        "force_rel": _rel(a.force, b.force),
        "n_points": int(union.sum()),
    }


def compare(bem_result, *, fem=None, analytic=None, force=None):
    """All available comparisons of a BEM result with an FEM reference and a closed form.

    Parameters
    ----------
    bem_result : bem.ContactResult
        The BEM solution.
    fem : fem_reference.FemResult, optional
        Axisymmetric FEM reference of the same scene.
    analytic : HertzSphere, RigidLayerParaboloid or HertzElliptic, optional
        Closed form of the same scene (a non-axisymmetric one is compared at the BEM nodes
        in ``x, y`` and not with the FEM).
    force : float, optional
        Target force [force] for the force balance; default the closed form's force.

    Returns
    -------
    dict
        JSON-ready; present only for what was given:

        - ``"bem_vs_fem"``: :func:`pair_metrics` at the BEM nodes, FEM ``p(r)`` interpolated;
        - ``"bem_vs_analytic"``: at the BEM nodes;
        - ``"fem_vs_analytic"``: at the FEM nodes with ring-area weights
          (only for an axisymmetric closed form);
        - ``"force_balance"``: ``{"target": P, "bem": |F - P| / P, "fem": ...}``.

        Each pair holds :data:`PAIR_KEYS` and one of :data:`RADIUS_KEYS` (:func:`pair_metrics`).
    """
    if not isinstance(bem_result, ContactResult):
        raise InputError(f"result = {type(bem_result).__name__} is not allowed: it must be a bem.ContactResult.")
    if fem is not None and not isinstance(fem, FemResult):
        raise InputError(f"fem = {type(fem).__name__} is not allowed: it must be a fem_reference.FemResult or None.")
    if analytic is not None:
        _check_source("analytic", analytic)
    out = {}
    if fem is not None:
        out["bem_vs_fem"] = pair_metrics(bem_result, fem)
    if analytic is not None:
        out["bem_vs_analytic"] = pair_metrics(bem_result, analytic)
        if fem is not None and analytic.is_axisymmetric:
            out["fem_vs_analytic"] = pair_metrics(fem, analytic)
    target = force if force is not None else (None if analytic is None else analytic.force)
    if target is not None:
        target = check_positive("force", target)
        balance = {"target": target, "bem": abs(bem_result.force - target) / target}
        if fem is not None:
            balance["fem"] = abs(fem.force - target) / target
        out["force_balance"] = balance
    return out
