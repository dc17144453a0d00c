"""The ``identification_quality`` README section says what its figures say (issue 20, issue 22).

Reads the results file that README's marked section names and its rendering: the rows have every
model and the peers' descriptions, the speed ratio follows from the stored times, and each of
issue 20's targets is printed met / not met as the figures decide. Nothing here times or runs a
benchmark. The checks are plain functions (``check_*``) so that a scratch results file can be
checked the same way.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

from tests.readme_results import section_data as _data

ROOT = Path(__file__).resolve().parent.parent
NAME = "identification_quality"
#: Rows of a full run (``--quick`` runs three of them).
FULL_ROWS = 15  # 5 KUKA (the 70/30 rows since 2026-12-07), 4 Kinova (the torque-sensor run
# since 2026-12-07), 6 virtual
FIGURES = ("raw", "filtered")


def check_rows(entry: dict[str, Any]) -> None:
    """Every row scores the nominal model, the textbook and the default, each model described."""
    assert entry["rows"]
    for row in entry["rows"]:
        models = row["models"]
        assert {"nominal", "textbook", "robodyn default"} <= models.keys(), row["data_set"]
        assert set(models) <= set(entry["peers"]), set(models) - set(entry["peers"])
        for label, m in models.items():
            if "failed" not in m:
                assert all(m[f] >= 0 for f in FIGURES), (row["data_set"], label)
        assert row["floor"] >= 0 and row["what"] and row["held_out_samples"] > 0
        if "thermal" in models:  # only where the recordings have drive temperatures
            assert row["data_set"].startswith("Kinova")
    assert all(entry["peers"][label] for label in entry["peers"])
    assert "Pinocchio" in entry["peers"]["textbook"] and "OLS" in entry["peers"]["textbook"]


def check_speed(entry: dict[str, Any]) -> None:
    """Both sides timed over >= 3 rounds; the ratio follows from the stored times."""
    s = entry["speed"]
    ours, theirs = s["seconds"]["robodyn default"], s["seconds"]["textbook"]
    for t in (ours, theirs):
        assert 0 < t["min"] <= t["median"] and t["repeats"] >= 3
    assert s["textbook_over_robodyn"]["min"] == pytest.approx(theirs["min"] / ours["min"],
                                                              rel=0.02, abs=0.01)
    assert s["textbook_over_robodyn"]["median"] == pytest.approx(
        theirs["median"] / ours["median"], rel=0.02, abs=0.01)
    assert s["threads"] == 1 and s["joints"] == 7 and s["what_differs"]
    if "--quick" not in entry["command"]:
        assert s["samples"] == entry["targets"]["speed_samples"] == 100_000


def check_rendered_targets(data: dict[str, Any], text: str) -> None:
    """Each target's met / not met in the rendering is the one its figure gives."""
    entry = data["benchmarks"][NAME]
    flat = " ".join(text.split())
    rows = {r["data_set"]: r["models"] for r in entry["rows"]}
    for goal in entry["targets"]["rows"]:
        prefix = f"{goal['data_set']} <= {goal['at_most']:g} {goal['figure']}: "
        if goal["data_set"] not in rows:
            assert prefix + "not run" in flat
            continue
        value = rows[goal["data_set"]]["robodyn default"][goal["figure"]]
        verdict = "met" if value <= goal["at_most"] else "not met"
        assert re.search(re.escape(prefix) + r"[0-9.]+, " + verdict + r"\b", flat), prefix
    above = [n for n, m in rows.items() if m["robodyn default"]["raw"] > m["textbook"]["raw"]]
    assert f"at or below on {len(rows) - len(above)} of the {len(rows)} rows" in flat
    for name in above:
        assert f"above on {name}" in flat or f"; {name} (" in flat
    every = re.search(r"on every row: .*?: (met|not met)\.", flat)
    assert every is not None and every.group(1) == ("not met" if above else "met")
    if "speed" in entry:
        s = entry["speed"]
        limit = entry["targets"]["speed_under_s"]
        if s["samples"] == entry["targets"]["speed_samples"]:
            met = s["seconds"]["robodyn default"]["min"] < limit
            assert f"judged on the minimum: {'met' if met else 'not met'})" in flat
        else:
            assert "not judged on this size" in flat


def test_rows_have_every_model_and_its_description(sections):
    entry = _data(sections, NAME)["benchmarks"][NAME]
    check_rows(entry)
    assert "--quick" not in entry["command"] and "--only" not in entry["command"]
    assert len(entry["rows"]) == FULL_ROWS


def test_speed_ratio_follows_from_the_times(sections):
    check_speed(_data(sections, NAME)["benchmarks"][NAME])


def test_targets_are_judged_from_the_figures(renderer, sections):
    data = _data(sections, NAME)
    check_rendered_targets(data, renderer.RENDERERS[NAME](data))
