"""Markdown rendering of a report; figures are relative links into ``figures/``."""

from __future__ import annotations

from .content import Figure, Table

__all__ = ["render_markdown"]

_MARK = {"ok": "OK", "warn": "WARN", "bad": "FAIL"}


def _cell(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def _table(tab, number):
    status = tab.status_column is not None
    head = list(tab.columns) + (["flag"] if status else [])
    lines = [f"**Table {number}.** {tab.caption}".rstrip(), "", "| " + " | ".join(_cell(c) for c in head) + " |",
             "|" + "|".join("---" for _ in head) + "|"]
    for row in tab.rows:
        cells = [_cell(c) for c in row]
        if status:
            cells.append(_MARK.get(tab.status(row), ""))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def render_markdown(sections, *, title, subtitle="", names, footer="", vectors=()):
    """The whole report as one Markdown string.

    Parameters
    ----------
    sections : sequence of Section
        Content in order.
    title, subtitle, footer : str
        As for :func:`validation.report.render.html.render_html`.
    names : mapping of str to str
        Relative file name (``figures/x.png``) of every figure, keyed by ``Figure.path``.
    vectors : collection of str
        Relative names of the PDF copies written beside the PNGs (``figures/x.pdf``); the
        caption links them.
    """
    out = [f"# {title}", ""]
    if subtitle:
        out += [f"*{subtitle}*", ""]
    if len(sections) > 1:
        out += [f"{i}. [{s.title}](#{s.anchor})" for i, s in enumerate(sections, 1)] + [""]
    n_fig = n_tab = 0
    for sec in sections:
        out += [f'<a id="{sec.anchor}"></a>', "", f"## {sec.title}", ""]
        for par in sec.text:
            out += [par, ""]
        for item in sec.items:
            if isinstance(item, Figure):
                n_fig += 1
                pdf = names[item.path][:-4] + ".pdf"
                link = f" (vector: [{pdf}]({pdf}))" if pdf in vectors else ""
                out += [f"![{_cell(item.alt_text)}]({names[item.path]})", "",
                        f"*Figure {n_fig}.* {item.caption}{link}", ""]
            elif isinstance(item, Table):
                n_tab += 1
                out += [_table(item, n_tab), ""]
    if footer:
        out += ["---", "", footer, ""]
    return "\n".join(out)
