"""HTML5 rendering of a report.

Figures are relative links to the files of ``figures/`` that the Markdown shows too, so a report
stores each figure once; the style sheet is inline and nothing refers outside the report's
folder (no external link, script or font), so the folder opens offline.
"""

from __future__ import annotations

import html
from urllib.parse import quote

from .content import Figure, Table
from .style import vector_name

__all__ = ["render_html", "CSS"]

CSS = """
:root { --ink: #1d2330; --muted: #5b6475; --line: #d9dee7; --accent: #1f5fae; }
* { box-sizing: border-box; }
body { margin: 0; font: 15px/1.55 system-ui, -apple-system, "Segoe UI", Roboto, "Helvetica Neue", Arial, sans-serif;
       color: var(--ink); background: #f6f7f9; }
main { max-width: 980px; margin: 0 auto; padding: 28px 28px 60px; background: #fff; min-height: 100vh;
       box-shadow: 0 0 0 1px var(--line); }
h1 { font-size: 1.7em; margin: 0.2em 0 0.1em; }
h2 { font-size: 1.3em; margin: 1.8em 0 0.5em; padding-bottom: 0.2em; border-bottom: 2px solid var(--line); }
p.subtitle { color: var(--muted); margin-top: 0; }
nav ol { columns: 2; padding-left: 1.2em; margin: 0.4em 0 1em; }
nav a, nav a:visited { color: var(--accent); text-decoration: none; }
figure { margin: 1.2em 0; text-align: center; }
figure img { max-width: 100%; height: auto; border: 1px solid var(--line); border-radius: 4px; }
figcaption { text-align: left; color: var(--muted); font-size: 0.92em; margin-top: 0.4em; }
figcaption b, caption b { color: var(--ink); }
div.table-wrap { overflow-x: auto; margin: 1em 0; }
table { border-collapse: collapse; font-size: 0.92em; width: 100%; }
caption { caption-side: top; text-align: left; color: var(--muted); padding-bottom: 0.3em; }
th, td { border: 1px solid var(--line); padding: 4px 8px; text-align: left; vertical-align: top; }
th { background: #eef1f6; }
tr.ok td { background: #e7f5e9; }
tr.warn td { background: #fff4d6; }
tr.bad td { background: #fde4e4; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
footer { margin-top: 3em; color: var(--muted); font-size: 0.85em; border-top: 1px solid var(--line);
         padding-top: 0.6em; }
"""


def _is_number(text):
    try:
        float(text)
    except ValueError:
        return False
    return True


def _href(name):
    return html.escape(quote(name))


def _figure(fig, number, name, vector):
    link = f' (vector: <a href="{_href(vector)}">{html.escape(vector)}</a>)' if vector else ""
    return (f'<figure>\n<img src="{_href(name)}" alt="{html.escape(fig.alt_text)}">\n'
            f"<figcaption><b>Figure {number}.</b> {html.escape(fig.caption)}{link}</figcaption>\n</figure>")


def _table(tab, number):
    cap = f"<b>Table {number}.</b> {html.escape(tab.caption)}" if tab.caption else f"<b>Table {number}.</b>"
    out = ['<div class="table-wrap"><table>', f"<caption>{cap}</caption>",
           "<thead><tr>" + "".join(f"<th>{html.escape(c)}</th>" for c in tab.columns) + "</tr></thead>", "<tbody>"]
    for row in tab.rows:
        cls = tab.status(row)
        attr = f' class="{cls}"' if cls != "other" else ""
        cells = "".join(f'<td class="num">{html.escape(c)}</td>' if _is_number(c) else f"<td>{html.escape(c)}</td>"
                        for c in row)
        out.append(f"<tr{attr}>{cells}</tr>")
    out.append("</tbody></table></div>")
    return "\n".join(out)


def render_html(sections, *, title, subtitle="", names, footer="", vectors=()):
    """The whole report as one HTML5 string.

    Parameters
    ----------
    sections : sequence of Section
        Content in order.
    title : str
        Document title and heading.
    subtitle : str
        Line under the heading.
    names : mapping of str to str
        Relative file name (``figures/x.png``) of every figure, keyed by ``Figure.path``.
    footer : str
        Text of the footer (e.g. how the report was generated).
    vectors : collection of str
        Relative names of the PDF copies written beside the PNGs (``figures/x.pdf``,
        :func:`validation.report.render.style.vector_name`); the caption links them.
    """
    body = [f"<h1>{html.escape(title)}</h1>"]
    if subtitle:
        body.append(f'<p class="subtitle">{html.escape(subtitle)}</p>')
    if len(sections) > 1:
        links = "".join(f'<li><a href="#{s.anchor}">{html.escape(s.title)}</a></li>' for s in sections)
        body.append(f'<nav aria-label="contents"><ol>{links}</ol></nav>')
    n_fig = n_tab = 0
    for sec in sections:
        body.append(f'<section id="{sec.anchor}" class="kind-{sec.kind}">')
        body.append(f"<h2>{html.escape(sec.title)}</h2>")
        body.extend(f"<p>{html.escape(par)}</p>" for par in sec.text)
        for item in sec.items:
            if isinstance(item, Figure):
                n_fig += 1
                pdf = vector_name(names[item.path])
                body.append(_figure(item, n_fig, names[item.path], pdf if pdf in vectors else None))
            elif isinstance(item, Table):
                n_tab += 1
                body.append(_table(item, n_tab))
        body.append("</section>")
    if footer:
        body.append(f"<footer>{html.escape(footer)}</footer>")
    return ("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
            f"<title>{html.escape(title)}</title>\n<style>{CSS}</style>\n</head>\n<body>\n<main>\n"
            + "\n".join(body) + "\n</main>\n</body>\n</html>\n")
