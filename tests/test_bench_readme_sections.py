"""Every README benchmark section but the kernels' shows the figures of its results file.

Issue 22, items 1c-1e and 2: each benchmark merges its figures into
``benchmarks/results/<machine>.json`` and ``benchmarks/render_readme.py`` renders one marked
README section per benchmark from it. Reads only committed files (README.md, the results file)
and renders them: nothing here times or runs a benchmark.
"""

from __future__ import annotations

import copy
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.readme_results import section_data as _data

ROOT = Path(__file__).resolve().parent.parent
#: Every marked section of the README but ``kernels`` (tests/test_readme_results.py covers it):
#: a section added to the README is checked here without a change to this file.
SECTIONS = tuple(sorted({m.group(1) for m in re.finditer(r"<!-- results:([\w-]+) ",
                                                          (ROOT / "README.md").read_text())}
                        - {"kernels"}))


def _summaries(node: Any) -> Iterator[dict[str, Any]]:
    """Every ``{"min", "median", "repeats"}`` figure in an entry."""
    if isinstance(node, dict):
        if {"min", "median", "repeats"} <= node.keys():
            yield node
        for value in node.values():
            yield from _summaries(value)
    elif isinstance(node, list):
        for value in node:
            yield from _summaries(value)


@pytest.mark.parametrize("name", SECTIONS)
def test_section_equals_its_rendering(renderer, sections, name):
    data = _data(sections, name)
    assert renderer.RENDERERS[name](data) == sections[name]["body"], (
        f"README's results:{name} section differs from its results file: run "
        ".venv/bin/python benchmarks/render_readme.py")


@pytest.mark.parametrize("name", SECTIONS)
def test_entry_has_min_median_load_and_command(sections, name):
    entry = _data(sections, name)["benchmarks"][name]
    figures = list(_summaries(entry))
    assert figures, f"{name}: no min/median figure"
    for f in figures:
        assert 0 <= f["min"] <= f["median"] and f["repeats"] >= 3
    assert len(entry["load_average_at_start"]) == len(entry["load_average_at_end"]) == 3
    assert entry["command"].startswith("python benchmarks/bench_") and entry["date"]


@pytest.mark.parametrize("name", SECTIONS)
def test_a_changed_figure_changes_the_rendering(renderer, sections, name):
    data = _data(sections, name)
    changed = copy.deepcopy(data)
    first = next(_summaries(changed["benchmarks"][name]))
    first["min"] += 1000
    assert renderer.RENDERERS[name](changed) != renderer.RENDERERS[name](data)


def test_casadi_rows_agree_and_say_what_differs(sections):
    entry = _data(sections, "casadi")["benchmarks"]["casadi"]
    rows = {r["library"]: r for r in entry["rows"]}
    casadi = [name for name in rows if name.startswith("CasADi")]
    # per state, CasADi's batched map, and sin/cos precomputed outside the timed call
    assert "CasADi per state" in rows and any("map" in n for n in casadi)
    assert any("sincos" in n and "not timed" in rows[n]["note"] for n in casadi)
    for name in casadi:
        assert rows[name]["note"] and rows[name]["max_rel_error"] <= 1e-9
    assert {r["peer"] for r in entry["ratios"]} == set(casadi)
    for r in entry["ratios"]:  # ratio to robodyn on the same number of threads
        ours = rows["robodyn" if r["threads"] == 1 else "robodyn 2 threads"]["ns_per_state"]
        theirs = rows[r["peer"]]["ns_per_state"]
        assert r["min"] == pytest.approx(theirs["min"] / ours["min"], rel=0.02, abs=0.01)
    assert entry["flags"]
    threads = _data(sections, "casadi")["benchmarks"]["threads"]  # rendered in the same section
    assert all(0 <= f["min"] <= f["median"] for f in _summaries(threads))
    assert set(threads["peers"]) == {"robodyn", "pinocchio wheel"}


def test_ensemble_has_mujoco_rollout_beside_robodyn(sections):
    entry = _data(sections, "ensemble")["benchmarks"]["ensemble"]
    labels = {r["library"] for r in entry["rows"]}
    assert {"robodyn ensemble", "MuJoCo rollout", "robodyn parameter sets"} <= labels
    assert set(entry["peers"]) == {"robodyn", "MuJoCo"}
    assert "contacts disabled" in entry["peers"]["MuJoCo"] and "RK4" in entry["peers"]["MuJoCo"]
    assert entry["mujoco_agreement_rad"] < 1e-5  # the same system, the same scheme


