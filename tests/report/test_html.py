"""Report HTML helpers: Jinja2 templates, escaping, figures embedded so a page stands alone."""

from __future__ import annotations

import base64
import re

import pytest
from matplotlib.figure import Figure

from robodyn.report.html import CSS, data_uri, figure, html_table, page, render


def test_figure_is_embedded_as_a_data_uri_with_the_file_bytes(tmp_path):
    fig = Figure()
    fig.subplots().plot([0, 1], [1, 0])
    path = tmp_path / "line.png"
    fig.savefig(path)
    tag = figure(path, 'a "quoted" <alt>')
    src = re.fullmatch(r'<img src="([^"]+)" alt="([^"]*)">', tag)
    assert src is not None, tag
    assert src.group(1).startswith("data:image/png;base64,")
    assert base64.b64decode(src.group(1).split(",", 1)[1]) == path.read_bytes()
    assert src.group(2) == "a &#34;quoted&#34; &lt;alt&gt;"
    assert data_uri(tmp_path / "line.png") == src.group(1)


def test_unknown_figure_type_names_the_file(tmp_path):
    path = tmp_path / "table.csv"
    path.write_text("a,b\n")
    with pytest.raises(ValueError, match=r"table\.csv: cannot embed a \.csv file as an image"):
        figure(path, "table")


def test_table_escapes_text_and_marks_verdicts_and_numbers():
    out = html_table(["name", "<h>"], [["<script>", 1.5], ["ok", "NO"]])
    assert "<script>" not in out and "&lt;script&gt;" in out and "<th>&lt;h&gt;</th>" in out
    assert '<td class="num">1.5</td>' in out
    assert '<td class="ok">ok</td>' in out and '<td class="bad">NO</td>' in out


def test_page_escapes_the_title_and_keeps_the_trusted_body():
    out = page("a < b", "<p>body</p>")
    assert out.startswith("<!DOCTYPE html>") and "<title>a &lt; b</title>" in out
    assert "<p>body</p>" in out and CSS.strip().splitlines()[0] in out
    assert "<script" not in out and "http" not in out


def test_templates_refuse_undefined_values():
    import jinja2

    with pytest.raises(jinja2.UndefinedError):
        render("page.html.j2", title="t")  # no body
