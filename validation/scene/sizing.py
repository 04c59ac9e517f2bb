"""The ``[bem]`` section of a scene: the solver options, and the lattice sized from the expected contact.

A scene may give the lattice directly (``bem.step``, ``bem.extent``) or relative to the
expected contact: ``bem.nodes_across`` nodes across its smaller diameter and
``bem.extent_factor`` times its semi-axes. The expected semi-axes are the gap's own estimate,
:meth:`bem.gaps.Gap.expected_semi_axes` (closed forms of :mod:`bem.reference`; tables,
callables and measured surfaces have none, and such a scene gives ``bem.step`` and
``bem.extent``). A layer given by the paper's parameters is sized by its linear reference
layer. An estimate only sizes the region: an automatic region grows when the contact reaches its
border (:class:`bem.HalfSpaceRegion`, ``grow=True``, up to :func:`bem.region.region_limit`).

The solver options are checked by the BEM itself (:func:`bem.options.check_options`: one rule,
one message), and the option names come from :data:`bem.options.OPTIONS`.
"""

from __future__ import annotations

from functools import partial

from bem import METHODS, InputError
from bem.checks import check_node_count
from bem.lattice import Lattice, node_count
from bem.layers import Linear
from bem.options import OPTIONS, check_options, solver_for
from bem.region import EXTENT_FACTOR, inner_domain, region_limit

from . import checks as ck
from .paper import is_paper_law, reference_compliance

__all__ = ["bem_options", "solver_keywords", "KEYS", "SOLVER_KEYS", "OWN_KEYS", "EXCLUSIVE", "DEFAULT_NODES_ACROSS",
           "DEFAULT_EXTENT_FACTOR"]

DEFAULT_NODES_ACROSS = 40
DEFAULT_EXTENT_FACTOR = EXTENT_FACTOR
#: the options every solver of bem.solve takes, and their checks
_COMMON = {"rtol": ck.rtol, "maxiter": partial(ck.integer, minimum=1), "precondition": ck.boolean,
           "nested": ck.boolean}
#: the options of one solver or another (bem.options.OPTIONS)
OWN_KEYS = tuple(sorted({k for keys in OPTIONS.values() for k in keys}))
#: solver options a scene may set: the method, the common options and each solver's own
SOLVER_KEYS = ("method", *_COMMON, *OWN_KEYS)
KEYS = ("step", "nodes_across", "extent", "extent_factor") + SOLVER_KEYS
#: pairs of lattice keys of which a scene gives one (a ``--set`` of one drops the other)
EXCLUSIVE = (("step", "nodes_across"), ("extent", "extent_factor"))


def _axes(gap, layer, E_star, load):
    try:
        return gap.expected_semi_axes(E_star=E_star, force=load["force"], approach=load["approach"], layer=layer)
    except InputError as exc:
        raise ck.SceneError(f"bem.nodes_across cannot be used: the contact size could not be estimated ({exc}); "
                            "give bem.step and bem.extent.") from None


def _expected(gap, layer_spec, layer, E_star, load):
    """Expected semi-axes; a layer of the paper's parameters is represented by its linear reference."""
    if layer_spec is None:
        return _axes(gap, None, E_star, load)
    if is_paper_law(layer_spec):
        return _axes(gap, Linear(reference_compliance(layer_spec, E_star)), E_star, load)
    return _axes(gap, layer, E_star, load)


def solver_options(d, layer_spec):
    """``[bem]``'s method and the options of every solver, those of the one that will run checked
    by the BEM itself (shared by lattice and periodic scenes)."""
    out = {"method": ck.choice("bem.method", d.get("method", "newton"), METHODS)}
    out.update(ck.options("bem", d, _COMMON))
    out.update(_own_options(d, out["method"], layer_spec))
    return out


def solver_keywords(options):
    """The keywords of :func:`bem.solve` (or :func:`bem.solve_periodic`) among a scene's checked ``bem``
    options (:func:`bem_options`): the method and the solver options the scene gives (:data:`SOLVER_KEYS`)."""
    return {k: options[k] for k in SOLVER_KEYS if k in options}


def _own_options(d, method, layer_spec):
    """The options of the solver that will run, checked by the BEM itself."""
    kind = None if layer_spec is None else ("linear" if layer_spec["law"] == "linear" else "nonlinear")
    if method == "kalker" and kind == "nonlinear":
        raise ck.SceneError(f"bem.method = 'kalker' is not allowed with layer.law = {layer_spec['law']!r}: "
                            "Kalker's QP solves smooth bodies and linear layers; use 'newton'.")
    own = {k: d[k] for k in OWN_KEYS if k in d}
    try:
        return check_options(method, solver_for(method, kind), own)
    except InputError as exc:
        raise ck.SceneError(f"bem.{exc}") from None


