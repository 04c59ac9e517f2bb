"""One name, one meaning: the names table of docs/results.md ("## Names") against the code.

Every public field of ``bem.ContactResult`` and ``fem_reference.FemResult`` has a row; each row
says where the name lives (a dataclass field, a property, a ``history`` entry, a solver
argument, a scene key, a result.json field), and a name is absent wherever the row says ``-``,
so that one name cannot hold two quantities (the FEM's interpolated edge is not
``contact_radius``, its initial gap not ``gap``).
"""

import dataclasses
import fnmatch
import inspect
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

import bem
import fem_reference
from bem.gaps import Paraboloid
from validation.labels import fmt
from validation.run import run_scene
from validation.scene import load_scene
from validation.scene.schema import KEYS

DOC = Path(__file__).resolve().parents[1] / "docs" / "results.md"
COLUMNS = ["name", "meaning", "unit", "bem", "fem_reference", "result.json", "scene key", "CLI"]
#: what a bem / fem_reference cell may say
PLACES = {"field", "property", "history", "argument", "-"}


def _names_table():
    """``{name: {column: cell}}`` of the table under ``## Names``."""
    text = DOC.read_text(encoding="utf-8")
    section = text[text.index("\n## Names\n"):]
    section = section[:section.find("\n## ", 1)] if "\n## " in section[1:] else section
    lines = [line for line in section.splitlines() if line.startswith("|")]
    header = [c.strip() for c in lines[0].strip("|").split("|")]
    assert header == COLUMNS
    table = {}
    for line in lines[2:]:
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        assert len(cells) == len(COLUMNS), line
        row = dict(zip(COLUMNS, cells))
        assert row["name"] not in table, f"{row['name']} has two rows"
        assert row["bem"] in PLACES and row["fem_reference"] in PLACES, row
        table[row["name"]] = row
    return table


def _result_json_fields():
    """The first cells of the result.json table (``## result.json``)."""
    text = DOC.read_text(encoding="utf-8")
    part = text[text.index("\n## result.json\n"):text.index("\n## Other files\n")]
    return re.findall(r"^\| `([^`]+)` \|", part, re.M)


TABLE = _names_table()


@pytest.fixture(scope="module")
def solved():
    """A tiny BEM solve and a tiny FEM solve of the same Hertz problem, and the BEM's stresses."""
    res = bem.solve(Paraboloid(1.0), E_star=1.0, force=1.0, step=0.1, extent=1.3)
    fem = fem_reference.solve(Paraboloid(1.0), E1=2 * (1 - 0.09), nu1=0.3, E2=2 * (1 - 0.09), nu2=0.3, force=1.0,
                              n_contact_elements=4, domain_factor=20.0)
    assert res.converged and fem.converged, (res.message, fem.message)
    stress = bem.subsurface_stress(res, np.array([0.0, 0.5]), nu=0.3)
    return {"bem": res, "fem_reference": fem, "stress": stress}


CLASSES = {"bem": bem.ContactResult, "fem_reference": fem_reference.FemResult}
SOLVERS = {"bem": bem.solve, "fem_reference": fem_reference.solve}


@pytest.mark.parametrize("package", CLASSES)
def test_every_field_of_the_results_has_a_row_saying_field(package):
    fields = {f.name for f in dataclasses.fields(CLASSES[package])}
    missing = sorted(fields - set(TABLE))
    assert not missing, f"{CLASSES[package].__name__} fields without a row in docs/results.md: {missing}"
    wrong = sorted(name for name in fields if TABLE[name][package] != "field")
    assert not wrong, f"rows that do not say 'field' under {package}: {wrong}"


@pytest.mark.parametrize("package", CLASSES)
def test_each_row_holds_where_it_says_and_is_absent_where_it_says_dash(package, solved):
    cls, result = CLASSES[package], solved[package]
    fields = {f.name for f in dataclasses.fields(cls)}
    parameters = inspect.signature(SOLVERS[package]).parameters
    for name, row in TABLE.items():
        place = row[package]
        if place == "field":
            assert name in fields, f"{cls.__name__}.{name} is not a field"
        elif place == "property":
            assert isinstance(inspect.getattr_static(cls, name, None), property), f"{cls.__name__}.{name}"
            getattr(result, name)
        elif place == "history":
            assert name in result.history and len(result.history[name]) >= 1, f"{package} history {name}"
            assert not hasattr(result, name), f"{cls.__name__}.{name} beside the history entry"
        elif place == "argument":
            assert name in parameters, f"{SOLVERS[package].__module__}.solve has no argument {name}"
        if place in ("-", "argument"):
            assert not hasattr(result, name), f"{cls.__name__}.{name} exists: its row says {place!r}"