def _check_routes(rows: list[dict[str, Any]], sweeps: dict[str, Any], key: str, base: str,
                  ) -> None:
    """SciPy rows at their sweep's timed setting, matched where claimed; ratios from the times."""
    by = {r["label"]: r for r in rows}
    for label, s in sweeps.items():
        row = by[f"SciPy {label}"]
        assert f"rtol {s['timed']['rtol']:.0e}" in row["settings"]
        assert row["max_error"] == s["timed"]["max_error"]
        if s["matched"] is not None:  # matched accuracy: within the target, the loosest tried
            assert s["matched"]["max_error"] <= s["target_error"]
            assert all(t["max_error"] > s["target_error"] for t in s["trials"][:-1])
        else:
            assert "NOT matched" in row["settings"]
    for r in rows:
        assert r["settings"]
        assert r[key]["min"] == pytest.approx(r["ms"]["min"] / by[base]["ms"]["min"],
                                              rel=0.02, abs=0.06)


def test_simulation_rows_have_scipy_at_its_best_and_mujoco(sections):
    entry = _data(sections, "simulation")["benchmarks"]["simulation"]
    t = entry["trolley"]
    labels = {r["label"] for r in t["rows"]}
    assert {"robodyn rd.rollout", "MuJoCo mj_step loop", "MuJoCo rollout",
            "SciPy RK45 + lambdify", "SciPy DOP853 + compiled RHS"} <= labels
    assert t["sweeps"]["DOP853 + compiled RHS"]["rhs"] == "compiled RHS"
    _check_routes(t["rows"], t["sweeps"], "vs_rollout", "robodyn rd.rollout")
    assert entry["puma"]["rows"] and entry["compile"]["first_s"] > 0


def test_hydro_rows_have_scipy_at_its_best(sections):
    entry = _data(sections, "hydro")["benchmarks"]["hydro"]
    s = entry["simulation"]
    assert {"SciPy RK45 + lambdify", "SciPy DOP853 + compiled RHS"} <= {r["label"] for r in s["rows"]}
    _check_routes(s["rows"], s["sweeps"], "vs_simulate", "robodyn rd.simulate")


def test_roofline_figures_follow_from_the_measurements(sections):
    e = _data(sections, "roofline")["benchmarks"]["roofline"]
    i, r = e["inverse_dynamics"], e["roofline"]
    flops = i["additions"] + i["multiplications"] + i["sincos_angles"] * i["sincos_flops_per_angle"]
    ns = i["ns_per_state"]["min"]
    assert r["flops_per_state"] == flops > 0
    assert r["achieved_gflops"] == pytest.approx(flops / ns, rel=0.01)  # flop per ns = GFLOP/s
    assert r["compute_floor_ns"] == pytest.approx(flops / e["peak"]["gflops"], rel=0.01)
    assert r["times_compute_floor"] == pytest.approx(ns / r["compute_floor_ns"], rel=0.01)
    assert r["memory_floor_ns"] == pytest.approx(i["bytes_per_state"] / e["triad"]["gbs"], rel=0.01)
    assert 0 < r["fraction_of_peak"] <= 1 and e["peak"]["median_gflops"] <= e["peak"]["gflops"]


def test_block_width_verdict_follows_from_the_rows(sections):
    e = _data(sections, "block_width")["benchmarks"]["block_width"]
    assert e["max_deviation_from_scalar"] <= 1e-12
    for isa, kernels in e["verdict"].items():
        rows = {r["width"]: r for r in e["rows"] if r["isa"] == isa}
        assert {1, 8, 16} <= rows.keys()
        for kernel, v in kernels.items():
            fastest = min(rows, key=lambda w: rows[w][kernel]["min"])
            assert v["best_width"] == fastest
            assert v["chosen_over_best"] == pytest.approx(
                rows[v["chosen_width"]][kernel]["min"] / rows[fastest][kernel]["min"], abs=2e-3)
    # the widths robodyn's rule gives the machine's own flags and AVX2 code
    from robodyn.codegen.cpu import default_block_width

    simd = frozenset(_data(sections, "block_width")["machine"]["simd"])
    assert e["verdict"]["native"]["ID"]["chosen_width"] == default_block_width(simd)
    assert e["verdict"]["avx2"]["ID"]["chosen_width"] == default_block_width(simd - {"avx512f"})
