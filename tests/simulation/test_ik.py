"""Inverse kinematics: accuracy, joint limits and failure reports."""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.simulation import UnreachableError, inverse_kinematics
from robodyn.simulation.ik import joint_limits


def test_full_pose_ik_of_the_puma_reaches_random_targets(puma):
    lower, upper = joint_limits(puma)
    rng = np.random.default_rng(7)
    for _ in range(10):
        q_true = rng.uniform(lower + 0.2, upper - 0.2)
        target = puma.forward_kinematics(q_true)
        res = inverse_kinematics(puma, target, q_true + rng.normal(0, 0.2, 6))
        assert res.success
        pose = puma.forward_kinematics(res.q)
        assert np.linalg.norm(pose[:3, 3] - target[:3, 3]) < 1e-9
        assert np.abs(pose[:3, :3] - target[:3, :3]).max() < 1e-9
        assert np.all(res.q >= lower) and np.all(res.q <= upper)


def test_position_ik_of_the_aa300_respects_its_limits(aa300):
    lower, upper = joint_limits(aa300)
    assert lower[1] == 0.2 and upper[1] == 1.2
    rng = np.random.default_rng(1)
    for _ in range(10):
        q_true = rng.uniform(lower, upper)
        target = aa300.forward_kinematics(q_true)[:3, 3]
        res = inverse_kinematics(aa300, target)  # from mid-range, with restarts
        assert res.success and res.position_error < 1e-9
        assert np.linalg.norm(aa300.forward_kinematics(res.q)[:3, 3] - target) < 1e-9
        assert np.all(res.q >= lower) and np.all(res.q <= upper)


def test_a_target_outside_the_limits_is_reported_clearly(aa300):
    q = np.array([0.0, 0.78, 1.93])
    p = aa300.forward_kinematics(q)[:3, 3]
    # 0.4 m higher than the slide allows
    too_high = p + np.array([0.0, 0.0, 0.8])
    with pytest.raises(UnreachableError) as info:
        inverse_kinematics(aa300, too_high, q)
    msg = str(info.value)
    assert "not reachable" in msg and "aa300" in msg and "upper_arm" in msg
    res = inverse_kinematics(aa300, too_high, q, raise_on_failure=False)
    assert not res.success and res.at_limit == ("upper_arm",)
    assert res.q[1] == 1.2
    assert res.position_error == pytest.approx(too_high[2] - (1.2 + 0.2194), abs=1e-6)
    # beyond the arm's reach
    res = inverse_kinematics(aa300, np.array([3.0, 0.0, 1.0]), raise_on_failure=False)
    assert not res.success and res.position_error > 1.0


def test_bad_ik_inputs(aa300):
    with pytest.raises(ValueError, match="target"):
        inverse_kinematics(aa300, np.zeros(4))
    with pytest.raises(ValueError, match="q0"):
        inverse_kinematics(aa300, np.zeros(3), np.zeros(2))
