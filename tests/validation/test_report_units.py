"""One unit per quantity within a run's report: every table (unit columns and headers), every
caption and every figure axis of a report shows pressures in one unit and lengths (layer closures
included) in one unit, the one the report's ``units`` choose; the problem statement states them once."""

import re

import matplotlib.figure
import pytest

from validation.report import SECTIONS
from validation.report.documents.results import load_results
from validation.report.documents.sections import run_sections
from validation.report.render import build_report
from validation.run import run_scene

SCENES = {"hertz": ["bem.nodes_across=16", "fem.n_contact_elements=6"],  # FEM, closed form, subsurface stresses
          "paper_elastic_rigid": ["bem.nodes_across=16", "fem.n_contact_elements=6"]}  # a layer: its closure w(p)
#: the units each choice of a report gives an SI scene: (pressure, length)
EXPECTED = {"auto": ({"MPa"}, {"mm"}), "scene": ({"Pa"}, {"m"}), "dimensionless": ({"p_H"}, {"a_H"})}
_KIND = {"pressure": re.compile(r"^(?:[kMG]?Pa|p_H|p_0|p_\{?max\}?)$"),
         "length": re.compile(r"^(?:[nuµcmk]?m|a_H|a_c)$")}
_NUMBER_UNIT = re.compile(r"(?<![\w.])\d[\d.e+-]* ([kMG]?Pa|[nuµcm]?m)\b(?!/)")


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("units")
    for name, small in SCENES.items():
        run_scene(name, root / name, overrides=small)
    return root


def _cells(line):
    return [c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]


def _unit_tokens(unit):
    """``"mm/MPa^0.5"`` -> ``["mm", "MPa"]``; ``"mm^2"`` -> ``["mm"]``."""
    return [re.sub(r"\^.*$", "", part) for part in unit.split("/") if part and part != "-"]


def _label_tokens(label):
    """Units in an axis label: ``$x$ [mm]`` -> mm; ``$p\\,/\\,p_H$`` -> p_H."""
    return re.findall(r"\[([^\]]+)\]", label) + re.findall(r"\\,/\\,([A-Za-z]+(?:_\{?\w+\}?)?)\$", label)


def _markdown_tokens(md, description, with_text):
    """Units of the tables (unit columns, headers) and, ``with_text``, of the numbers in the text."""
    tokens, lines = [], md.splitlines()
    for i, line in enumerate(lines):
        if line.startswith("|") and i + 1 < len(lines) and lines[i + 1].startswith("|---"):
            header = _cells(line)
            for cell in header:
                tokens += re.findall(r"\[([^\]]+)\]", cell) + re.findall(r" / (\S+)$", cell)
            if header[-1] == "unit":
                for row in lines[i + 2:]:
                    if not row.startswith("|"):
                        break
                    tokens += _unit_tokens(_cells(row)[-1])
        elif with_text and not line.startswith(("|", "!", "#", "<")) and line.strip() != description:
            tokens += _NUMBER_UNIT.findall(line)
    return tokens


def _by_kind(tokens):
    return {kind: {t for t in tokens if rx.match(t)} for kind, rx in _KIND.items()}


@pytest.mark.parametrize("units", list(EXPECTED))
@pytest.mark.parametrize("name", list(SCENES))
def test_one_unit_per_quantity_in_every_table_caption_and_axis(runs, tmp_path, monkeypatch, name, units):
    labels, save = [], matplotlib.figure.Figure.savefig

    def spy(fig, *args, **kwargs):
        for ax in fig.axes:
            labels.extend([ax.get_xlabel(), ax.get_ylabel(), getattr(ax, "get_zlabel", str)()])
        return save(fig, *args, **kwargs)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", spy)
    res = load_results(runs / name, units=units)
    sections = run_sections(res, tmp_path / "figures", SECTIONS)
    built = build_report(sections, tmp_path / "report", title=res.title)
    md = built.markdown.read_text(encoding="utf-8")
    description = str(res.section("scene").get("description", ""))
    pressure, length = EXPECTED[units]
    figures = _by_kind([t for label in labels for t in _label_tokens(label)])
    tables = _by_kind(_markdown_tokens(md, description, with_text=units != "dimensionless"))
    assert figures["pressure"] == pressure and figures["length"] == length, figures
    assert tables["pressure"] == pressure and tables["length"] == length, tables
    if name == "paper_elastic_rigid":  # the layer law's closure axis is a length like every other
        closure = [label for label in labels if "closure" in label]
        assert len(closure) == 1 and set(_label_tokens(closure[0])) == length
    # the problem statement states the units once, and no other section does
    stated = [t for s in sections for t in s.text if t.startswith("Units")]
    assert len(stated) == 1 and stated[0] in sections[0].text
    assert all(u in stated[0] for u in pressure | length)


@pytest.mark.parametrize(("length_unit", "spacing_mm"), [("um", 0.002), (1e-6, 0.002), ("mm", 2.0)])
def test_a_measured_gaps_spacing_is_shown_in_the_reports_length_unit(runs, tmp_path, length_unit, spacing_mm):
    """A measured file's spacing, given in the file's length unit (a symbol or the factor to the
    scene's unit), is shown in the report's length unit like every other length."""
    from dataclasses import replace

    from validation.report.documents.problem import scene_section

    scene = {"gap": {"type": "measured", "file": "surface.csv", "spacing": 2.0, "length_unit": length_unit}}
    res = replace(load_results(runs / "hertz"), scene=scene)
    rows = {r[0]: r[1:] for r in scene_section(res, tmp_path).items[0].rows}
    assert rows["gap spacing"][1] == "mm" and float(rows["gap spacing"][0]) == pytest.approx(spacing_mm, rel=1e-12)
