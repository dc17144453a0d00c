"""Circle-point analysis: circles, lines, joint axes from one-joint-at-a-time data, S-model."""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.calibration import calibrate, circle_point, robot_geometry, validate
from robodyn.calibration.joint_axes import fit_circle, fit_line, joint_axis
from robodyn.calibration.kinematics import rot, trans
from robodyn.studies.calibration_study import HOME, circle_sets, perturbed_robot, robot_positions
from tests.calibration.helpers import TARGET, TRACKER, poses, robot


def _circle(center, normal, radius, angles):
    normal = normal / np.linalg.norm(normal)
    e1 = np.cross(normal, [0.3, 0.5, 0.8])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    return center + radius * (np.cos(angles)[:, None] * e1 + np.sin(angles)[:, None] * e2)


def test_circle_fit_exact_and_at_noise_level():
    c, n, rad = np.array([0.3, -0.2, 1.1]), np.array([0.2, -0.4, 0.9]), 0.35
    n = n / np.linalg.norm(n)
    angles = np.linspace(-1.2, 0.9, 15)  # a partial arc
    exact = fit_circle(_circle(c, n, rad, angles))
    np.testing.assert_allclose(exact.center, c, atol=1e-12)
    assert abs(abs(exact.normal @ n) - 1) < 1e-14
    assert exact.radius == pytest.approx(rad, abs=1e-12)
    sigma = 5e-5
    rng = np.random.default_rng(0)
    errors = []
    for _ in range(50):
        f = fit_circle(_circle(c, n, rad, angles) + rng.normal(0, sigma, (15, 3)))
        errors.append((np.linalg.norm(f.center - c), np.arccos(min(1, abs(f.normal @ n))),
                       abs(f.radius - rad), f.rms))
    errors = np.array(errors)
    # centre and radius to a few sigma, the normal to a few sigma / radius, residual ~ sigma
    assert np.sqrt(np.mean(errors[:, 0] ** 2)) < 5 * sigma
    assert np.sqrt(np.mean(errors[:, 1] ** 2)) < 5 * sigma / rad
    assert np.sqrt(np.mean(errors[:, 2] ** 2)) < 3 * sigma
    assert 0.5 * sigma < np.mean(errors[:, 3]) < 1.7 * sigma


def test_line_fit_recovers_a_line():
    rng = np.random.default_rng(1)
    u = np.array([0.1, 0.7, -0.2])
    u /= np.linalg.norm(u)
    pts = np.array([0.5, 0.1, 0.2]) + np.linspace(0, 0.8, 20)[:, None] * u
    c, d, rms = fit_line(pts + rng.normal(0, 1e-5, pts.shape))
    assert abs(abs(d @ u) - 1) < 1e-8
    assert np.linalg.norm(np.cross(c - pts[0], u)) < 1e-5
    assert rms < 2e-5


def test_joint_axis_direction_follows_the_readings():
    center, n = np.array([0.0, 0.0, 0.5]), np.array([0.0, 0.0, 1.0])
    q = np.linspace(0, 1.5, 10)
    ax = joint_axis(q, _circle(center, n, 0.2, 0.3 + q), "revolute")
    np.testing.assert_allclose(ax.direction, n, atol=1e-12)
    assert ax.scale == pytest.approx(1.0, abs=1e-12)
    ax = joint_axis(q, _circle(center, n, 0.2, 0.3 - q), "revolute")
    np.testing.assert_allclose(ax.direction, -n, atol=1e-12)
    pts = np.array([0.1, 0.2, 0.3]) - q[:, None] * np.array([0.0, 1.0, 0.0])
    ax = joint_axis(q, pts, "prismatic")
    np.testing.assert_allclose(ax.direction, [0, -1, 0], atol=1e-12)


def _true_axes(true):
    g = robot_geometry(true)
    return g.points, g.directions