def _extent(d, gap, axes):
    """``(ex, ey)`` [length] and whether the region is automatic (may be enlarged)."""
    hx, hy = inner_domain(gap)
    if "extent" not in d:
        fx, fy = ck.number_or_pair("bem.extent_factor", d.get("extent_factor", DEFAULT_EXTENT_FACTOR),
                                   lambda p, v: ck.in_range(p, v, 1.0, 100.0))
        lx, ly = region_limit(gap)
        return (min(fx * axes[0], lx), min(fy * axes[1], ly)), True
    ex, ey = ck.number_or_pair("bem.extent", d["extent"], ck.scale)
    if hasattr(gap, "check_region"):  # measured data: their own rule (bem.gaps.Measured.check_region)
        with ck.scene_errors():
            gap.check_region(d["extent"], name="bem.extent")
    elif ex >= hx or ey >= hy:
        raise ck.SceneError(f"bem.extent = {d['extent']!r} is not allowed: the candidate region must lie "
                            f"inside the gap's domain, |x| < {hx:.6g}, |y| < {hy:.6g}.")
    if axes is not None and (ex < axes[0] or ey < axes[1]):
        raise ck.SceneError(
            f"bem.extent = {d['extent']!r} is not allowed for this load: the expected contact semi-axes "
            f"are ({axes[0]:.4g}, {axes[1]:.4g}), beyond the region; make extent larger (or use "
            "extent_factor) or reduce the load.")
    return (ex, ey), False


def bem_options(d, gap, layer_spec, layer, E_star, load):
    """``[bem]``: lattice (``step`` | ``nodes_across``, ``extent`` | ``extent_factor``) and solver options.

    Parameters
    ----------
    d : dict or None
        The raw ``[bem]`` table.
    gap : bem.gaps.Gap
        The scene's gap.
    layer_spec : dict or None
        The validated ``[layer]``; ``layer`` the law built from it (``None`` for a law of the
        paper's parameters, which is resolved by a solve at run time).
    E_star : float
        Effective modulus [pressure].
    load : dict
        ``{"force": ..., "approach": ...}``.

    Returns
    -------
    dict
        The checked solver options with the resolved ``step`` [length], ``extent`` ``(ex, ey)``
        [length], ``expected`` semi-axes (or None), ``extent_auto`` (the region may be
        enlarged), ``nodes_across`` and ``n_nodes``.
    """
    d = {} if d is None else ck.table("bem", d)
    ck.unknown_keys("bem", d, KEYS)
    for a, b in EXCLUSIVE:
        if a in d and b in d:
            raise ck.SceneError(f"bem.{a} = {d[a]!r} and bem.{b} = {d[b]!r} are not allowed together: "
                                "give one of them.")
    out = solver_options(d, layer_spec)
    step = ck.scale("bem.step", d["step"]) if "step" in d else None
    n_across = ck.integer("bem.nodes_across", d.get("nodes_across", DEFAULT_NODES_ACROSS), 4, 2000)
    axes = _expected(gap, layer_spec, layer, E_star, load)
    if axes is None and ("step" not in d or "extent" not in d):
        raise ck.SceneError(f"bem.step and bem.extent are missing: a {gap.type_name!r} gap has no estimate "
                            "of the contact size, so give the lattice step [m] and the region half-width [m].")
    if step is None:
        step = 2 * min(axes) / n_across
    elif axes is not None and 2 * min(axes) / step < 4:
        raise ck.SceneError(f"bem.step = {step!r} is not allowed for this load: the expected contact is only "
                            f"{2 * min(axes):.4g} across ({2 * min(axes) / step:.1f} steps); make step smaller "
                            "(at least 4 nodes across the contact).")
    extent, auto = _extent(d, gap, axes)
    n = node_count(step, extent)
    key = "step" if "step" in d else "nodes_across"
    with ck.scene_errors("bem."):
        check_node_count(f"bem.{key}", d.get(key, n_across), n)  # bem's memory guard, before building
        Lattice.from_extent(step, extent)
    out.update(step=step, extent=extent, extent_auto=auto, expected=axes,
               nodes_across=2 * min(axes) / step if axes else None, n_nodes=n)
    return out
