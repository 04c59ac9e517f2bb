"""Coatings in a scene: ``[bodies] coating1``, ``coating2`` (a :class:`bem.Coating` each) and what they exclude."""

from __future__ import annotations

from . import checks as ck

__all__ = ["COATING_KEYS", "COATING_FIELDS", "coating", "coated_sections"]

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


def coated_sections(coatings, raw):
    """A coated scene (``coatings`` of :func:`validation.scene.schema.bodies`) has no ``[stress]`` and no
    ``[analytic]``: both are those of homogeneous bodies."""
    if coatings is None:
        return
    coated = next(k for k, v in coatings.items() if v is not None)
    for section, what in (("stress", "the subsurface stresses of homogeneous half-spaces"),
                          ("analytic", "closed forms of homogeneous bodies")):
        if section in raw:
            raise ck.SceneError(f"{section} = {{...}} is not allowed with bodies.{coated}: [{section}] gives {what}; "
                                f"remove [{section}] or the coating.")
