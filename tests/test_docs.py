"""The documentation: self-contained, and tested against the code so that it cannot drift.

- ``docs/scenes.md`` has a row for every key of the scene schema in code
  (:func:`validation.scene.schema.scene_keys`) and no other, with the defaults of the code;
- ``docs/results.md`` has a row for every field of real ``result.json`` files;
- ``docs/method.md`` names only code that exists;
- the README's quick start runs, its links resolve inside the repository, and nothing a user
  reads points outside it.
"""

import fnmatch
import importlib
import inspect
import json
import math
import re
import subprocess
from pathlib import Path

import pytest
import yaml

import bem
import fem_reference
from validation.scene import schema as ss
from validation.run import run_scene
from validation.scene import SECTIONS
from validation.scene import sizing
from bem.checks import BYTES_PER_NODE
from validation.run.sweep import SUMMARY_COLUMNS

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
_ROW = re.compile(r"^\|\s*`([^`]+)`\s*\|")


def _table_rows(text):
    """``{key: [cells]}`` of the table rows whose first cell is a code span."""
    rows = {}
    for line in text.splitlines():
        m = _ROW.match(line)
        if m:
            rows[m.group(1)] = [c.strip() for c in line.strip().strip("|").split("|")]
    return rows


def _scene_doc():
    """``{section: {variant: {key: cells}}}`` from the headings and tables of docs/scenes.md."""
    doc, section, variant = {}, None, ""
    for block in re.split(r"(?m)^(?=#{2,3} )", (DOCS / "scenes.md").read_text()):
        heading = block.splitlines()[0]
        if m := re.match(r"^## \[(\w+)\]", heading):
            section, variant = m.group(1), ""
        elif m := re.match(r'^### (?:type|law) = "(\w+)"', heading):
            variant = m.group(1)
        elif heading.startswith("#"):
            section = None
        if section is not None:
            doc.setdefault(section, {}).setdefault(variant, {}).update(_table_rows(block))
    return doc


def test_scenes_doc_documents_every_section_and_key():
    schema, doc = ss.scene_keys(), _scene_doc()
    for section in SECTIONS:
        assert section in schema, f"section [{section}] has no entry in validation.scene_sections.scene_keys()"
    for section, variants in schema.items():
        assert section in doc, f"docs/scenes.md has no '## [{section}]' section"
        for variant, keys in variants.items():
            where = f"[{section}]" + (f" {variant!r}" if variant else "")
            assert variant in doc[section], f"docs/scenes.md has no table for {where}"
            for key in keys:
                assert key in doc[section][variant], f"docs/scenes.md: {where} key {key!r} is not documented"
            extra = set(doc[section][variant]) - set(keys)
            assert not extra, f"docs/scenes.md: {where} documents keys the schema does not have: {extra}"
            for key, cells in doc[section][variant].items():
                assert len(cells) == 5 and all(cells), f"{where} {key}: key | type | unit | default | meaning"


def _default(cells):
    text = cells[3].strip("`")
    if text == "none":  # an optional key (the code's None)
        return None
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return text


def test_scenes_doc_defaults_are_the_code_defaults():
    doc = _scene_doc()
    checked = 0
    for kind, cls in ss.GAP_TYPES.items():
        for name, p in inspect.signature(cls.__init__).parameters.items():
            if p.default not in (inspect.Parameter.empty, None):
                assert _default(doc["gap"][kind][name]) == p.default, (kind, name)
                checked += 1
    fem = inspect.signature(fem_reference.solve).parameters
    for key in ss.KEYS["fem"]:
        assert _default(doc["fem"][""][key]) == fem[key].default, key
        checked += 1
    solve = inspect.signature(bem.solve).parameters
    for key in ("method", "rtol", "precondition"):
        assert _default(doc["bem"][""][key]) == solve[key].default, key
    assert _default(doc["bem"][""]["nodes_across"]) == sizing.DEFAULT_NODES_ACROSS
    assert _default(doc["bem"][""]["extent_factor"]) == sizing.DEFAULT_EXTENT_FACTOR
    assert _default(doc["scene"][""]["units"]) == ss.DEFAULT_UNITS
    scenes = " ".join((DOCS / "scenes.md").read_text().split())
    assert "`bem.checks.max_nodes`" in scenes
    assert (f"{BYTES_PER_NODE['candidate region']} bytes a node on a half-space region, "
            f"{BYTES_PER_NODE['periodic cell']} on a periodic cell or a surface grid") in scenes
    assert checked > 10
    sections = doc["report"][""]["sections"][4]
    assert all(f"`{name}`" in sections for name in ss.report_sections())
    assert all(f'"{kind}"' in doc["analytic"][""]["kind"][4] for kind in ss.ANALYTIC_KINDS)


