"""The demo's Kinova Gen3 section and validation on the real Gen3 recordings."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import robodyn as rd
from robodyn.report.identification_report import KINOVA_CONTROLLER_GAINS, kinova_section

DATA = Path(__file__).resolve().parents[3] / "shared" / "data" / "kinova-gen3"
JOINT2 = DATA / "jointwise_motion" / "joint_2_trapez.csv.gz"


def test_kinova_section_says_so_when_the_data_are_absent(tmp_path):
    html, ok = kinova_section(tmp_path, data_dir=tmp_path / "nowhere")
    assert ok
    assert "were not found" in html and "nowhere" in html


@pytest.mark.data(JOINT2)
def test_manufacturer_model_on_the_joint_2_run():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("kinova_gen3")
    rec = rd.read_recording(JOINT2, spec="kinova_gen3", robot=robot)
    model = rd.compile_model(robot)
    # noise separated at 10 Hz here: the 2.5 Hz reference filter (the default) also smooths the
    # trapezoid's acceleration steps (joint 2 floor 0.21 there)
    val = rd.validate(robot, rec, "current", model=model, gains=KINOVA_CONTROLLER_GAINS,
                      noise_cutoff=10.0)
    assert val.noise.cutoff == 10.0
    # only joint 2 moves in this run; the others are held by the controller
    np.testing.assert_array_equal(val.moving, [False, True, False, False, False, False, False])
    assert val.estimated == frozenset({"qdd"})
    # joint 2's current is smooth (a slow trapezoid against gravity): little of it is noise
    assert val.noise.relative[1] < 0.15
    windows = int(np.floor((rec.t[-1] - rec.t[0]) / val.simulation.dt / 200 + 1e-9))
    assert len(val.simulation.starts) == windows
    # the same data as joint torque k i: the same relative errors, in N m
    as_tau = rd.Recording(t=rec.t, q=rec.q, qd=rec.qd, qdd=rec.qdd,
                          tau=rec.current * KINOVA_CONTROLLER_GAINS, joint_names=rec.joint_names)
    val_tau = rd.validate(robot, as_tau, "tau", model=model, window=None)
    np.testing.assert_allclose(val_tau.prediction.relative, val.prediction.relative, rtol=1e-9)
    np.testing.assert_allclose(val_tau.prediction.rms, val.prediction.rms * KINOVA_CONTROLLER_GAINS,
                               rtol=1e-9)


def test_gravity_scale_is_one_for_the_same_model_and_nan_without_gravity_load():
    from robodyn.report.identification_report import _gravity_scale

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = rd.compile_model(rd.load("puma560"))
    q = np.random.default_rng(5).uniform(-2, 2, (50, 6))
    scale = _gravity_scale(model, model, q)
    # joint 1 turns about the vertical: no gravity load to scale
    assert np.isnan(scale[0])
    np.testing.assert_allclose(scale[1:3], 1.0, rtol=1e-12)


def test_figures_of_a_joint_without_a_sensor_raise_no_warning(tmp_path):
    from robodyn.validation.figures import validation_figures
    from tests.validation.helpers import puma_run, recording

    robot, model, sim = puma_run(duration=0.5)
    tau = sim.tau.copy()
    tau[:, 0] = np.nan  # joint 1 has no torque sensor
    rec = recording(t=sim.t, q=sim.q, qd=sim.qd, tau=tau, joint_names=robot.joint_names)
    val = rd.validate(robot, rec, "tau", model=model)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # before: "All-NaN slice encountered" from the histogram
        paths = validation_figures(val, tmp_path, "run")
    assert paths and all(Path(p).stat().st_size > 1000 for p in paths.values())
