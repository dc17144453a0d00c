"""Bad inputs give errors that say what is wrong."""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.simulation import (
    LQR,
    PD,
    PID,
    ComputedTorque,
    GravityCompensation,
    quintic,
    simulate,
    via_points,
)


@pytest.mark.parametrize(("args", "kwargs", "match"), [
    ((np.zeros(3), None, 1.0, 1e-3), {}, r"q0 must have shape \(2,\)"),
    ((np.zeros(2), np.zeros(3), 1.0, 1e-3), {}, r"qd0 must have shape \(2,\)"),
    ((np.array([np.nan, 0.0]), None, 1.0, 1e-3), {}, "non-finite"),
    ((np.zeros(2), None, 1.0, -1e-3), {}, "dt must be a positive"),
    ((np.zeros(2), None, 1.0, 0.0), {}, "dt must be a positive"),
    ((np.zeros(2), None, -1.0, 1e-3), {}, "duration must be a positive"),
    ((np.zeros(2), None, 1.0005, 1e-3), {}, "whole number of steps"),
    ((np.zeros(2), None, 1.0, 1e-3), {"method": "euler"}, "unknown method 'euler'"),
    ((np.zeros(2), None, 1.0, 1e-3), {"tau_limit": -1.0}, "tau_limit must be positive"),
    ((np.zeros(2), None, 1.0, 1e-3), {"tau_limit": [1.0, 2.0, 3.0]}, "tau_limit"),
])
def test_simulate_rejects_bad_arguments(planar, args, kwargs, match):
    with pytest.raises(ValueError, match=match):
        simulate(planar, *args, **kwargs)


def test_bad_controllers(planar):
    with pytest.raises(TypeError, match="controller must be"):
        simulate(planar, np.zeros(2), None, 0.1, 1e-3, controller="pd")
    with pytest.raises(ValueError, match="returned shape"):
        simulate(planar, np.zeros(2), None, 0.1, 1e-3, controller=lambda t, q, qd: np.zeros(3))
    with pytest.raises(ValueError, match=r"q_ref must have shape \(2,\)"):
        simulate(planar, np.zeros(2), None, 0.1, 1e-3, controller=PD(1.0, 1.0, np.zeros(3)))
    with pytest.raises(ValueError, match="kp must be"):
        simulate(planar, np.zeros(2), None, 0.1, 1e-3, controller=PD(np.ones(3), 1.0, np.zeros(2)))
    with pytest.raises(ValueError, match="trajectory has 3 joints"):
        simulate(planar, np.zeros(2), None, 0.1, 1e-3,
                 controller=ComputedTorque(quintic(np.zeros(3), np.ones(3), 1.0), 1.0, 1.0))
    with pytest.raises(ValueError, match="ki must be"):
        PID(1.0, np.eye(2), 1.0, np.zeros(2))
    with pytest.raises(ValueError, match="needs the robot's dynamics"):
        GravityCompensation(1.0, 1.0, np.zeros(2))(0.0, np.zeros(2), np.zeros(2))
    with pytest.raises(ValueError, match="tau_limit must be positive"):
        PD(1.0, 1.0, np.zeros(2), tau_limit=0.0)


def test_bad_lqr_requests(trolley):
    with pytest.raises(ValueError, match="actuated"):
        LQR.about(trolley, np.zeros(3), 1.0, 1.0, actuated=[0, 5])
    # tilted rods need a hinge torque to stay put: not an equilibrium with the trolley alone
    with pytest.raises(ValueError, match="not an equilibrium"):
        LQR.about(trolley, np.array([0.0, 0.3, 0.0]), 1.0, 1.0, actuated=[0])
    with pytest.raises(ValueError, match="K must be"):
        LQR(np.zeros((2, 2)), np.zeros(4), np.zeros(2))


def test_bad_trajectory_requests():
    with pytest.raises(ValueError, match="duration must be a positive"):
        quintic([0.0], [1.0], 0.0)
    with pytest.raises(ValueError, match="q1 must be"):
        quintic([0.0, 0.0], [1.0], 1.0)
    with pytest.raises(ValueError, match="strictly increasing"):
        via_points([[0.0], [1.0]], [0.0, 0.0])
    with pytest.raises(ValueError, match="unknown kind"):
        via_points([[0.0], [1.0]], [0.0, 1.0], kind="linear")