def _paths(obj, prefix="", *, leaves):
    """Dotted paths of the fields of a JSON object: the leaves (arrays are leaves), or every field."""
    out = set()
    for key, value in obj.items():
        path = f"{prefix}{key}"
        if not (leaves and isinstance(value, dict) and value):
            out.add(path)
        if isinstance(value, dict):
            out |= _paths(value, path + ".", leaves=leaves)
    return out


@pytest.fixture(scope="module")
def real_results(tmp_path_factory):
    """result.json of runs that together write every kind of field."""
    tmp = tmp_path_factory.mktemp("results")
    runs = [("hertz", ["bem.nodes_across=16", "fem.n_contact_elements=8"]),           # FEM, Hertz, report, files
            ("paper_bilinear", ["bem.nodes_across=16", "fem.n_contact_elements=8"]),  # paper layer: alpha_a, alpha_c
            ("paper_root", ["bem.nodes_across=16", "layer.alpha_b=0.9"]),    # alpha_b target and result
            ("elliptic", ["bem.nodes_across=16"]),                          # hertz_elliptic, not axisymmetric
            ("rough_flat", ["gap.grid=32", "bem.cell_nodes=32"]),           # a periodic cell
            ("rough_flat", ["gap.grid=32", "bem.cell_nodes=32", "bodies.E1=210e9", "bodies.nu1=0.3",  # coated
                            "bodies.E2=210e9", "bodies.nu2=0.3", "bodies.coating1.thickness=1e-5",
                            "bodies.coating1.E=2e10", "bodies.coating1.nu=0.3"])]
    from validation.scene.load import read_toml
    from validation.scene.source import builtin_path

    coated = read_toml(builtin_path("hertz"))  # a coated body's [stress]: stress.bodies.*.coated
    for section in ("analytic", "fem", "report"):
        coated.pop(section)
    coated["bodies"]["coating1"] = {"thickness": 4e-5, "E": 4.5e11, "nu": 0.25}
    runs.append((coated, ["bem.nodes_across=8", "stress.n_depths=4"]))
    out = []
    for i, (scene, overrides) in enumerate(runs):
        name = scene if isinstance(scene, str) else "coated_stress"
        run_scene(scene, tmp / f"{i}_{name}", overrides=overrides)
        out.append(json.loads((tmp / f"{i}_{name}" / "result.json").read_text()))
    return out


def test_results_doc_documents_every_field_of_real_results(real_results):
    rows = _table_rows((DOCS / "results.md").read_text())
    for path in sorted(set().union(*(_paths(r, leaves=True) for r in real_results))):
        assert any(fnmatch.fnmatchcase(path, key) for key in rows), (
            f"docs/results.md has no row for the result.json field {path!r}")
    for key, cells in rows.items():
        if key not in _FILE_TABLE:
            assert len(cells) == 4 and all(cells), f"{key}: field | type | unit | meaning"
    written = set().union(*(_paths(r, leaves=False) for r in real_results))
    stale = {k for k in rows if "*" not in k and k not in _FILE_TABLE} - written
    assert not stale, f"docs/results.md documents fields no run writes: {sorted(stale)}"


_FILE_TABLE = ("result.json", "scene.toml", "bem_field.vtu", "fem_field.vtu", "stress_field.vtu", ".contactlab")