@pytest.mark.parametrize("sigma", (0.0, 5e-5))
def test_axes_of_a_perturbed_puma_are_recovered(sigma):
    r = robot("puma560")
    true = perturbed_robot(r, 3, base=TRACKER, target=TARGET)
    sets = circle_sets(true, HOME, np.random.default_rng(4), sigma, count=16)
    cp = circle_point(robot_geometry(r), sets)
    points, dirs = _true_axes(true)
    angle = np.linalg.norm(np.cross(cp.directions, dirs), axis=1)  # sine of the angle
    assert np.all(np.sum(cp.directions * dirs, axis=1) > 0)  # same sense
    dist = np.linalg.norm(np.cross(cp.points - points, dirs), axis=1)
    if sigma == 0:
        assert angle.max() < 1e-9 and dist.max() < 1e-9
        np.testing.assert_allclose(cp.target, robot_positions(true, np.zeros((1, 6)))[0], atol=1e-9)
    else:
        # noise level: sigma over the circle radius (the wrist circles are a few cm)
        radii = np.array([a.radius for a in cp.axes])
        assert np.all(angle < 10 * sigma / radii)
        assert dist.max() < 2e-3


def test_s_model_frames_lie_on_the_axes_at_the_circle_centres():
    r = robot("puma560")
    true = perturbed_robot(r, 3, base=TRACKER, target=TARGET)
    cp = circle_point(robot_geometry(r), circle_sets(true, HOME, np.random.default_rng(4), 0.0))
    for i in range(r.dof):
        f = cp.s_frames[i]
        np.testing.assert_allclose(f[:3, 2], cp.directions[i], atol=1e-12)
        np.testing.assert_allclose(f[:3, 3], cp.centres[i], atol=1e-12)
    assert {"q2.beta_y", "q2.b", "q2.beta", "q3.d"} <= set(cp.s_model)


def test_calibration_from_the_circle_point_estimate():
    r = robot("puma560")
    true = perturbed_robot(r, 6, base=TRACKER @ rot("z", 2.0), target=TARGET)
    rng = np.random.default_rng(7)
    sets = circle_sets(true, HOME, rng, 5e-5)
    q, q_test = poses("puma560", 60, 8), poses("puma560", 50, 9)
    y = robot_positions(true, q) + rng.normal(0, 5e-5, (60, 3))
    cal = calibrate(r, q, y, "s-model", initial="circle-point", circle_data=sets)
    assert cal.circle_point is not None
    start = np.linalg.norm(y - cal.model.evaluate(cal.model.initial, q, derivatives=False).position, axis=1)
    assert np.sqrt(np.mean(start**2)) < 0.2 * cal.before.rms  # a far better start than nominal
    assert validate(cal, q_test, robot_positions(true, q_test)).rms < 5e-5


def test_a_joint_that_never_moved_is_an_error():
    r = robot("puma560")
    true = perturbed_robot(r, 3, base=TRACKER, target=TARGET)
    sets = circle_sets(true, HOME, np.random.default_rng(4), 0.0)
    q3, p3 = sets[2]
    sets[2] = (np.tile(q3[0], (len(q3), 1)), np.tile(p3[0], (len(p3), 1)))
    with pytest.raises(ValueError, match=r"set 2 \(q3\): the joint never moved"):
        circle_point(robot_geometry(r), sets)


def test_a_set_that_moves_two_joints_is_an_error():
    r = robot("puma560")
    true = perturbed_robot(r, 3, base=TRACKER, target=TARGET)
    sets = circle_sets(true, HOME, np.random.default_rng(4), 0.0)
    q1, p1 = sets[0]
    q1 = q1.copy()
    q1[:, 1] += np.linspace(0, 0.1, len(q1))
    sets[0] = (q1, robot_positions(true, q1))
    with pytest.raises(ValueError, match="also moves q2"):
        circle_point(robot_geometry(r), sets)


def test_a_target_on_the_axis_is_an_error():
    q = np.linspace(0, 1, 8)
    pts = np.array([0.0, 0.0, 1.0]) + 1e-12 * np.random.default_rng(0).normal(size=(8, 3))
    with pytest.raises(ValueError, match="collinear|too close"):
        joint_axis(q, pts, "revolute", "q6")


