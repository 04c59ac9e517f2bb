"""Coatings in a scene: ``[bodies] coating1``, ``coating2`` (a :class:`bem.Coating` each) and what they exclude
or bound (``[analytic]``; ``[stress] depths`` below a rigid substrate)."""

from __future__ import annotations

import math

from . import checks as ck

__all__ = ["COATING_KEYS", "COATING_FIELDS", "coating", "coated_sections", "coated_stress_depths",
           "coated_stress_bodies"]

#: the coating of each body, a table ``{thickness, E, nu}`` (:class:`bem.Coating`)
COATING_KEYS = ("coating1", "coating2")
COATING_FIELDS = ("thickness", "E", "nu")


def coating(path, d):
    """A coating table ``{thickness [length], E [pressure], nu [-]}``, checked as :class:`bem.Coating` does."""
    from bem import Coating

    ck.table(path, d)
    ck.unknown_keys(path, d, COATING_FIELDS)
    for key in COATING_FIELDS:
        ck.require(path, d, key, "give thickness [m], E [Pa] and nu [-] of the coating")
    with ck.scene_errors(f"{path}."):
        Coating(d["thickness"], d["E"], d["nu"])
    return {key: float(d[key]) for key in COATING_FIELDS}


def coated_sections(coatings, raw, stress=None, materials=None):
    """A coated scene (``coatings`` of :func:`validation.scene.schema.bodies`) has no ``[analytic]``: its
    closed forms are those of homogeneous bodies; its ``stress`` (:func:`validation.scene.schema.stress_options`)
    is checked by :func:`coated_stress_depths` (``materials``: the bodies' ``E1, nu1, E2, nu2``) and returned."""
    if coatings is None:
        return stress
    coated = next(k for k, v in coatings.items() if v is not None)
    if "analytic" in raw:
        raise ck.SceneError(f"analytic = {{...}} is not allowed with bodies.{coated}: [analytic] gives closed forms "
                            "of homogeneous bodies; remove [analytic] or the coating.")
    return coated_stress_depths(stress, materials, coatings)


def coated_stress_bodies(stress, materials, coatings):
    """``{body name: (thickness [length], rigid substrate)}`` of the coated bodies among ``stress["bodies"]``
    (``materials``: the bodies' ``E1, nu1, E2, nu2``; a rigid substrate has ``E = inf``)."""
    if stress is None or coatings is None:
        return {}
    out = {}
    for name in stress["bodies"]:
        k = name.removeprefix("body")
        c = coatings[f"coating{k}"]
        if c is not None:
            out[name] = (c["thickness"], math.isinf(materials[f"E{k}"]))
    return out


def coated_stress_depths(stress, materials, coatings):
    """``[stress] depths`` (a list) of a coated body on a rigid substrate (``bodies.E1`` or ``E2 = inf``) lie
    in its coating (at most its thickness): a rigid substrate has no stresses. Returns ``stress``."""
    if stress is None or stress["depths"] == "auto":
        return stress
    for name, (thickness, rigid) in coated_stress_bodies(stress, materials, coatings).items():
        if not rigid:
            continue
        k = name.removeprefix("body")
        for i, depth in enumerate(stress["depths"]):
            if depth > thickness:
                raise ck.SceneError(
                    f"stress.depths[{i}] = {depth!r} is not allowed with bodies.E{k} = inf and bodies.coating{k}: "
                    f"the rigid substrate has no stresses, so {name}'s depths must be at most the coating thickness "
                    f"bodies.coating{k}.thickness = {thickness!r}; list depths within it or leave {name} out "
                    "of stress.bodies.")
    return stress