def test_the_fem_result_names_its_own_quantities_apart_from_the_bem(solved):
    """The FEM's initial gap, overlap and interpolated edge are not the BEM's gap, closure and
    sqrt(A / pi): they have their own names, with the values they stand for."""
    res, fem = solved["bem"], solved["fem_reference"]
    for name in ("gap", "closure", "contact_radius", "displacement", "n_contact"):
        assert not hasattr(fem, name), name
    np.testing.assert_allclose(fem.initial_gap, fem.r**2 / 2, rtol=1e-12)  # h(r) of the paraboloid R = 1
    inside = (fem.p > 0) & (fem.r > 0)
    assert np.all(fem.overlap[inside] > 0) and np.all(fem.overlap[~inside & (fem.r > 0)] <= 0)
    assert fem.r[inside].max() <= fem.edge_radius <= fem.r[np.flatnonzero(inside).max() + 1]
    assert res.contact_radius == pytest.approx(math.sqrt(res.contact_area / math.pi), rel=1e-12)
    np.testing.assert_allclose(res.gap, res.displacement + res.closure + Paraboloid(1.0)(res.x, res.y) - res.approach,
                               atol=1e-12)


def test_wall_time_s_is_one_number_of_seconds_everywhere(solved):
    """No field or property named wall_time_s holds a dict: each is the float time of its object."""
    objects = [solved["bem"], solved["fem_reference"], solved["stress"]]
    for obj in objects:
        value = obj.wall_time_s
        assert isinstance(value, float) and 0.0 <= value < math.inf, (type(obj).__name__, value)
    fem = solved["fem_reference"]
    assert fem.wall_time_s == fem.timings["total"] and fem.wall_time_s >= fem.timings["solve"]


def test_scene_keys_of_the_table_exist_and_no_section_holds_a_name_the_table_does_not_give_it():
    for name, row in TABLE.items():
        listed = set(re.findall(r"\[(\w+)\] (\w+)", row["scene key"]))
        for section, key in listed:
            assert key == name and key in KEYS[section], f"[{section}] {key} is not a scene key"
        for section in ("bem", "fem"):
            if name in KEYS[section]:
                assert (section, name) in listed, f"[{section}] {name} is a scene key its row does not list"


def test_cli_overrides_of_the_table_load():
    """Each ``--set`` the table shows is accepted by a scene that has the section."""
    for name, row in TABLE.items():
        for key, value in re.findall(r"--set (\w+\.\w+)=(\S+?)`", row["CLI"]):
            assert key.split(".")[1] == name
            scene = load_scene("hertz", overrides=[f"{key}={value}"])
            section, option = key.split(".")
            assert scene.raw[section][option] == pytest.approx(float(value)), key


def test_result_json_fields_of_the_table_are_documented_fields():
    documented = _result_json_fields()
    for name, row in TABLE.items():
        for field in re.findall(r"`([^`]+)`", row["result.json"]):
            assert any(field == key or fnmatch.fnmatchcase(key, field) for key in documented), (name, field)
            assert name in field.split("."), (name, field)


def test_result_json_of_an_fem_run_uses_the_fem_names(tmp_path):
    run_scene("hertz", tmp_path / "r", overrides=["bem.nodes_across=12", "fem.n_contact_elements=6",
                                                  "fem.domain_factor=20"])
    result = json.loads((tmp_path / "r" / "result.json").read_text(encoding="utf-8"))
    fem = result["fem"]
    assert "edge_radius" in fem and "contact_radius" not in fem
    assert fem["mesh"]["n_contact_elements"] == 6 and fem["mesh"]["domain_factor"] == pytest.approx(20.0)
    assert "n_contact" not in fem["mesh"] and "extent_factor" not in fem["mesh"]
    pair = result["comparison"]["bem_vs_fem"]
    assert pair["edge_radius_rel"] == pytest.approx(result["contact_radius"] / fem["edge_radius"] - 1, rel=1e-9)
    assert pair["contact_radius_rel"] is None
    assert result["comparison"]["bem_vs_analytic"]["contact_radius_rel"] is not None


def test_one_cell_formatter_for_studies_reports_and_the_command_line():
    """Significant digits as an int, any format spec as a str; None, booleans, non-finite floats."""
    assert fmt(0.000123456) == "0.0001235" and fmt(1.23456e-3, 3) == "0.00123"
    assert fmt(1.23456e-3, ".2e") == "1.23e-03" and fmt(2.5, ".3f") == "2.500"
    assert fmt(None, ".2e") == "-" and fmt(True, 3) == "yes" and fmt(7, ".2e") == "7"
    assert fmt(math.inf, ".2e") == "inf" and fmt(math.nan, 4) == "nan"
