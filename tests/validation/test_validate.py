"""``rd.validate`` against simulated ground truth and closed forms."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import robodyn as rd
from robodyn.measure.conversions import current_to_torque
from robodyn.measure.filtering import lowpass
from robodyn.validation import validate
from tests.validation.helpers import SLIDER_MASS, puma_run, recording, slider


@pytest.fixture(scope="module")
def puma():
    return puma_run()


def test_exact_model_predicts_simulated_torque_and_motion(puma):
    robot, model, sim = puma
    rec = recording(t=sim.t, q=sim.q, qd=sim.qd, qdd=sim.qdd, tau=sim.tau,
                    joint_names=robot.joint_names, source="sim")
    val = validate(robot, rec, model=model)
    assert val.target == "tau" and val.unit == "N m"
    # inverse dynamics reproduce the torque that produced the motion
    assert val.prediction.total_relative < 1e-12
    assert np.all(val.prediction.rms < 1e-10 * np.abs(sim.tau).max())
    assert val.moving.all()
    # windows replay the same held-torque RK4 steps from the measured state: no drift
    drift = val.simulation
    assert len(drift.starts) == 5 and drift.failed == 0
    assert drift.final.max() < 1e-9
    # ... while a constant-velocity guess drifts visibly
    assert drift.median_baseline.min() > 1e-4


def test_torque_scaled_by_a_known_factor_gives_that_relative_error(puma):
    robot, model, sim = puma
    rec = recording(t=sim.t, q=sim.q, qd=sim.qd, qdd=sim.qdd, tau=1.25 * sim.tau,
                    joint_names=robot.joint_names)
    val = validate(robot, rec, model=model, window=None)
    # ||tau - 1.25 tau|| / ||1.25 tau|| = 0.25 / 1.25
    np.testing.assert_allclose(val.prediction.relative, 0.2, rtol=1e-9)
    assert val.simulation is None


def test_current_target_uses_the_drive_gains(puma):
    robot, model, sim = puma
    ratio = np.array([float(j.drive.gear_ratio) for j in robot.joints])
    kt = np.array([float(j.drive.torque_constant) for j in robot.joints])
    assert np.any(ratio < 0)  # PUMA joints 1 and 3: motors turning against their joints
    # the motor current that robodyn.measure's conversion turns back into the joint torque
    current = sim.tau / (ratio * kt)
    np.testing.assert_allclose(current_to_torque(current, ratio, kt), sim.tau, rtol=1e-12)
    gains = ratio * kt
    rec = recording(t=sim.t, q=sim.q, qd=sim.qd, qdd=sim.qdd, current=current,
                    joint_names=robot.joint_names)
    val = validate(robot, rec, target="current", model=model, window=0.25)
    assert val.target == "current" and val.unit == "A"
    np.testing.assert_allclose(val.gains, gains)
    assert val.prediction.total_relative < 1e-12
    assert val.simulation.final.max() < 1e-9
    # explicit gains twice as large: the model then predicts half the current
    val2 = validate(robot, rec, target="current", model=model, gains=2 * gains, window=None)
    np.testing.assert_allclose(val2.prediction.relative, 0.5, rtol=1e-9)


def test_noise_floor_matches_added_noise_and_errors_against_filtered_are_smaller(puma):
    robot, model, sim = puma
    rng = np.random.default_rng(3)
    sigma = 0.05 * np.abs(sim.tau).std(axis=0)
    noisy = sim.tau + rng.normal(size=sim.tau.shape) * sigma
    rec = recording(t=sim.t, q=sim.q, qd=sim.qd, qdd=sim.qdd, tau=noisy,
                    joint_names=robot.joint_names)
    val = validate(robot, rec, model=model, window=None, noise_cutoff=10.0)
    assert val.noise.cutoff == 10.0
    # the filter removes the white noise above 10 Hz (98 % of its variance in a 500 Hz band) and
    # the clean torque's own content above 10 Hz (Coulomb friction steps at velocity reversals)
    clean_hf = sim.tau - lowpass(sim.t, sim.tau, val.noise.cutoff)
    added = np.mean((noisy - sim.tau) ** 2, axis=0)  # the realised noise power
    expected = np.sqrt(0.98 * added + np.mean(clean_hf**2, axis=0))
    np.testing.assert_allclose(val.noise.rms, expected, rtol=0.05)
    # the exact model's error is the noise itself
    np.testing.assert_allclose(val.prediction.rms, np.sqrt(added), rtol=1e-9)
    # against the filtered torque most of the noise is gone; what remains is the clean torque's
    # own content above 10 Hz, noise below 10 Hz and the filter's end effects
    assert np.all(val.prediction_filtered.rms < 0.9 * val.prediction.rms)
    assert np.all(val.prediction_filtered.rms[:3] < 0.4 * val.prediction.rms[:3])


def test_torque_bias_on_a_cart_drifts_by_half_b_over_m_t_squared(tmp_path):
    robot = slider(tmp_path)
    force, bias, dt = 3.0, 0.4, 1e-3
    t = np.arange(0.0, 1.0 + dt / 2, dt)
    # x(t) = x0 + v0 t + F t^2 / (2 m): the cart under a constant force
    acc = force / SLIDER_MASS
    q = (0.1 + 0.2 * t + 0.5 * acc * t**2)[:, None]
    qd = (0.2 + acc * t)[:, None]
    rec = recording(t=t, q=q, qd=qd, qdd=np.full_like(q, acc), tau=np.full_like(q, force + bias),
                    joint_names=("x",))
    val = validate(robot, rec, window=0.2)
    assert val.unit == "N m | N"
    np.testing.assert_allclose(val.prediction.relative, bias / (force + bias), rtol=1e-12)
    # RK4 integrates a constant acceleration exactly: drift = b T^2 / (2 m)
    np.testing.assert_allclose(val.simulation.final, 0.5 * bias / SLIDER_MASS * 0.2**2, rtol=1e-8)
    np.testing.assert_allclose(val.simulation.baseline_final, 0.5 * acc * 0.2**2, rtol=1e-8)
    # the cart has no friction: the data's friction cloud is the bias
    np.testing.assert_allclose(val.friction_data, bias, rtol=1e-12)
    np.testing.assert_array_equal(val.friction_model, 0.0)


def test_friction_curve_is_the_descriptions_friction(puma):
    robot, model, sim = puma
    rec = recording(t=sim.t, q=sim.q, qd=sim.qd, qdd=sim.qdd, tau=sim.tau,
                    joint_names=robot.joint_names)
    val = validate(robot, rec, model=model, window=None)
    # exact data: the cloud is the model's own friction at each sample
    from robodyn.validation.effort import friction_torque

    np.testing.assert_allclose(val.friction_data, friction_torque(robot, sim.qd), atol=1e-9)
    j = robot.joints[1]
    gear = float(j.drive.gear_ratio)
    # PUMA joint 2: motor-side Coulomb 0.126 N m reflected by the gear ratio 107.815
    top = val.friction_model[-1, 1] - float(j.friction.viscous) * val.friction_grid[-1, 1]
    assert top == pytest.approx(float(j.friction.coulomb_positive), rel=1e-12)
    assert float(j.friction.coulomb_positive) == pytest.approx(0.126 * abs(gear), rel=1e-6)


def test_joints_are_matched_by_name_and_input_is_not_modified(puma):
    robot, model, sim = puma
    order = [3, 0, 5, 1, 4, 2]
    names = tuple(robot.joint_names[k] for k in order)
    rec = recording(t=sim.t, q=sim.q[:, order], qd=sim.qd[:, order], qdd=sim.qdd[:, order],
                    tau=sim.tau[:, order], joint_names=names)
    before = rec.tau.copy()
    val = validate(robot, rec, model=model, window=None)
    assert val.joint_names == robot.joint_names
    assert val.prediction.total_relative < 1e-12
    np.testing.assert_array_equal(rec.tau, before)
    assert rec.joint_names == names


def test_joints_the_robot_lacks_are_left_out_with_a_note(tmp_path):
    robot = slider(tmp_path)
    t = np.arange(200) * 1e-3
    q = np.column_stack([0.1 * np.sin(2 * np.pi * t), 0.2 * t])
    qdd = np.column_stack([-0.1 * (2 * np.pi) ** 2 * np.sin(2 * np.pi * t), 0 * t])
    rec = recording(t=t, q=q, qdd=qdd, tau=SLIDER_MASS * qdd, joint_names=("finger", "x"))
    val = validate(robot, rec, window=None)
    assert val.joint_names == ("x",)
    assert any("left out of the recording: finger" in n for n in val.notes)
    np.testing.assert_allclose(val.measured[:, 0], rec.tau[:, 1])


def test_a_joint_without_a_sensor_and_a_joint_held_still(tmp_path, puma):
    robot, model, sim = puma
    tau = sim.tau.copy()
    tau[:, 0] = np.nan
    qd = sim.qd.copy()
    rec = recording(t=sim.t, q=sim.q, qd=qd, qdd=sim.qdd, tau=tau, joint_names=robot.joint_names)
    val = validate(robot, rec, model=model)
    assert np.isnan(val.prediction.relative[0]) and val.prediction.relative[1] < 1e-12
    assert val.simulation is None
    assert any("q1 has no tau measurement" in n for n in val.notes)
    assert any("simulation check skipped" in n for n in val.notes)


def test_irregular_time_stamps(tmp_path):
    robot = slider(tmp_path)
    rng = np.random.default_rng(4)
    t = np.cumsum(rng.uniform(0.010, 0.012, 300))
    w = 2 * np.pi * 0.8
    q = (0.3 * np.sin(w * t))[:, None]
    qd = (0.3 * w * np.cos(w * t))[:, None]
    qdd = (-0.3 * w**2 * np.sin(w * t))[:, None]
    rec = recording(t=t, q=q, qd=qd, qdd=qdd, tau=SLIDER_MASS * qdd, joint_names=("x",))
    val = validate(robot, rec, window=0.2)
    assert val.prediction.total_relative < 1e-12
    # torque linearly interpolated and held over 11 ms steps: a small but nonzero drift
    assert 0 < val.simulation.median_final[0] < 0.05 * val.simulation.median_baseline[0]


def test_default_target_and_public_export(puma):
    robot, model, sim = puma
    rec = recording(t=sim.t, q=sim.q, current=sim.tau, joint_names=robot.joint_names)
    assert rd.validate is validate and rd.Validation.__name__ == "Validation"
    val = validate(robot, rec, model=model, gains=np.ones(6), window=None)
    assert val.target == "current"
    assert val.estimated == frozenset({"qd", "qdd"})


def test_cutoff_evaluates_the_model_on_filtered_states(tmp_path):
    from robodyn.measure.filtering import differentiate

    robot = slider(tmp_path)
    dt = 1e-3
    t = np.arange(0.0, 2.0, dt)
    w = 2 * np.pi * 1.0
    rng = np.random.default_rng(6)
    q = (0.2 * np.sin(w * t) + rng.normal(scale=2e-5, size=t.size))[:, None]
    # raw second differences of noisy positions: the noise is amplified by 1/dt^2
    qdd_raw = np.gradient(np.gradient(q[:, 0], t), t)[:, None]
    tau = SLIDER_MASS * (-0.2 * w**2 * np.sin(w * t))[:, None]
    rec = recording(t=t, q=q, qd=np.gradient(q[:, 0], t)[:, None], qdd=qdd_raw, tau=tau,
                    joint_names=("x",))
    raw = validate(robot, rec, window=None)
    filt = validate(robot, rec, window=None, cutoff=5.0)
    np.testing.assert_array_equal(filt.qd, differentiate(t, q, 5.0)[1])
    assert raw.prediction.relative[0] > 1.0
    assert filt.prediction.relative[0] < 0.05
    # an identification result's filter is used when no cutoff is given
    ident = SimpleNamespace(target="tau", preprocess=SimpleNamespace(cutoff=5.0, velocity="position"),
                            predict=lambda r: np.zeros((t.size, 1)))
    via_ident = validate(robot, rec, window=None, ident=ident)
    np.testing.assert_array_equal(via_ident.qd, filt.qd)
    np.testing.assert_allclose(via_ident.prediction.relative, 1.0)
