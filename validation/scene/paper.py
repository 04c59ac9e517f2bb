"""The paper's parameterisation of the interface layers of its test problems (section 6).

The test problem is the contact of two paraboloids with a layer between them (Fig. 4 a);
the layer laws are those of Fig. 4 b-d, given relative to quantities of the discrete problem:

- compliance [length/pressure]: ``lam`` (``lam1``; ``lam_ref`` for the root law), a property
  of the layer alone. Fig. 5 uses ``lam = 10 C_nn``, a multiple of the diagonal influence
  coefficient (eq. 6) ``C_nn = c / (pi E*) * w_t(0, 0)``, ``w_t(0, 0) = (3 sqrt3 / 2) ln 3``
  (:func:`bem.template`), which is proportional to the lattice step ``c``. The paper's value
  may be given as ``lam_over_cnn`` together with ``cnn_step``, the reference step ``c`` at
  which ``C_nn`` is taken: ``lam = lam_over_cnn * C_nn(cnn_step)``. Either way the layer is
  the same on every lattice, so refining the lattice converges to one solution.
- ``p_max^lambda``: the peak pressure of the same problem (gap, bodies, load, lattice) with
  the linear layer ``w = lam p``, solved first.
- elastic-rigid (Fig. 4 b): ``w = lam min(p, p_cr)``, ``alpha_a = p_cr / p_max^lambda``
  in ``[0, 1]``; ``alpha_a = 0`` is the contact of smooth bodies (no layer), ``alpha_a = 1``
  the linear layer.
- bilinear (Fig. 4 d): ``lam1 = lam``, ``alpha_c = arctan(lam2 / lam1)`` in ``[0, pi/2)``
  (``lam2 = lam1 tan(alpha_c)``; ``alpha_c = 0`` is elastic-rigid), kink at
  ``p_star = alpha_a p_max^lambda``.
- root (Fig. 4 c): ``w = lam_r sqrt(p)``. Choice made here (the paper does not state it):
  ``lam_r = lam sqrt(p_max^lambda)``, i.e. the root law closes exactly as much as the linear
  layer at ``p = p_max^lambda`` (more below it, less above). The paper's
  ``alpha_b = p_max^root / p_max^lambda`` is reported as an output. Given ``alpha_b``
  instead, ``lam_r`` is found (root of ``p_max^root(lam_r) = alpha_b p_max^lambda``,
  a few extra solves) so that a family of root laws can be swept by ``alpha_b``.

This module parses and checks those parameters; the solves that calibrate a law are the run's
(:mod:`validation.run.calibrate`).
"""

from __future__ import annotations

import math

from bem.layers import LAWS, Bilinear, ElasticRigid, Linear, Root
from bem.operator import diagonal_coefficient

from .checks import SceneError, in_range, positive, string, table, unknown_keys

__all__ = ["c_nn", "check_layer", "paper_law", "is_paper_law", "needs_calibration", "paper_keys",
           "reference_compliance", "PAPER_LAWS", "PAPER_KEYS", "EXCLUSIVE", "ALIASES"]


#: law -> {constructor parameter: (direct key, paper key)}
PAPER_LAWS = {
    "linear": {"lam": ("lam", "lam_over_cnn")},
    "elastic_rigid": {"lam": ("lam", "lam_over_cnn"), "p_cr": ("p_cr", "alpha_a")},
    "bilinear": {"lam1": ("lam1", "lam_over_cnn"), "lam2": ("lam2", "alpha_c"), "p_star": ("p_star", "alpha_a")},
    "root": {"lam": ("lam_ref", "lam_over_cnn")},
}
PAPER_KEYS = ("lam_over_cnn", "lam_ref", "alpha_a", "alpha_c", "alpha_b")
#: groups of layer keys that replace each other (a ``--set`` of one drops the others)
EXCLUSIVE = (("lam", "lam_over_cnn"), ("lam1", "lam_over_cnn"), ("p_cr", "alpha_a"), ("p_star", "alpha_a"),
             ("lam2", "alpha_c"))
