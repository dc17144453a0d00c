"""Tracker synchronisation: a known delay between tracker and joint clocks is recovered."""


import numpy as np
import pytest

import robodyn as rd
from robodyn.measure.sync import synchronise


@pytest.mark.parametrize("delay", [0.0237, -0.0113])
def test_known_tracker_delay_recovered_within_one_sample(puma, delay):
    rng = np.random.default_rng(5)
    freqs = np.array([0.31, 0.53, 0.87, 1.3])

    def q_of(t):  # smooth multi-sine joint motion, rad
        return 0.4 * np.sin(np.outer(t, 2 * np.pi * freqs)[:, :, None] + np.arange(6)).sum(axis=1)

    t = 1e-3 * np.arange(6000)  # joints at 1 kHz
    q = q_of(t) + 2e-6 * rng.standard_normal((t.size, 6))  # encoder-level noise
    true_tool_t = 0.004 * np.arange(1500) + 0.0013  # tracker at 250 Hz on its own phase
    points = puma.forward_kinematics(q_of(true_tool_t))[:, :3, 3]
    # tracker in its own frame (rotated, moved) with 20 um noise, stamps late by `delay`
    c, s = np.cos(0.7), np.sin(0.7)
    rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    points = points @ rot.T + [1.0, -2.0, 0.3] + 20e-6 * rng.standard_normal(points.shape)
    rec = rd.Recording(t=t, q=q, tool_t=true_tool_t + delay, tool_points=points)
    sync = synchronise(rec, puma)
    assert abs(sync.offset - delay) < rec.dt  # within one joint sample (1 ms)
    assert sync.correlation > 0.95
    assert np.allclose(sync.recording.tool_t, true_tool_t, atol=rec.dt)
    assert np.array_equal(rec.tool_t, true_tool_t + delay)  # input recording untouched


def test_needs_tracker_samples(puma):
    t = 1e-3 * np.arange(100)
    rec = rd.Recording(t=t, q=np.zeros((100, 6)) + t[:, None])
    with pytest.raises(rd.robot.errors.RecordingError, match="no tracker samples"):
        synchronise(rec, puma)
