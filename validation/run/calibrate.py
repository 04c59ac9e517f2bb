"""The calibration of a layer given by the paper's parameters: the solves that fix its law.

A ``[layer]`` of the paper's parameters (:mod:`validation.scene.paper`) is relative to
``p_max^lambda``, the peak pressure of the same problem with the linear reference layer: the
runner solves that problem first (:func:`resolve_layer`), and for ``alpha_b`` the root law whose
peak is ``alpha_b p_max^lambda`` (a few more solves).
"""

from __future__ import annotations

import logging
import math

from bem.layers import Linear, Root, from_dict

from ..scene.paper import c_nn, is_paper_law, needs_calibration, paper_law, reference_compliance

__all__ = ["CalibrationError", "resolve_layer"]

log = logging.getLogger(__name__)

_ALPHA_B_XTOL = 1e-5  # relative tolerance on lam_r when targeting alpha_b


class CalibrationError(RuntimeError):
    """A solve that calibrates a layer law (``alpha_a``, ``alpha_b``, the root law's reference) failed,
    or no law reaches the asked ``alpha_b``."""


def _root_for_alpha_b(alpha_b, p_lambda, lam_r0, solve):
    """``lam_r`` with ``p_max(Root(lam_r)) = alpha_b p_lambda``: bracket in log, then Brent."""
    from scipy.optimize import brentq

    target = alpha_b * p_lambda
    cache = {}

    def f(t):
        if t not in cache:
            cache[t] = math.log(solve(Root(math.exp(t))).p_max / target)
        return cache[t]

    t0 = math.log(lam_r0)
    step = 2.0 if f(t0) > 0 else -2.0  # p_max decreases as lam_r grows
    t1 = t0
    for _ in range(12):
        t1 = t1 + step
        if (f(t1) > 0) != (f(t0) > 0):
            break
        t0 = t1
    else:
        raise CalibrationError(
            f"layer.alpha_b = {alpha_b!r} cannot be reached: no root law reaches p_max = alpha_b p_max^lambda "
            f"(p_max^lambda = {p_lambda:.6g}); the root law's peak ranges from near 0 (soft) up to the "
            "smooth contact's peak (stiff): choose alpha_b between those.")
    lo, hi = sorted((t0, t1))
    t = brentq(f, lo, hi, xtol=_ALPHA_B_XTOL)
    return math.exp(t), len(cache)


def resolve_layer(spec, *, step, E_star, solve, layer=None):
    """The layer law of a validated spec, solving the linear reference first if needed.

    Parameters
    ----------
    spec : dict or None
        Output of :func:`check_layer`.
    step : float
        BEM step ``c`` [length] of the lattice in use (for the reported ``c_nn``; the layer
        does not depend on it).
    E_star : float
        Effective modulus [pressure].
    solve : callable
        ``solve(layer) -> bem.ContactResult`` of the scene's problem with that layer.
    layer : bem.layers.Layer, optional
        The law the scene already built from a spec of direct parameters (used as it is).

    Returns
    -------
    layer : bem.layers.Layer or None
    info : dict
        ``law`` and, when the paper's parameters are used, ``c_nn`` (of the lattice in use),
        ``lam_ref`` (the linear reference compliance), ``lam_over_cnn`` (``lam_ref / c_nn``: how
        soft the layer is on the scale of one node of this lattice), ``p_max_lambda``, ``alpha_a``,
        ``alpha_c``, ``alpha_b_target``, ``reference_solves``; ``parameters`` (the resolved
        law's ``to_dict()``).

    Raises
    ------
    CalibrationError
        No root law reaches ``alpha_b`` (``solve`` raises its own errors).
    """
    if spec is None:
        return None, {"law": "none", "parameters": None}
    law = spec["law"]
    info = {"law": law}
    if not is_paper_law(spec):
        layer = from_dict(spec) if layer is None else layer
        return layer, dict(info, parameters=layer.to_dict())
    cnn = c_nn(step, E_star)
    lam_ref = reference_compliance(spec, E_star)
    info.update(c_nn=cnn, lam_over_cnn=lam_ref / cnn, lam_ref=lam_ref)
    p_lambda = None
    if needs_calibration(spec):
        p_lambda = solve(Linear(lam_ref)).p_max
        info.update(p_max_lambda=p_lambda, reference_solves=1)
        log.info("linear reference layer lam = %.6g: p_max^lambda = %.6g", lam_ref, p_lambda)
    layer = paper_law(law, lam_ref, p_lambda, alpha_a=spec.get("alpha_a"), alpha_c=spec.get("alpha_c"),
                      p_cr=spec.get("p_cr"), p_star=spec.get("p_star"), lam2=spec.get("lam2"))
    if law in ("elastic_rigid", "bilinear"):
        info["alpha_a"] = spec.get("alpha_a")
    if law == "bilinear":
        lam2 = spec["lam2"] if "lam2" in spec else lam_ref * math.tan(spec["alpha_c"])
        info["alpha_c"] = math.atan2(lam2, lam_ref)
    if law == "root" and "alpha_b" in spec:
        info["alpha_b_target"] = spec["alpha_b"]
        lam_r, n = _root_for_alpha_b(spec["alpha_b"], p_lambda, layer.lam, solve)
        info["reference_solves"] += n
        layer = Root(lam_r)
    if layer is None:
        log.info("%s layer with a zero threshold: smooth contact (no layer), as in the paper", law)
    return layer, dict(info, parameters=None if layer is None else layer.to_dict())
