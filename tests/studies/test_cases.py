"""Grid expansion, samplers and per-case seeds: deterministic, independent of how cases are run."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import qmc

from robodyn.robot.errors import StudyError
from robodyn.studies import Grid, LatinHypercube, RandomSampler, Range, case_seed, expand_cases, run_serial
from tests.studies.tasks import noisy_square


def test_grid_is_the_product_last_key_fastest():
    cases = expand_cases({"a": [1, 2], "b": ["x", "y", "z"]}, seed=None)
    assert cases == [{"a": a, "b": b} for a in (1, 2) for b in ("x", "y", "z")]
    assert expand_cases(Grid({"a": [1, 2], "b": ["x", "y", "z"]}), seed=None) == cases


def test_user_cases_are_copied_not_modified():
    given = [{"x": 1.0}, {"x": 2.0, "seed": 7}]
    cases = expand_cases(given, seed=5)
    assert given == [{"x": 1.0}, {"x": 2.0, "seed": 7}]
    assert cases[0]["seed"] == case_seed(5, 0) and cases[1]["seed"] == 7  # a given seed is kept


def test_case_seed_is_the_spawned_child_of_the_study_seed():
    # SeedSequence(s).spawn(n)[i] is the reference: the same entropy and spawn key (i,)
    children = np.random.SeedSequence(42).spawn(5)
    for i, child in enumerate(children):
        assert case_seed(42, i) == int(child.generate_state(1, np.uint64)[0] >> np.uint64(1))
    seeds = [case_seed(42, i) for i in range(1000)]
    assert len(set(seeds)) == 1000 and all(0 <= s < 2**63 for s in seeds)
    assert case_seed(43, 0) != case_seed(42, 0)


def test_latin_hypercube_matches_scipy_and_is_stratified():
    lhs = LatinHypercube({"a": (0.0, 10.0), "b": Range(1.0, 100.0, log=True)}, n=8, seed=3)
    cases = expand_cases(lhs, seed=None)
    u = qmc.LatinHypercube(d=2, seed=np.random.default_rng(3)).random(8)
    np.testing.assert_array_equal([c["a"] for c in cases], 10.0 * u[:, 0])
    np.testing.assert_allclose([c["b"] for c in cases], 10 ** (2 * u[:, 1]), rtol=1e-14)
    # one point in each of the 8 strata of every dimension
    assert sorted(np.floor(np.array([c["a"] for c in cases]) / 10.0 * 8).astype(int)) == list(range(8))
    assert expand_cases(lhs, seed=None) == cases  # same seed, same design
    other = expand_cases(LatinHypercube({"a": (0.0, 10.0), "b": (1.0, 2.0)}, n=8, seed=4), seed=None)
    assert [c["a"] for c in other] != [c["a"] for c in cases]


def test_sampler_crossed_with_grid_and_fixed_values():
    s = RandomSampler({"x": Range(1, 20, integer=True)}, n=4, seed=1, fixed={"k": "v"},
                      grid={"g": [0, 1]})
    cases = expand_cases(s, seed=None)
    assert len(cases) == 8 and all(c["k"] == "v" for c in cases)
    assert [c["g"] for c in cases] == [0] * 4 + [1] * 4
    xs = [c["x"] for c in cases]
    assert xs[:4] == xs[4:] and all(isinstance(x, int) and 1 <= x <= 20 for x in xs)
    u = np.random.default_rng(1).random((4, 1))
    assert xs[:4] == [int(v) for v in np.rint(1 + 19 * u[:, 0])]


@pytest.mark.parametrize("bad, message", [
    (LatinHypercube({"a": (5.0, 1.0)}, n=3), "range 'a': min 5 > max 1"),
    (LatinHypercube({"a": Range(0.0, 1.0, log=True)}, n=3), "log range needs min > 0"),
    (LatinHypercube({"a": (0.0, float("nan"))}, n=3), "max must be a finite number"),
    (RandomSampler({"a": (0.0, 1.0)}, n=0), "n must be a positive integer"),
    (RandomSampler({"a": (0.0, 1.0)}, n=2, fixed={"a": 1}), "given both as a range and a value"),
    ({"a": []}, "grid parameter 'a': empty list"),
    ({"a": 3}, "grid parameter 'a': expected a list"),
    ([{"a": 1}, 5], "case 1: expected a dict"),
    ("a=1", "cases: expected a list of dicts"),
])
def test_bad_cases_are_refused_with_the_reason(bad, message):
    with pytest.raises(StudyError, match=message.replace("(", r"\(").replace(")", r"\)")):
        expand_cases(bad)


def test_bad_seed_is_refused():
    with pytest.raises(StudyError, match="seed must be a non-negative integer"):
        expand_cases([{"a": 1}], seed=-1)


def test_serial_table_records_a_failing_case_and_keeps_case_order():
    table = run_serial(noisy_square, {"x": [0, 1, 2, 3, 4]}, seed=9)
    assert list(table.index) == [0, 1, 2, 3, 4]
    assert list(table.columns) == ["x", "seed", "y", "noise", "pair[0]", "pair[1]", "error"]
    assert table.loc[3, "error"] == "ValueError: x = 3 is not allowed here"
    assert table["error"].drop(3).isna().all() and np.isnan(table.loc[3, "y"])
    # each draw comes from the case's own seed, whatever else runs
    for i in (0, 1, 2, 4):
        assert table.loc[i, "noise"] == np.random.default_rng(case_seed(9, i)).normal()
    alone = run_serial(noisy_square, [{"x": 4, "seed": case_seed(9, 4)}], seed=None)
    assert alone.loc[0, "noise"] == table.loc[4, "noise"]
    with pytest.raises(ValueError, match="not allowed") as info:
        run_serial(noisy_square, {"x": [0, 3]}, on_error="raise")
    assert "case 1" in " ".join(getattr(info.value, "__notes__", []))


def test_case_count_bounded_before_anything_is_built(monkeypatch):
    big = {f"p{k}": list(range(1000)) for k in range(3)}  # 10^9 combinations
    with pytest.raises(StudyError, match=r"grid over p0, p1, p2: 1e\+09 cases, more than 1,000,000"):
        expand_cases(big)
    with pytest.raises(StudyError, match=r"LatinHypercube of n = 10000000 crossed with a grid of 2"):
        LatinHypercube({"x": (0.0, 1.0)}, n=10_000_000, grid={"g": [1, 2]}).cases()
    monkeypatch.setenv("ROBODYN_MAX_CASES", "10")
    with pytest.raises(StudyError, match="11 cases, more than 10"):
        RandomSampler({"x": (0.0, 1.0)}, n=11).cases()
    assert len(RandomSampler({"x": (0.0, 1.0)}, n=10).cases()) == 10
