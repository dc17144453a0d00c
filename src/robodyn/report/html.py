"""HTML building blocks shared by the reports: the style sheet, tables and a page frame."""

from __future__ import annotations

import html
from collections.abc import Sequence

from robodyn.report.text import is_number

__all__ = ["CSS", "html_table", "page"]

CSS = """
body { font-family: system-ui, sans-serif; max-width: 70rem; margin: 2rem auto; padding: 0 1rem;
       color: #222; line-height: 1.45; }
h1 { font-size: 1.6rem; border-bottom: 2px solid #345; padding-bottom: .3rem; }
h2 { font-size: 1.25rem; margin-top: 2rem; color: #234; }
h4 { margin: 1rem 0 .2rem; }
table { border-collapse: collapse; margin: .5rem 0; font-variant-numeric: tabular-nums; }
th, td { border: 1px solid #bbc; padding: .25rem .6rem; }
th { background: #e8edf3; }
td.num { text-align: right; }
.ok { color: #176117; font-weight: 600; }
.bad { color: #a01010; font-weight: 600; }
pre { background: #f5f6f8; padding: .6rem; overflow-x: auto; font-size: .85rem; }
math { font-size: 1.1rem; }
.meta { color: #555; font-size: .9rem; }
"""


def html_table(headers: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """An HTML table; numbers right-aligned, "ok"/"yes" green, "DISAGREE"/"NO" red."""
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in headers)
    body = []
    for row in rows:
        cells = []
        for c in row:
            text = html.escape(str(c))
            if text in ("ok", "yes"):
                cells.append(f'<td class="ok">{text}</td>')
            elif text in ("DISAGREE", "NO"):
                cells.append(f'<td class="bad">{text}</td>')
            else:
                cells.append(f'<td class="num">{text}</td>' if is_number(c)
                             else f"<td>{text}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def page(title: str, body: str) -> str:
    """A complete HTML document with the shared style sheet around ``body``."""
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">\n'
            f"<title>{html.escape(title)}</title>\n<style>{CSS}</style></head>\n<body>\n"
            f"{body}\n</body></html>\n")
