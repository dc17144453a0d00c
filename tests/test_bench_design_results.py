"""The design suites' entries (derivation, excitation, measure) hold together.

Issue 22, item 2: ``bench_derivation.py``, ``bench_excitation.py`` and ``bench_measure.py`` merge
their figures into the results file that README's marked sections name. These checks read those
entries (nothing here times or runs a benchmark): ratios follow from the stored times, the
targets' met / not met from the figures, peers measured in the run agree with robodyn and say
what they are, and every figure not measured in the run carries its source.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

from tests.readme_results import section_data

ROOT = Path(__file__).resolve().parent.parent
MARKER = re.compile(r"<!-- results:(?P<name>[\w-]+) (?P<path>\S+) -->")


def _entry(sections: dict[str, Any], name: str) -> dict[str, Any]:
    """Entry ``name`` of the results file that README's section ``name`` names."""
    return section_data(sections, name)["benchmarks"][name]


def _close(a: float, b: float) -> bool:
    return a == pytest.approx(b, rel=0.03, abs=0.02)


def _check_quoted(quoted: dict[str, Any]) -> None:
    for name, q in quoted.items():
        assert "not measured in this run" in q["source"], name


def check_derivation(e: dict[str, Any]) -> None:
    """Targets, ratios, op-count rows and quoted figures of the ``derivation`` entry."""
    sym = e["symbolic"]
    assert sym["met"] == (sym["seconds"]["complete"]["min"] < sym["target_s"])
    m = e["methods"]
    assert m["met"] == all(v["min"] < m["target_s"] for k, v in m["seconds"].items()
                           if k != "newton_euler")
    rows = e["ops"]["rows"]
    for r in rows:
        if r["label"] != "robodyn Newton-Euler with rotor and friction":
            assert set(e["ops"]["counting"]) <= r.keys(), r["label"]  # both methods, every side
        if r["label"] == "CasADi textbook RNEA":
            assert r["max_rel_error"] < 1e-9 and r["form"]
    for t in e["ops"]["targets"]:
        if t["peer"] != "CasADi textbook RNEA":
            continue
        ours, theirs = (next(r[t["method"]] for r in rows if r["label"] == label
                             and r["parameters"] == t["parameters"])
                        for label in ("robodyn Newton-Euler", "CasADi textbook RNEA"))
        assert t["met"] == (ours["mul"] < theirs["mul"] and ours["add"] < theirs["add"])
    _check_quoted(e["quoted"])
    assert "another method" in e["quoted"]["SymPyBotics"]["counting"]
    k = e["kanes_method"]
    for name, ratio in k["sympy_over"].items():
        assert _close(ratio["min"], k["seconds"]["sympy KanesMethod"]["min"]
                      / k["seconds"][name]["min"])
    ch = e["chains"]
    if "growth" in ch:
        assert ch["met"] == (max(ch["growth"].values()) <= ch["target_growth"])
        first, last = ch["marginal"][0], ch["marginal"][-1]
        assert _close(ch["growth"]["mul"], last["mul_per_joint"] / first["mul_per_joint"])
        small, large = ch["rows"][0], ch["rows"][-1]
        assert _close(ch["growth"]["time"], large["seconds"]["min"] / large["joints"]
                      / (small["seconds"]["min"] / small["joints"]))


def check_excitation(e: dict[str, Any]) -> None:
    """Targets, the gradient ratio and agreement, the quoted range of the ``excitation`` entry."""
    d, t, g, r = e["design"], e["targets"], e["gradient"], e["random"]
    assert e["met"]["condition_number"] == (d["condition_number"] < t["condition_number"])
    assert e["met"]["design_s"] == (d["wall_s"] < t["design_s"])
    assert _close(r["best_over_optimised"], r["best"] / d["condition_number"])
    ms = g["ms"]
    assert _close(g["ratio"]["min"], ms["central differences"]["min"] / ms["analytic"]["min"])
    assert g["max_rel_difference"] < 1e-6  # the same gradient, two ways
    _check_quoted(e["quoted"])


def check_measure(e: dict[str, Any]) -> None:
    """The ratio and the velocity errors of the ``measure`` entry, and what each pipeline does."""
    sec = e["seconds"]
    assert _close(e["ratio"]["min"], sec["robodyn"]["min"] / sec["pandas + numpy"]["min"])
    err = e["velocity_error"]
    assert len(err["robodyn"]) == len(err["pandas + numpy"]) == e["files"] == len(e["error_ratio"])
    for ratio, ours, plain in zip(e["error_ratio"], err["robodyn"], err["pandas + numpy"],
                                  strict=True):
        assert _close(ratio, plain / ours)
    assert set(e["pipelines"]) == set(sec) and all(e["pipelines"].values())


def test_derivation_entry(sections):
    check_derivation(_entry(sections, "derivation"))


def test_excitation_entry(sections):
    check_excitation(_entry(sections, "excitation"))


def test_measure_entry(sections):
    check_measure(_entry(sections, "measure"))
