"""The ``derivatives`` and ``identify`` entries of the results file README's sections name.

Issue 22 (items 1 and 2): the figures follow from the stored times (ratios, the loop and the
binding taken out), the targets' met / not met follow from the figures, the stacking ratios
judged against the target compare one thread with one thread, and the path timed is the one
``rd.identify`` was seen to use. Reads only committed files (README.md, the results file):
nothing here times or runs a benchmark. The checks are plain functions, callable on any entry.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from tests.readme_results import section_data as _data

ROOT = Path(__file__).resolve().parent.parent


def _ratio_follows(ratio: dict[str, float], theirs: dict[str, float], ours: dict[str, float]) -> None:
    """A stored ratio equals the quotient of the stored (rounded) figures it is made of."""
    for key in ("min", "median"):
        assert ratio[key] == pytest.approx(theirs[key] / ours[key], rel=0.02, abs=0.06), key


def check_derivatives(e: dict[str, Any]) -> None:
    """The ``derivatives`` entry: ratios from the times, loop and binding floor taken out,
    the floor above the loop, agreement, what each side is, the target judged."""
    rows = {r["kernel"]: r for r in e["rows"]}
    assert {"RNEA derivatives", "ABA derivatives", "inverse dynamics", "forward dynamics"} == set(rows)
    loop, floor = e["python_loop_ns"], e["binding_floor_ns"]
    assert 0 < loop["min"] < floor["min"]  # the binding costs more than the bare Python loop
    assert "forwardKinematics" in e["binding_floor_call"]
    for r in rows.values():
        theirs = r["pinocchio_loop_ns"]
        assert r["minus_loop_ns"]["min"] == pytest.approx(theirs["min"] - loop["min"], abs=0.3)
        assert r["minus_loop_ns"]["min"] < theirs["min"]
        _ratio_follows(r["ratio"], theirs, r["robodyn_ns"])
        _ratio_follows(r["minus_loop_ratio"], r["minus_loop_ns"], r["robodyn_ns"])
        # the binding floor taken out of the derivatives (a lower bound of the ratio) only
        assert ("minus_binding_floor_ns" in r) == r["kernel"].endswith("derivatives")
        if "minus_binding_floor_ns" in r:
            bare = r["minus_binding_floor_ns"]
            assert bare["min"] == pytest.approx(theirs["min"] - floor["min"], abs=0.3)
            assert 0 < bare["min"] < r["minus_loop_ns"]["min"]
            _ratio_follows(r["minus_binding_floor_ratio"], bare, r["robodyn_ns"])
    t = e["target"]
    aba = rows["ABA derivatives"]
    assert t["target"] == 5.0 and t["judged_on"] == "minus_binding_floor_ratio"
    assert t["value"] == aba["minus_binding_floor_ratio"]["min"]
    assert t["met"] == (t["value"] >= t["target"])
    a = e["agreement"]
    assert a["states"] >= 10
    assert max(a[k] for k in ("d_tau_d_q", "d_tau_d_qd", "d_qdd_d_q", "d_qdd_d_qd", "d_qdd_d_tau")) < 1e-9
    assert set(e["returns_views"]) == {"computeRNEADerivatives", "computeABADerivatives"}
    assert e["three_copies_ns"]["min"] > 0
    assert "friction" in e["peers"]["robodyn"] and "no friction" in e["peers"]["Pinocchio"]
    assert "1 thread" in e["peers"]["robodyn"] and "1 thread" in e["peers"]["Pinocchio"]
    assert not any("Derivatives" in name for name in e["pinocchio_batched"])
    assert e["loops"] <= e["states"]


def check_identify(e: dict[str, Any]) -> None:
    """The ``identify`` entry: rd.identify's path timed first, ratios from the times, the target
    judged only 1 thread against 1, threads stated, agreement, what rd.identify was seen to call."""
    s = e["stacking"]
    rows = {r["label"]: r for r in s["rows"]}
    first = s["rows"][0]
    assert first["label"] == "robodyn fresh" and first["threads"] == 1
    assert "regressor_rows_of" in first["what"]
    assert {"Pinocchio fresh", "Pinocchio reused", "NumPy np.full", "NumPy fill",
            "robodyn reused", "robodyn fresh 2 threads", "robodyn reused 2 threads"} <= set(rows)
    assert rows["Pinocchio fresh"]["threads"] == rows["Pinocchio reused"]["threads"] == 1
    judged = set()
    for r in s["ratios"]:
        peer, row = rows[r["peer"]], rows[r["row"]]
        assert r["peer_threads"] == peer["threads"] == 1 and r["row_threads"] == row["threads"]
        assert r["case"] in r["peer"]  # fresh with fresh, reused with reused
        _ratio_follows(r, peer["ns_per_sample"], row["ns_per_sample"])
        if "target" in r:
            assert r["row_threads"] == 1 and r["row"].startswith("robodyn")
            assert r["target"] == 10.0 and r["met"] == (r["min"] >= r["target"])
            judged.add(r["row"])
    assert judged == {"robodyn fresh", "robodyn reused"}
    w = s["writing_alone"]
    for case, ours, numpy in (("fresh", "robodyn fresh", "NumPy np.full"),
                              ("reused", "robodyn reused", "NumPy fill")):
        _ratio_follows({k: 1 / w[case][k] for k in ("min", "median")},
                       rows[numpy]["ns_per_sample"], rows[ours]["ns_per_sample"])
    assert s["rigid_body_agreement"] < 1e-9
    assert s["columns"] == 15 * s["joints"] and s["pinocchio_columns"] == 10 * s["joints"]
    if "identifications" in e:
        c = e["identifications"]["stacking_calls"]
        # rd.identify stacks its fit's rows through identification_matrix as the first row does
        # (1 thread, fresh, all columns); its effort goes through it in chunks into a reused buffer
        assert c["count"] > 0 and c["threads"] == [1] and not c["columns"]
        if "fresh" in c:
            assert c["fresh"]["count"] > 0 and c["fresh"]["samples"] > 0
            assert c["fresh"]["count"] + c["reused"]["count"] == c["count"]
            assert c["out"] == (c["reused"]["count"] > 0)
        else:  # written before the calls were told apart, when every call was fresh
            assert not c["out"]
        m = e["identifications"]["methods"]
        assert set(m) == {"ols", "wls", "consistent"} and all(v["seconds"] > 0 for v in m.values())


def test_derivatives_entry(sections):
    check_derivatives(_data(sections, "derivatives")["benchmarks"]["derivatives"])


def test_identify_entry(sections):
    check_identify(_data(sections, "identify")["benchmarks"]["identify"])


def test_identify_section_says_threads_of_unjudged_rows(renderer, sections):
    data = _data(sections, "identify")
    text = renderer.RENDERERS["identify"](data)
    for r in data["benchmarks"]["identify"]["stacking"]["ratios"]:
        if r["row_threads"] != r["peer_threads"]:
            assert f"({r['row_threads']} threads vs {r['peer_threads']})" in text
    assert "not judged" in text
