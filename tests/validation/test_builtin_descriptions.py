"""The built-in scenes say what they run: every quantity with a unit in a scene's description
(``P = 100 N``, ``a mean pressure of 200 MPa``, ``1 mm cell``) is a value of the scene file."""

import math
import re

import pytest

from validation.scene.source import builtin_dir, read_toml

#: the units the descriptions use -> metres, pascals, newtons (SI scenes), longest first
UNITS = {"m/Pa^0.5": 1.0, "m/Pa": 1.0, "kN": 1e3, "N": 1.0, "GPa": 1e9, "MPa": 1e6, "Pa": 1.0, "mm": 1e-3,
         "um": 1e-6, "m": 1.0}
QUANTITY = re.compile(r"(?<![\w.^/])(\d+(?:\.\d+)?(?:e[+-]?\d+)?) ?(" + "|".join(map(re.escape, UNITS))
                      + r")(?![\w/^])")
SCENES = sorted(builtin_dir().glob("*.toml"))


def _numbers(value):
    """Every number in a scene's tables, lists included."""
    if isinstance(value, dict):
        for v in value.values():
            yield from _numbers(v)
    elif isinstance(value, list):
        for v in value:
            yield from _numbers(v)
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        yield float(value)


def quantities(text):
    """``[(as written, value in SI units)]`` of the quantities with a unit in ``text``."""
    return [(m.group(0), float(m.group(1)) * UNITS[m.group(2)]) for m in QUANTITY.finditer(text)]


def test_the_quantities_of_a_description_are_read_with_their_units():
    assert quantities("P = 5 kN, R = 4 mm, at 20 MPa, lam = 1e-11 m/Pa^0.5, Fig. 4 d / 5, c = a_H/20") == [
        ("5 kN", 5e3), ("4 mm", 4e-3), ("20 MPa", 2e7), ("1e-11 m/Pa^0.5", 1e-11)]


@pytest.mark.parametrize("path", SCENES, ids=[p.stem for p in SCENES])
def test_every_quantity_a_builtin_description_states_is_a_value_of_the_scene(path):
    raw = read_toml(path)
    meta = raw["scene"]
    stated = quantities(meta.get("description", "") + " " + meta.get("title", ""))
    if stated:
        assert meta["units"] == "SI (m, Pa, N)"  # the units above
    values = list(_numbers({k: v for k, v in raw.items() if k != "scene"}))
    for text, value in stated:
        assert any(math.isclose(value, v, rel_tol=1e-3) for v in values), \
            f"{path.stem}: the description says {text!r}, and no value of the scene is {value:g}"