def test_results_doc_units_of_the_main_fields():
    rows = _table_rows((DOCS / "results.md").read_text())
    units = {"p_max": "Pa", "force": "N", "approach": "m", "contact_area": "m^2", "contact_radius": "m",
             "wall_time_s_by_part.bem": "s", "fem.p_max": "Pa", "layer.c_nn": "m/Pa", "layer.alpha_c": "rad"}
    for key, unit in units.items():
        assert rows[key][2] == unit, key
    text = (DOCS / "results.md").read_text()
    listed = re.search(r"Summary columns: (.*?)\.\n", text, re.S).group(1)
    assert re.findall(r"`(\w+)`", listed) == list(SUMMARY_COLUMNS)


def test_method_doc_names_existing_code():
    text = (DOCS / "method.md").read_text()
    assert "Numerical methods for contact analysis of complex-shaped bodies with account for non-linear " \
           "interface layers" in " ".join(text.split())
    names = set(re.findall(r"`((?:bem|fem_reference|validation)(?:\.\w+)+)`", text))
    assert len(names) > 15
    for name in sorted(names):
        parts = name.split(".")
        for i in range(len(parts), 0, -1):
            try:
                obj = importlib.import_module(".".join(parts[:i]))
            except ModuleNotFoundError:
                continue
            for attr in parts[i:]:
                assert hasattr(obj, attr), f"docs/method.md names {name}, which does not exist"
                obj = getattr(obj, attr)
            break
    assert math.isclose(1.5 * math.sqrt(3) * math.log(3), float(bem.template(0.0, 0.0)), rel_tol=1e-12)


def test_readme_quick_start_runs(capsys):
    text = (ROOT / "README.md").read_text()
    code = re.search(r"## Quick start\n\n```python\n(.*?)```", text, re.S).group(1)
    assert "m/Pa^0.5" in code and "[Pa]" in code and "[N]" in code and "[m]" in code
    exec(compile(code, "README.md (quick start)", "exec"), {})
    out = capsys.readouterr().out
    assert "converged True" in out
    p_max = float(re.search(r"p_max (\S+) Pa", out).group(1))
    assert 1.0e9 < p_max < 1.37e9  # below Hertz's 1.371 GPa: the layer softens the contact


def _tracked_text_files():
    files = subprocess.run(["git", "-C", str(ROOT), "ls-files"], capture_output=True, text=True, check=True)
    for name in files.stdout.splitlines():
        path = ROOT / name
        if path.suffix in (".png",) or not path.is_file():
            continue
        yield name, path.read_text(encoding="utf-8", errors="replace")


def test_nothing_points_outside_the_repository():
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    outside = ("../" + "shared", "DESIGN" + ".md", "seed/" + "paper.md")  # spelt so that this file passes
    for name, text in _tracked_text_files():
        for word in outside:
            assert word not in text, f"{name} mentions {word!r}: it points outside the repository"


def test_readme_links_resolve_inside_the_repository():
    text = (ROOT / "README.md").read_text()
    targets = re.findall(r"\]\(([^)#\s]+)", text)
    assert {"docs/method.md", "docs/scenes.md", "docs/results.md", "docs/install.md", "docs/verification.md",
            "docs/performance.md", "LICENSE", "CITATION.cff"} <= set(targets)
    for target in targets:
        assert not target.startswith(("/", "..")), target
        assert (ROOT / target).exists(), f"README links to {target}, which is not in the repository"
    for page in ("method.md", "scenes.md", "results.md", "rough.md", "install.md", "verification.md",
                 "performance.md"):
        for target in re.findall(r"\]\(([^)#\s]+)", (DOCS / page).read_text()):
            assert (DOCS / target).exists(), f"docs/{page} links to {target}"


def test_license_and_citation():
    assert (ROOT / "LICENSE").read_text().startswith("BSD 3-Clause License\n\nCopyright (c) 2026, the contactlab "
                                                      "developers")
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert cff["cff-version"] == "1.2.0"
    assert {"cff-version", "message", "title", "authors"} <= set(cff)
    assert cff["version"] == project["version"]
    assert cff["license"] == project["license"] == "BSD-3-Clause"
    assert project["license-files"] == ["LICENSE"]
    assert all("name" in a or "family-names" in a for a in cff["authors"])