#: sweep parameter short names
ALIASES = {"alpha_a": "layer.alpha_a", "alpha_b": "layer.alpha_b", "alpha_c": "layer.alpha_c"}


c_nn = diagonal_coefficient  # ``C_nn = c / (pi E*) w_t(0, 0)``, defined once in bem.operator


def is_paper_law(spec):
    """Whether a validated ``[layer]`` spec is given by the paper's parameters (resolved by solves)."""
    return spec is not None and spec["law"] in PAPER_LAWS and any(k in spec for k in PAPER_KEYS)


def needs_calibration(spec):
    """Whether a validated ``[layer]`` spec needs solves before its law is known: ``alpha_a`` (a
    threshold relative to ``p_max^lambda``) or the root law (``lam_r`` from ``p_max^lambda``, or from
    ``alpha_b``); :func:`validation.run.calibrate.resolve_layer` runs them."""
    return is_paper_law(spec) and ("alpha_a" in spec or spec["law"] == "root")


def paper_keys(law):
    """The keys of a paper law's table besides ``law``: each parameter's direct and paper key."""
    return ([k for pair in PAPER_LAWS[law].values() for k in pair] + ["cnn_step"]
            + (["alpha_b"] if law == "root" else []))


def reference_compliance(spec, E_star):
    """Compliance of the linear reference layer [length/pressure]: ``lam`` (``lam1``, ``lam_ref``) or
    ``lam_over_cnn C_nn(cnn_step)``, the same on every lattice."""
    direct = PAPER_LAWS[spec["law"]][next(iter(PAPER_LAWS[spec["law"]]))][0]  # lam, lam1 or lam_ref
    return spec[direct] if direct in spec else spec["lam_over_cnn"] * c_nn(spec["cnn_step"], E_star)


def _check_paper_values(path, d):
    """Range checks of the direct and paper parameters of the four paper laws."""
    for key in ("lam", "lam1", "lam_ref", "p_cr", "p_star", "lam_over_cnn", "cnn_step", "alpha_b"):
        if key in d:
            positive(f"{path}.{key}", d[key])
    if "lam2" in d:
        in_range(f"{path}.lam2", d["lam2"], 0.0, math.inf)
    if "alpha_a" in d:
        in_range(f"{path}.alpha_a", d["alpha_a"], 0.0, 1.0)
    if "alpha_c" in d:
        in_range(f"{path}.alpha_c", d["alpha_c"], 0.0, math.pi / 2, high_open=True)
    if "lam_over_cnn" in d and "cnn_step" not in d:
        raise SceneError(f"{path}.lam_over_cnn = {d['lam_over_cnn']!r} is not allowed without {path}.cnn_step: "
                         "C_nn is proportional to the lattice step, so give the reference step [m] at which "
                         "lam = lam_over_cnn * C_nn (the layer is then the same on every lattice), or give the "
                         "compliance directly [m/Pa].")
    if "cnn_step" in d and "lam_over_cnn" not in d:
        raise SceneError(f"{path}.cnn_step = {d['cnn_step']!r} is not allowed without {path}.lam_over_cnn: "
                         "it is the reference step of lam = lam_over_cnn * C_nn(cnn_step).")


def _check_law_keys(path, d):
    """Recursive key check of a non-paper law (series holds two nested laws)."""
    table(path, d)
    law = choice_law(path, d, allow_none=False)
    cls = LAWS[law]
    keys = ("law", *cls._required, *cls._optional)
    unknown_keys(path, d, keys)
    for key in cls._required:
        if key not in d:
            raise SceneError(f"{path}.{key} is missing: a {law!r} layer needs " + ", ".join(cls._required) + ".")
    if law == "series":
        for key in ("a", "b"):
            _check_law_keys(f"{path}.{key}", d[key])


