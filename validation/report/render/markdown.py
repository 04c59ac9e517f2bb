"""Markdown rendering of a report; figures are relative links into ``figures/``.

Every text of the content (titles, paragraphs, captions, cells) is plain text, as in the HTML
(:mod:`.html`): :func:`md_escape` writes it so that Markdown shows it as it is, never as markup.
"""

from __future__ import annotations

import re

from .content import Figure, Table
from .style import vector_name

__all__ = ["render_markdown", "md_escape"]

_MARK = {"ok": "OK", "warn": "WARN", "bad": "FAIL"}

#: characters that are Markdown markup anywhere in a line (``_`` inside a word is not)
_INLINE = re.compile(r"([\\`*\[\]~|]|(?<![A-Za-z0-9])_|_(?![A-Za-z0-9]))")
#: what makes the start of a line a block (heading, quote, list, rule, numbered item, table)
_BLOCK = re.compile(r"^(\s*)([#>+=:-])")
_NUMBERED = re.compile(r"^(\s*\d+)([.)])")
_HTML = {"<": "&lt;", ">": "&gt;"}


def md_escape(text, *, block=True):
    """``text`` as Markdown that shows it literally, on one line.

    Newlines and runs of white space collapse to one space; ``<``, ``>`` and an ``&`` that would
    start an entity become HTML entities (no raw HTML such as ``<script>`` or ``<iframe>``, no
    autolink); the inline markup characters (``\\ ` * [ ] ~ |``, a ``_`` at a word's edge) are
    escaped with a backslash, so no link (``[x](javascript:...)``), image, emphasis or code span
    forms; with ``block`` (text that starts a line, not a table cell) a leading heading, quote,
    list or numbered-item mark is escaped too.
    """
    text = " ".join(str(text).split())
    text = re.sub(r"&(?=#?[A-Za-z0-9]+;)", "&amp;", text)
    text = _INLINE.sub(r"\\\1", text)
    text = re.sub(r"[<>]", lambda m: _HTML[m.group()], text)
    if not block:
        return text
    if _NUMBERED.match(text):
        return _NUMBERED.sub(r"\1\\\2", text)
    return _BLOCK.sub(lambda m: m.group(1) + "\\" + m.group(2), text)


def _cell(text):
    return md_escape(text, block=False)


def _table(tab, number):
    status = tab.status_column is not None
    head = list(tab.columns) + (["flag"] if status else [])
    lines = [f"**Table {number}.** {md_escape(tab.caption)}".rstrip(), "",
             "| " + " | ".join(_cell(c) for c in head) + " |", "|" + "|".join("---" for _ in head) + "|"]
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
    out = [f"# {md_escape(title)}", ""]
    if subtitle:
        out += [f"*{md_escape(subtitle)}*", ""]
    if len(sections) > 1:
        out += [f"{i}. [{md_escape(s.title)}](#{s.anchor})" for i, s in enumerate(sections, 1)] + [""]
    n_fig = n_tab = 0
    for sec in sections:
        out += [f'<a id="{sec.anchor}"></a>', "", f"## {md_escape(sec.title)}", ""]
        for par in sec.text:
            out += [md_escape(par), ""]
        for item in sec.items:
            if isinstance(item, Figure):
                n_fig += 1
                pdf = vector_name(names[item.path])
                link = f" (vector: [{pdf}]({pdf}))" if pdf in vectors else ""
                out += [f"![{_cell(item.alt_text)}]({names[item.path]})", "",
                        f"*Figure {n_fig}.* {md_escape(item.caption)}{link}", ""]
            elif isinstance(item, Table):
                n_tab += 1
                out += [_table(item, n_tab), ""]
    if footer:
        out += ["---", "", md_escape(footer), ""]
    return "\n".join(out)
