"""The README's benchmark figures are the ones in the results file it names (issue 22).

Reads only files committed in the repository (README.md, ``benchmarks/results/*.json``) and
renders them with ``benchmarks/render_readme.py``: nothing is timed.
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def readme() -> str:
    return (ROOT / "README.md").read_text()


def test_readme_section_equals_its_rendering(renderer, readme):
    sections = list(renderer.MARKER.finditer(readme))
    assert "kernels" in [m["name"] for m in sections]
    for m in sections:
        assert (ROOT / m["path"]).is_file(), f"README names {m['path']}, which is not committed"
    assert renderer.render(readme, ROOT) == readme, (
        "README's benchmark section differs from its results file: run "
        ".venv/bin/python benchmarks/render_readme.py")


def test_results_file_records_machine_load_and_every_peer(renderer, readme):
    path = ROOT / renderer.MARKER.search(readme)["path"]
    data = json.loads(path.read_text())
    assert data["machine"]["cpu_model"] and data["machine"]["logical_cpus"] >= 1
    entry = data["benchmarks"]["kernels"]
    assert len(entry["load_average_at_start"]) == len(entry["load_average_at_end"]) == 3
    libraries = {r["library"] for r in entry["rows"]}
    assert set(entry["peers"]) == libraries  # every row says what it is and differs in
    for row in entry["rows"]:
        ns = row["ns_per_state"]
        assert 0 < ns["min"] <= ns["median"] and ns["repeats"] >= 3
        if row["max_rel_error"] is not None:  # every peer agrees with robodyn's model
            assert row["max_rel_error"] <= entry["tolerance"]
    targets = [r for r in entry["ratios"] if "target" in r]
    assert {r["kernel"] for r in targets} == {"ID", "FD", "FD derivatives"}
    assert all(r["peer"] == "pinocchio native" and r["met"] == (r["min"] >= r["target"]) for r in targets)


def test_a_changed_figure_changes_the_rendering(renderer, readme):
    match = renderer.MARKER.search(readme)
    data = json.loads((ROOT / match["path"]).read_text())
    changed = copy.deepcopy(data)
    changed["benchmarks"]["kernels"]["rows"][0]["ns_per_state"]["min"] += 1000
    assert renderer.render_kernels(changed) != renderer.render_kernels(data)
    assert renderer.render_kernels(data) == match["body"]


def test_rendering_needs_a_marked_section(renderer):
    with pytest.raises(ValueError, match="no <!-- results"):
        renderer.render("# README without figures\n", ROOT)


def test_documents_quote_the_readmes_run(renderer, readme):
    # docs/identification.md's quality table is rendered from the same results file as the
    # README's section of the same benchmark: one run, quoted alike
    readme_paths = {m["name"]: m["path"] for m in renderer.MARKER.finditer(readme)}
    for path in renderer.DOCUMENTS:
        text = path.read_text()
        sections = list(renderer.MARKER.finditer(text))
        assert sections, f"{path} has no marked section"
        for m in sections:
            assert m["path"] == readme_paths[m["name"].removesuffix("_table")]
        assert renderer.render(text, ROOT) == text, (
            f"{path.name}'s figures differ from the results file: run "
            ".venv/bin/python benchmarks/render_readme.py")