def choice_law(path, d, *, allow_none=True):
    """The ``law`` key of a layer table, checked against the known laws."""
    choices = (("none",) if allow_none else ()) + tuple(LAWS)
    known = ", ".join(map(repr, choices))
    if "law" not in d:
        raise SceneError(f"{path}.law is missing: give one of {known}.")
    law = string(f"{path}.law", d["law"])
    if law not in choices:
        raise SceneError(f"{path}.law = {law!r} is not allowed: it must be one of {known}.")
    return law


def check_layer(d, path="layer"):
    """Validate a ``[layer]`` table; returns the spec dict, or ``None`` for no layer.

    Direct parameters are those of :mod:`bem.layers` (``from_dict``, which checks their values
    when the scene builds the law, once); the four paper laws also take the paper's parameters
    (module docstring): each constructor parameter from exactly one of its direct or paper key.
    """
    if d is None:
        return None
    table(path, d)
    law = choice_law(path, d)
    if law == "none":
        for key, value in d.items():
            if key != "law":
                raise SceneError(f"{path}.{key} = {value!r} is not allowed with {path}.law = 'none': "
                                 "a scene without a layer takes no layer parameters.")
        return None
    if law not in PAPER_LAWS or not any(k in d for k in PAPER_KEYS):
        _check_law_keys(path, d)
        return dict(d)
    if "alpha_b" in d and "lam" in d:
        raise SceneError(f"{path}.alpha_b = {d['alpha_b']!r} is not allowed together with {path}.lam: "
                         "alpha_b sets the root coefficient; give the linear reference (lam_ref, or lam_over_cnn "
                         "and cnn_step) and alpha_b, or lam alone.")
    unknown_keys(path, d, ["law", *paper_keys(law)])
    for param, (direct, paper) in PAPER_LAWS[law].items():
        present = [k for k in (direct, paper) if k in d]
        if not present:
            raise SceneError(f"{path}.{direct} or {path}.{paper} is missing: a {law!r} layer needs {param}.")
        if len(present) == 2:
            raise SceneError(f"{path}.{direct} = {d[direct]!r} and {path}.{paper} = {d[paper]!r} are not "
                             f"allowed together: give one of them ({param} directly or the paper's {paper}).")
    _check_paper_values(path, d)
    return dict(d)


def paper_law(law, lam, p_lambda=None, *, alpha_a=None, alpha_c=None, p_cr=None, p_star=None, lam2=None):
    """A layer law of the paper's section 6 from its parameters.

    ``p_lambda`` is ``p_max^lambda``, the peak pressure of the same problem with the
    linear layer ``lam``. Elastic-rigid: ``p_cr = alpha_a p_lambda``; bilinear:
    ``lam2 = lam tan(alpha_c)``, ``p_star = alpha_a p_lambda``; root:
    ``lam_r = lam sqrt(p_lambda)`` (closes as the linear layer does at ``p_lambda``).
    Explicit ``p_cr``, ``p_star``, ``lam2`` win over the alphas. A zero threshold gives no
    layer (``None``: the paper's ``alpha_a = 0`` is the smooth contact), a bilinear law with
    a zero knee the linear layer ``lam2``.
    """
    if law == "linear":
        return Linear(lam)
    if law == "elastic_rigid":
        p_cr = alpha_a * p_lambda if p_cr is None else p_cr
        return ElasticRigid(lam, p_cr) if p_cr > 0 else None
    if law == "bilinear":
        lam2 = lam * math.tan(alpha_c) if lam2 is None else lam2
        p_star = alpha_a * p_lambda if p_star is None else p_star
        return Bilinear(lam, lam2, p_star) if p_star > 0 else (Linear(lam2) if lam2 > 0 else None)
    if law == "root":
        return Root(lam * math.sqrt(p_lambda))
    raise SceneError(f"layer.law = {law!r} is not allowed: it must be one of {sorted(PAPER_LAWS)}.")
