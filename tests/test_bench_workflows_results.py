"""The workflow benchmarks' entries (calibration, validation, sweep) hold together.

Issue 22, item 2: ``bench_calibration.py``, ``bench_validation.py`` and ``bench_sweep.py`` merge
their figures into the results file that README's marked sections name, and
``benchmarks/render_workflows.py`` renders them. These checks read that file (and render it):
ratios follow from the stored times, targets' "met" / "not met" follow from the figures, the
peers' settings and quoted figures' sources are present. Nothing here times or runs a benchmark.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from tests.readme_results import section_data as _data

ROOT = Path(__file__).resolve().parent.parent


def _ratio_of(r: dict[str, float], a: dict[str, float], b: dict[str, float]) -> None:
    """Ratio ``r`` (min and median) follows from the summaries ``a`` / ``b``."""
    assert r["min"] == pytest.approx(a["min"] / b["min"], rel=0.03, abs=0.011)
    assert r["median"] == pytest.approx(a["median"] / b["median"], rel=0.03, abs=0.011)


def check_calibration(entry: dict[str, Any], text: str) -> None:
    """The ``calibration`` entry and its rendered section ``text``."""
    m = entry["models"]
    assert [r["model"] for r in m["rows"]] == ["dh", "hayati", "s-model", "poe"]
    for r in m["rows"]:
        assert r["parameters"] > 0 and r["evaluations"] > 0 and r["seconds"]["repeats"] >= 3
    j = entry["jacobian"]
    _ratio_of(j["ratio_fd_vs_analytic"], j["seconds"]["2-point"], j["seconds"]["analytic"])
    _ratio_of(j["ratio_fd_vs_calibrate"], j["seconds"]["2-point"], j["seconds"]["calibrate"])
    assert j["max_parameter_difference"] < 1e-6  # the same solution by both Jacobians
    c = entry["combined"]
    assert (c["poses"], c["targets"], c["terms"]) == (1000, 3, ["compliance", "harmonics"])
    _ratio_of(c["ratio_fd_vs_analytic"], c["seconds"]["2-point"], c["seconds"]["analytic"])
    met = c["seconds"]["calibrate"]["min"] < c["target_s"]
    assert f"(target under {c['target_s']:g} s: {'met' if met else 'not met'})" in text
    cli = entry["cli"]
    s = cli["seconds"]
    # the pairing, the other floor and the two imports, measured in the same rounds
    assert {"before the solve", "import numpy process", "numpy + scipy.optimize",
            "import scipy.optimize after numpy", "import sympy after numpy"} <= s.keys()
    assert {v["repeats"] for v in s.values()} == {cli["rounds"]}
    _ratio_of(cli["before_vs_import_numpy"], s["before the solve"], s["import numpy process"])
    _ratio_of(cli["before_vs_floor"], s["before the solve"], s["numpy + scipy.optimize"])
    assert cli["sympy_loaded_before_solve"] is False  # the robot's numbers come from the cache
    assert cli["before_minus_floor_s"]["min"] == pytest.approx(
        s["before the solve"]["min"] - s["numpy + scipy.optimize"]["min"], abs=0.002)
    before, target = s["before the solve"]["min"], cli["target_before_s"]
    assert target == 0.5
    assert f"at most 0.5 s: {'met' if before <= target else 'not met'}" in text
    for v in cli["after_solve_s"].values():
        assert v["min"] <= v["median"]


def check_validation(entry: dict[str, Any], text: str) -> None:
    """The ``validation`` entry and its rendered section ``text``."""
    methods = list(entry["seconds"])
    assert set(methods) == {"ols", "wls", "consistent"}
    for m in methods:
        _ratio_of(entry["vs_ols"][m], entry["seconds"][m], entry["seconds"]["ols"])
    rows = entry["held_out"]
    for m in methods:  # three runs and their pooling, seven jointwise runs
        mine = [r for r in rows if r["method"] == m]
        last = [r for r in mine if r["case"] == "last 30 %"]
        joint = [r for r in mine if r["case"] == "jointwise"]
        assert len(last) == 4 and len(joint) == 7
        assert last[3]["samples"] == sum(r["samples"] for r in last[:3])
        assert all(len(r["joints"]) == 1 for r in joint)
        pooled = last[3]
        below = pooled["raw"] < 0.32 and pooled["filtered"] < 0.22
        assert (f"{m} {pooled['raw']:.3f} / {pooled['filtered']:.3f} "
                f"({'below both' if below else 'not below both'})") in text
    b = entry["baseline"]
    assert (b["raw"], b["filtered"]) == (0.32, 0.22) and "README" in b["source"]
    for r in entry["cross_run"]:
        assert r["recording"] not in r["fit_on"] and r["method"] == "consistent"
    assert entry["train_samples"] > 0 and entry["friction"]


def check_sweep(entry: dict[str, Any], text: str) -> None:
    """The ``sweep`` entry and its rendered section ``text``."""
    assert entry["sizes"] and {"serial loop", "ProcessPool, 2 processes", "Dask"} <= entry["peers"].keys()
    for s in entry["sizes"]:
        t = s["seconds"]
        assert set(t) == {"serial loop", "ProcessPool, 2 processes", "Dask, 1 worker",
                          "Dask, 2 workers"}
        assert {v["repeats"] for v in t.values()} == {s["rounds"]}
        _ratio_of(s["scaling_2_vs_1"], t["Dask, 1 worker"], t["Dask, 2 workers"])
        _ratio_of(s["dask2_vs_pool"], t["ProcessPool, 2 processes"], t["Dask, 2 workers"])
        oh = s["overhead_percent"]
        assert oh["min"] == pytest.approx(
            100 * (t["Dask, 1 worker"]["min"] / t["serial loop"]["min"] - 1), abs=0.2)
        assert s["ms_per_case_serial"]["min"] == pytest.approx(
            t["serial loop"]["min"] * 1e3 / s["cases"], rel=0.01)
        met = oh["min"] < s["target_overhead_percent"]
        assert f"target under {s['target_overhead_percent']:g} %: {'met' if met else 'not met'}" \
            in text
    run = {s["cases"] for s in entry["sizes"]}
    if 20000 in run:
        assert "quoted" not in entry
    else:  # the size: quoted with its source, said not to be measured here
        q = entry["quoted"]
        assert q["cases"] == 20000 and q["source"] and "not measured in this run" in text


CHECKS = {"calibration": check_calibration, "validation": check_validation, "sweep": check_sweep}


@pytest.mark.parametrize("name", sorted(CHECKS))
def test_workflow_entry(renderer, sections, name):
    data = _data(sections, name)
    CHECKS[name](data["benchmarks"][name], renderer.RENDERERS[name](data))