def test_wrong_number_of_sets_is_an_error():
    with pytest.raises(ValueError, match="one data set per joint"):
        circle_point(robot_geometry(robot("puma560")), [(np.zeros((3, 6)), np.zeros((3, 3)))])


def test_registration_places_nominal_axes_on_measured_ones():
    r = robot("puma560")
    g = robot_geometry(r)
    x = trans(1.0, 2.0, -0.5) @ rot("z", 1.0) @ rot("y", 0.2)
    from robodyn.calibration.joint_axes import register_lines

    pts = g.points @ x[:3, :3].T + x[:3, 3]
    dirs = g.directions @ x[:3, :3].T
    est = register_lines(g.points, g.directions, pts, dirs, g.target[:3, 3], x[:3, :3] @ g.target[:3, 3]
                         + x[:3, 3])
    np.testing.assert_allclose(est, x, atol=1e-9)


def _sets(true, sweeps, counts, scale=None):
    """One set per joint: joint j sweeps HOME[j] +- sweeps[j] in counts[j] readings."""
    out = []
    for j in range(true.dof):
        qs = np.tile(HOME, (counts[j], 1))
        qs[:, j] = HOME[j] + np.linspace(-sweeps[j], sweeps[j], counts[j])
        pts = robot_positions(true, qs)
        if scale is not None and j == scale[0]:
            qs[:, j] *= scale[1]  # readings of another scale than the arc
        out.append((qs, pts))
    return out


@pytest.mark.parametrize(("sweep6", "count6"), [(np.radians(200), 20),  # 400 deg, 21 deg steps
                                                (2 * np.pi, 4),  # 720 deg in 240 deg steps
                                                (np.radians(500), 7)])  # 1000 deg
def test_multi_turn_sweeps_give_the_axes(sweep6, count6):
    r = robot("puma560")
    true = perturbed_robot(r, 3, base=TRACKER, target=TARGET)
    sweeps, counts = [1.0, 1.0, 1.0, np.radians(200), 1.0, sweep6], [12, 12, 12, 16, 12, count6]
    cp = circle_point(robot_geometry(r), _sets(true, sweeps, counts))
    points, dirs = _true_axes(true)
    assert np.all(np.sum(cp.directions * dirs, axis=1) > 0)
    assert np.linalg.norm(np.cross(cp.directions, dirs), axis=1).max() < 1e-9
    assert np.linalg.norm(np.cross(cp.points - points, dirs), axis=1).max() < 1e-9
    assert all(a.scale == pytest.approx(1.0, abs=1e-9) for a in cp.axes)


def test_multi_turn_readings_as_given_and_wrapped_agree():
    r = robot("puma560")
    true = perturbed_robot(r, 3, base=TRACKER, target=TARGET)
    sets = _sets(true, [1.0, 1.0, 1.0, 1.0, 1.0, np.radians(200)], [12] * 5 + [15])
    wrapped = list(sets)
    q6 = sets[5][0].copy()
    q6[:, 5] = np.angle(np.exp(1j * q6[:, 5]))  # a controller that reports (-180, 180] deg
    wrapped[5] = (q6, sets[5][1])
    a, b = circle_point(robot_geometry(r), sets), circle_point(robot_geometry(r), wrapped)
    np.testing.assert_allclose(a.directions, b.directions, atol=1e-12)
    np.testing.assert_allclose(a.points, b.points, atol=1e-12)


def test_sparse_sweep_whose_readings_do_not_follow_says_what_to_do():
    r = robot("puma560")
    true = perturbed_robot(r, 3, base=TRACKER, target=TARGET)
    # q6 turns 720 deg in 240 deg steps but its readings are 1.3 times the arc (a wrong gear ratio)
    sets = _sets(true, [1.0] * 5 + [2 * np.pi], [12] * 5 + [4], scale=(5, 1.3))
    with pytest.raises(ValueError, match=r"set 5 \(q6\).*readings are up to 312 deg apart.*"
                                         r"measure the sweep in steps under 180 deg"):
        circle_point(robot_geometry(r), sets)
