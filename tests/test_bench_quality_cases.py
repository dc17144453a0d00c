"""The virtual lab's logger-clock stamps of the identification benchmarks (``quality_cases.ticked``).

``bench_identification_matrix.py --stamp-tick`` rounds each recording's stamps to a coarse clock:
samples taken every 10.6 ms (94 Hz) and stamped by a 2 ms clock come out 10 or 12 ms apart, each
stamp within half a tick of the instant, the measured values untouched; a tick so coarse that two
samples share a stamp is refused, naming the recording.
"""

from __future__ import annotations

from types import ModuleType

import numpy as np
import pytest

import robodyn as rd
from tests.readme_results import benchmark_module


@pytest.fixture(scope="module")
def cases() -> ModuleType:
    """``benchmarks/quality_cases.py`` loaded as a module."""
    return benchmark_module("quality_cases")


def _log(period: float, count: int) -> rd.Recording:
    t = period * np.arange(count)
    q = np.column_stack([np.sin(2.0 * t), np.cos(3.0 * t)])
    return rd.Recording(t=t, q=q, current=0.1 * q, joint_names=("a", "b"), source="log.csv")


def test_a_2_ms_clock_stamps_94_hz_samples_10_or_12_ms_apart(cases: ModuleType) -> None:
    rec = _log(0.0106, 500)
    out = cases.ticked(rec, 0.002)
    steps = np.unique(np.round(np.diff(out.t) * 1e3, 9))
    assert set(steps) == {10.0, 12.0}
    assert np.max(np.abs(out.t - rec.t)) <= 0.001 + 1e-12
    np.testing.assert_array_equal(out.q, rec.q)
    np.testing.assert_array_equal(out.current, rec.current)
    assert np.allclose(out.t / 0.002, np.round(out.t / 0.002), atol=1e-9)


def test_a_measured_velocity_is_kept_and_an_estimated_one_made_anew(cases: ModuleType) -> None:
    rec = _log(0.0106, 500)
    measured = rd.Recording(t=rec.t, q=rec.q, qd=np.ones_like(rec.q), current=rec.current,
                            joint_names=("a", "b"), source="log.csv")
    np.testing.assert_array_equal(cases.ticked(measured, 0.002).qd, measured.qd)
    out = cases.ticked(rec, 0.002)
    assert "qd" in out.estimated and not np.array_equal(out.qd, rec.qd)


def test_a_tick_that_merges_two_samples_is_refused_naming_the_recording(cases: ModuleType) -> None:
    with pytest.raises(ValueError, match="log.csv"):
        cases.ticked(_log(0.0106, 50), 0.02)
