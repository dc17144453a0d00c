"""Planned trajectories: boundary conditions, limits, via points, Cartesian lines."""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.simulation import (
    UnreachableError,
    cartesian_line,
    concatenate,
    quintic,
    trapezoidal,
    via_points,
)


def test_quintic_meets_its_boundary_conditions_exactly():
    q0, q1 = np.array([0.1, -0.4, 2.0]), np.array([1.3, 0.2, -1.0])
    plan = quintic(q0, q1, 1.7, dt=1e-3)
    start, end = plan.at(0.0), plan.at(1.7)
    np.testing.assert_allclose(start[0], q0, atol=1e-14)
    np.testing.assert_allclose(end[0], q1, atol=1e-13)
    for arr in (*start[1:], *end[1:]):
        np.testing.assert_allclose(arr, 0.0, atol=1e-12)
    np.testing.assert_allclose(plan.q[-1], q1, atol=1e-13)
    # general end velocities and accelerations
    v0, v1, a0, a1 = np.array([0.5, 0, -1]), np.array([-0.2, 1, 0]), np.array([1, 2, 3]), np.array([0, -1, 4])
    plan = quintic(q0, q1, 2.0, qd0=v0, qd1=v1, qdd0=a0, qdd1=a1)
    for got, want in zip(plan.at(0.0) + plan.at(2.0 - 1e-15), (q0, v0, a0, q1, v1, a1), strict=True):
        np.testing.assert_allclose(got, want, atol=1e-10)
    # derivatives are consistent with the positions
    mid = plan.t[1:-1]
    num = (plan.at(mid + 1e-6)[0] - plan.at(mid - 1e-6)[0]) / 2e-6
    np.testing.assert_allclose(num, plan.at(mid)[1], atol=1e-6)
    # held at rest outside [0, T]
    q, qd, qdd = plan.at(np.array([-1.0, 5.0]))
    np.testing.assert_allclose(q, [q0, q1], atol=1e-12)
    assert np.all(qd == 0) and np.all(qdd == 0)


@pytest.mark.parametrize("q1", [[1.0, -2.0, 0.5], [0.01, -0.02, 0.0]])  # trapezoid and triangle
def test_trapezoidal_never_exceeds_its_limits(q1):
    q0, q1 = np.zeros(3), np.array(q1)
    vmax, amax = np.array([1.0, 0.8, 2.0]), np.array([2.0, 3.0, 1.0])
    plan = trapezoidal(q0, q1, vmax, amax, dt=1e-4)
    np.testing.assert_allclose(plan.q[0], q0, atol=1e-15)
    np.testing.assert_allclose(plan.q[-1], q1, atol=1e-12)
    assert np.all(np.abs(plan.qd) <= vmax * (1 + 1e-12))
    assert np.all(np.abs(plan.qdd) <= amax * (1 + 1e-12))
    # the binding joint reaches a limit: the move is time-optimal along the joint-space line
    assert np.any(np.isclose(np.abs(plan.qdd).max(axis=0), amax, rtol=1e-9))
    np.testing.assert_allclose(plan.at(plan.duration)[1], 0.0, atol=1e-12)
    # all joints move along the same straight line in joint space
    s = plan.q[:, 0] / q1[0]
    np.testing.assert_allclose(plan.q, np.outer(s, q1), atol=1e-12)
    # stretched to a longer time: still within limits, ends on time
    slow = trapezoidal(q0, q1, vmax, amax, duration=2 * plan.duration)
    assert slow.duration == pytest.approx(2 * plan.duration)
    np.testing.assert_allclose(slow.q[-1], q1, atol=1e-12)
    assert np.all(np.abs(slow.qd) <= vmax * (1 + 1e-12))
    with pytest.raises(ValueError, match="shorter than the minimum"):
        trapezoidal(q0, q1, vmax, amax, duration=0.5 * plan.duration)


@pytest.mark.parametrize("kind", ["quintic", "cubic"])
def test_via_points_pass_through_their_points_and_start_and_end_at_rest(kind):
    pts = np.array([[0.0, 0.0], [0.5, 1.0], [1.2, 0.4], [0.8, -0.3]])
    times = np.array([0.0, 1.0, 1.8, 3.0])
    plan = via_points(pts, times, kind=kind)
    for p, tk in zip(pts, times, strict=True):
        np.testing.assert_allclose(plan.at(tk)[0], p, atol=1e-12)
    for tk in (0.0, 3.0 - 1e-15):
        np.testing.assert_allclose(plan.at(tk)[1], 0.0, atol=1e-9)
    if kind == "quintic":
        np.testing.assert_allclose(plan.at(0.0)[2], 0.0, atol=1e-9)
    # continuous accelerations (C2 for both kinds)
    jumps = [np.abs(plan.at(tk + 1e-9)[2] - plan.at(tk - 1e-9)[2]).max() for tk in times[1:-1]]
    assert max(jumps) < 1e-5


def test_concatenate_joins_parts_in_time():
    a = quintic([0.0, 0.0], [1.0, 0.5], 1.0)
    b = trapezoidal([1.0, 0.5], [0.0, 0.0], 1.0, 2.0)
    both = concatenate(a, b)
    assert both.duration == pytest.approx(a.duration + b.duration)
    np.testing.assert_allclose(both.at(0.5)[0], a.at(0.5)[0], atol=1e-12)
    np.testing.assert_allclose(both.at(1.0 + 0.3)[0], b.at(0.3)[0], atol=1e-12)
    np.testing.assert_allclose(both.q[-1], [0.0, 0.0], atol=1e-12)
    with pytest.raises(ValueError, match="starts"):
        concatenate(a, quintic([0.0, 0.0], [1.0, 1.0], 1.0))


def test_cartesian_line_keeps_the_tool_on_the_segment(aa300, puma):
    # AA300, position only: 0.1 m radially out, then straight up
    q0 = np.array([0.0, 0.78, 1.93])
    p0 = aa300.forward_kinematics(q0)[:3, 3]
    goal = p0 + np.array([0.017, -0.098, 0.0])
    plan = cartesian_line(aa300, q0, goal, 1.5)
    tool = aa300.forward_kinematics(plan.q)[:, :3, 3]
    u = (goal - p0) / np.linalg.norm(goal - p0)
    d = tool - p0
    off = np.linalg.norm(d - np.outer(d @ u, u), axis=1)
    assert off.max() < 1e-9  # measured 1e-11 between knots
    np.testing.assert_allclose(tool[-1], goal, atol=1e-9)
    np.testing.assert_allclose(plan.qd[[0, -1]], 0.0, atol=1e-9)
    # PUMA, full pose: position along the line and orientation turning about one axis
    q = np.array([0.2, 0.6, -0.9, 0.3, 0.7, -0.2])
    start = puma.forward_kinematics(q)
    goal = start.copy()
    goal[:3, 3] += [-0.1, 0.05, -0.08]
    plan = cartesian_line(puma, q, goal, 1.0, knots=101)
    poses = puma.forward_kinematics(plan.q)
    np.testing.assert_allclose(poses[-1], goal, atol=1e-9)
    # the orientation does not change
    np.testing.assert_allclose(poses[:, :3, :3], np.broadcast_to(start[:3, :3], (plan.t.size, 3, 3)),
                               atol=1e-9)
    with pytest.raises(UnreachableError, match="leaves the reachable workspace"):
        cartesian_line(aa300, q0, p0 + np.array([0.0, -0.5, 0.0]), 1.0)
