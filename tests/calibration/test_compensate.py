"""Compensation: corrected joint targets from the calibrated model."""

from __future__ import annotations

import numpy as np

from robodyn.calibration import build_model, calibrate, compensate, robot_geometry
from robodyn.calibration.compensation import readings_for_points
from robodyn.studies.calibration_study import perturbed_robot, robot_positions
from tests.calibration.helpers import TARGET, TRACKER, poses, robot


def test_corrected_joint_targets_reach_the_desired_points_on_the_true_robot():
    r = robot("puma560")
    true = perturbed_robot(r, 21, base=TRACKER, target=TARGET)
    q = poses("puma560", 60, 22)
    cal = calibrate(r, q, robot_positions(true, q), "hayati")
    q_goal = poses("puma560", 20, 23)
    desired = robot_positions(true, q_goal)
    # the joint targets the nominal kinematics (placed in the tracker frame) would command
    nominal = build_model("dh", robot_geometry(cal.before_robot))
    q_nominal = readings_for_points(nominal, nominal.initial, desired, q_goal)
    nominal_error = np.linalg.norm(robot_positions(true, q_nominal) - desired, axis=1)
    q_corrected = compensate(cal, desired, q_nominal)
    np.testing.assert_allclose(cal.predict(q_corrected), desired, atol=1e-10)
    corrected_error = np.linalg.norm(robot_positions(true, q_corrected) - desired, axis=1)
    assert nominal_error.mean() > 1e-3  # millimetres with the nominal kinematics
    assert corrected_error.max() < 1e-8  # exact model, noise-free data


def test_points_in_the_robot_base_frame():
    r = robot("puma560")
    true = perturbed_robot(r, 24, base=TRACKER, target=TARGET)
    q = poses("puma560", 60, 25)
    cal = calibrate(r, q, robot_positions(true, q), "poe")
    q_goal = poses("puma560", 5, 26)
    in_instrument = cal.predict(q_goal)
    base = cal.base()
    in_base = (in_instrument - base[:3, 3]) @ base[:3, :3]
    q_c = compensate(cal, in_base, q_goal + 0.01, frame="base")
    np.testing.assert_allclose(cal.predict(q_c), in_instrument, atol=1e-10)
