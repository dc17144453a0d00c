"""HTML building blocks shared by the reports, rendered from the Jinja2 templates in ``templates/``.

A report is a page template around *sections*: each section is an HTML fragment (a ``str``)
returned by a section-builder function, so that a new analysis adds a section by returning one.
Fragments are plain ``str`` of trusted HTML (wrap them in :class:`markupsafe.Markup` to pass
them to a template); every value put into them from outside (names, paths, messages) is
escaped, by the templates' autoescaping or by :func:`html.escape` where a fragment is built in
Python. Figures are embedded as ``data:`` URIs (:func:`figure`), so a written page is really
self-contained: one file, nothing fetched, no scripts.
"""

from __future__ import annotations

import base64
from collections.abc import Sequence
from functools import cache
from pathlib import Path

from robodyn.robot.errors import InputError
from robodyn.robot.optional import require
from robodyn.text import is_number

# the ``report`` extra: every report module takes Jinja2 and Markup from here
jinja2 = require("jinja2", "an HTML report")
Markup = require("markupsafe", "an HTML report").Markup

__all__ = ["CSS", "Markup", "data_uri", "figure", "html_table", "page", "render", "render_macro"]

#: Media types of the figure files a report embeds, by suffix.
_MEDIA_TYPES = {".png": "image/png", ".gif": "image/gif", ".svg": "image/svg+xml",
                ".jpg": "image/jpeg", ".jpeg": "image/jpeg", ".webp": "image/webp"}


@cache
def _environment() -> jinja2.Environment:
    """The template environment: package templates, autoescaping, undefined names are errors."""
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("robodyn.report", "templates"),
        autoescape=jinja2.select_autoescape(enabled_extensions=("html", "j2"), default=True),
        undefined=jinja2.StrictUndefined,
        keep_trailing_newline=True,
    )
    env.filters["g_list"] = _general_list
    return env


def _general_list(values: Sequence[float], digits: int | None = None) -> str:
    """Template filter ``g_list``: numbers (a list or an array) in ``%g`` format (``digits``
    significant digits), joined by ", "."""
    spec = "g" if digits is None else f".{digits}g"
    return ", ".join(format(float(v), spec) for v in values)


def render(template: str, **context: object) -> str:
    """Render the package template ``template`` (e.g. ``"page.html.j2"``) with ``context``.

    Strings in ``context`` are escaped; wrap trusted HTML fragments in :class:`markupsafe.Markup`.
    """
    return _environment().get_template(template).render(**context)


def render_macro(template: str, name: str, **arguments: object) -> str:
    """Call the macro ``name`` of the package template ``template`` with ``arguments`` (escaped
    as in :func:`render`) and return its HTML."""
    return str(getattr(_environment().get_template(template).module, name)(**arguments))


#: The shared style sheet (``templates/style.css``).
CSS = _environment().loader.get_source(_environment(), "style.css")[0]


def _cell_class(value: object) -> str:
    """CSS class of a table cell: "ok"/"yes" green, "DISAGREE"/"NO" red, numbers right-aligned."""
    text = str(value)
    if text in ("ok", "yes"):
        return "ok"
    if text in ("DISAGREE", "NO"):
        return "bad"
    return "num" if is_number(value) else ""


def html_table(headers: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """An HTML table fragment (escaped text); numbers right-aligned, "ok"/"yes" green,
    "DISAGREE"/"NO" red."""
    cells = [[(str(c), _cell_class(c)) for c in row] for row in rows]
    return render("table.html.j2", headers=[str(h) for h in headers], rows=cells).strip()


def data_uri(path: str | Path) -> str:
    """The file at ``path`` as a base64 ``data:`` URI (media type from the suffix).

    Raises
    ------
    ValueError
        For a suffix that is not a known image type (the message names the file).
    """
    path = Path(path)
    media = _MEDIA_TYPES.get(path.suffix.lower())
    if media is None:
        raise InputError(f"{path}: cannot embed a {path.suffix or 'suffix-less'} file as an image "
                         f"(known: {', '.join(sorted(_MEDIA_TYPES))})")
    return f"data:{media};base64,{base64.b64encode(path.read_bytes()).decode('ascii')}"


def figure(path: str | Path, alt: str) -> str:
    """``<img>`` fragment of the image file ``path`` embedded in the page (the file stays on disk)."""
    return render("figure.html.j2", uri=data_uri(path), alt=alt).strip()


def page(title: str, body: str) -> str:
    """A complete HTML document with the shared style sheet around the trusted fragment ``body``."""
    return render("page.html.j2", title=title, body=Markup(body))
