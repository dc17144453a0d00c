"""The ready-made study tasks, run in this process against independent references."""

from __future__ import annotations

import pytest

from robodyn.robot.errors import StudyError
from robodyn.studies.aa300 import run_study
from robodyn.studies.calibration_mc import CalibrationMonteCarlo
from robodyn.studies.models import RobotSource
from robodyn.studies.sizing import ActuatorSizing


def test_aa300_sizing_case_reproduces_the_design_study():
    # one sweep case = the AA300 design study of robodyn.studies.aa300, number for number
    task = ActuatorSizing(RobotSource.of("aa300"))
    for gravity in (True, False):
        result = task({"payload": 50.0, "gravity_compensation": gravity})
        study = run_study(payload=50.0, animate=False, gravity_compensation=gravity)
        for d, err in zip(study.demands, study.max_tracking_error, strict=True):
            assert result[f"peak_torque.{d.joint}"] == d.peak
            assert result[f"rms_torque.{d.joint}"] == d.rms
            assert result[f"peak_ideal_torque.{d.joint}"] == d.peak_ideal
            assert result[f"peak_speed.{d.joint}"] == d.peak_speed
            assert result[f"peak_power.{d.joint}"] == d.peak_power
            assert result[f"tracking_error.{d.joint}"] == err


def test_sizing_refuses_unknown_parameters_and_the_wrong_robot():
    task = ActuatorSizing(RobotSource.of("aa300"))
    with pytest.raises(StudyError, match="unknown parameter 'payload_kg' for actuator sizing of aa300"):
        task({"payload_kg": 1.0})
    with pytest.raises(StudyError, match="'aa300_cycle' plans the AA300's cycle; planar_2r is not"):
        ActuatorSizing(RobotSource.of("planar_2r"))({})
    with pytest.raises(StudyError, match="trapezoid needs q_start, q_goal, vmax and amax"):
        ActuatorSizing(RobotSource.of("planar_2r"), trajectory="trapezoid", q_start=(0.0, 0.0))


@pytest.mark.slow
def test_calibration_monte_carlo_recovers_the_true_robot_without_noise():
    task = CalibrationMonteCarlo(n_test=40)
    clean = task({"seed": 5, "sigma": 1e-9, "n_poses": 30, "model": "s-model"})
    # random 1 mm / 0.1 deg errors put the nominal model millimetres off; the S-model represents
    # them exactly, so noise-free data recovers the truth
    assert clean["nominal_rms_true"] > 1e-3
    assert clean["heldout_rms_true"] < 1e-7
    noisy = task({"seed": 5, "sigma": 1e-4, "n_poses": 30, "model": "s-model"})
    assert 1e-5 < noisy["heldout_rms_true"] < 1e-3
    assert task({"seed": 5, "sigma": 1e-4, "n_poses": 30, "model": "s-model"}) == noisy  # seeded
    with pytest.raises(StudyError, match="unknown parameter 'noise'"):
        task({"seed": 1, "noise": 1e-4})
