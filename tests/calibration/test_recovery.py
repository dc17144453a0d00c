"""Noise-free synthetic data: identifiable parameters recovered, held-out errors at round-off."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import robodyn as rd
from robodyn.calibration import MODELS, calibrate, validate
from robodyn.calibration.models import model_frames
from robodyn.studies.calibration_study import perturbed_robot, robot_positions
from tests.calibration.helpers import TARGET, TRACKER, in_model_truth, poses, robot, symbolic_fk

PARAM_TOL = 1e-8  # m, rad
HELD_OUT_TOL = 1e-9  # m (1e-6 mm)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("name", ("puma560", "kinova_gen3"))
def test_every_identifiable_parameter_is_recovered(name, model):
    q, q_test = poses(name, 80, 1), poses(name, 40, 2)
    truth, p_true, points = in_model_truth(name, model, q, seed=3)
    cal = calibrate(robot(name), q, points, model)
    assert cal.converged
    if model == "poe":
        # the POE twists are written in frame 0 of the estimated placement: compare the
        # geometry they describe (joint axes at zero readings and the target, instrument frame)
        _, motion, target = model_frames(truth, p_true)
        points_c, dirs_c = cal.axes()
        np.testing.assert_allclose(dirs_c, motion[:, :3, 2], atol=PARAM_TOL)
        offsets = np.cross(points_c - motion[:, :3, 3], dirs_c)  # distance between the lines
        np.testing.assert_allclose(offsets, 0, atol=PARAM_TOL)
        np.testing.assert_allclose(cal.target(), target[:3, 3], atol=PARAM_TOL)
    else:
        for par in cal.parameters:
            if not par.name.startswith("base"):
                assert par.value == pytest.approx(p_true[truth.index(par.name)], abs=PARAM_TOL), par.name
        # base parameters are small rotations about the estimated initial orientation: compare
        # the instrument-to-base transform they describe
        true_base = model_frames(truth, p_true)[0] @ truth.base_to_robot
        np.testing.assert_allclose(cal.base(), true_base, atol=PARAM_TOL)
    held = validate(cal, q_test, truth.evaluate(p_true, q_test, derivatives=False).position)
    assert held.max < HELD_OUT_TOL
    assert cal.after.max < HELD_OUT_TOL


@pytest.mark.parametrize("model", ("hayati", "s-model", "poe"))
def test_generic_manufacturing_errors_are_absorbed_by_complete_models(model):
    # errors drawn outside any error model (random rigid errors of every joint placement and
    # zero offsets); data from the symbolic forward kinematics of the true robot
    r = robot("puma560")
    true = perturbed_robot(r, 11, base=TRACKER, target=TARGET, length_error=2e-3)
    fk = symbolic_fk(true)
    q, q_test = poses("puma560", 40, 12), poses("puma560", 8, 13)
    cal = calibrate(r, q, fk(q)[:, :3, 3], model)
    assert cal.before.rms > 1e-3  # millimetres before
    assert validate(cal, q_test, fk(q_test)[:, :3, 3]).max < HELD_OUT_TOL


@pytest.mark.parametrize("model", ("hayati", "s-model", "poe"))
def test_prismatic_joint_robot_is_calibrated_exactly(model):
    # AA300: revolute column, prismatic upper arm, revolute tube, all axes parallel
    r = robot("aa300")
    true = perturbed_robot(r, 5, base=TRACKER, target=TARGET)
    q, q_test = poses("aa300", 40, 1), poses("aa300", 20, 2)
    cal = calibrate(r, q, robot_positions(true, q), model)
    assert validate(cal, q_test, robot_positions(true, q_test)).max < HELD_OUT_TOL


def test_standard_dh_cannot_absorb_a_tilt_at_parallel_joints():
    # the documented limitation: a true joint 3 axis tilted about the axis perpendicular to the
    # common normal of joints 2 and 3 (a Hayati beta) is out of reach of DH from the nominal model
    q, q_test = poses("puma560", 80, 1), poses("puma560", 40, 2)
    truth, p_true, points = in_model_truth("puma560", "hayati", q, seed=3)
    p_true[truth.index("q2.beta")] += np.radians(0.1)
    points = truth.evaluate(p_true, q, derivatives=False).position
    test_points = truth.evaluate(p_true, q_test, derivatives=False).position
    dh = calibrate(robot("puma560"), q, points, "dh")
    hayati = calibrate(robot("puma560"), q, points, "hayati")
    assert validate(hayati, q_test, test_points).max < HELD_OUT_TOL
    assert validate(dh, q_test, test_points).rms > 1e-5


def test_calibrated_robot_reproduces_the_model_and_loads_back():
    r = robot("puma560")
    q = poses("puma560", 60, 1)
    truth, p_true, points = in_model_truth("puma560", "s-model", q, seed=4)
    cal = calibrate(r, q, points, "s-model")
    q_check = poses("puma560", 6, 9)
    expected = truth.evaluate(p_true, q_check, derivatives=False).position
    np.testing.assert_allclose(symbolic_fk(cal.robot)(q_check)[:, :3, 3], expected, atol=1e-12)
    # the links, drives and friction are the nominal robot's
    assert cal.robot.links == r.links
    assert [j.drive for j in cal.robot.joints] == [j.drive for j in r.joints]
    assert [j.friction for j in cal.robot.joints] == [j.friction for j in r.joints]
    # each link keeps its place on its joint's frame: post transforms unchanged
    for jc, jn in zip(cal.robot.joints, r.joints, strict=True):
        np.testing.assert_allclose(np.array(jc.post, dtype=float), np.array(jn.post.evalf(), dtype=float),
                                   atol=1e-15)


@pytest.mark.slow
def test_compiled_model_of_the_calibrated_robot_predicts_the_points():
    # the contract: compile_model(result.robot).forward_kinematics(q)[..., :3, 3]
    r = robot("puma560")
    true = perturbed_robot(r, 2, base=TRACKER, target=TARGET)
    q = poses("puma560", 50, 3)
    points = robot_positions(true, q)
    cal = calibrate(r, q, points, "hayati")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = rd.compile_model(cal.robot, backend="numpy")
    np.testing.assert_allclose(model.forward_kinematics(q)[..., :3, 3], points, atol=1e-9)
