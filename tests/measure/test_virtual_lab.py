"""Virtual laboratory: sensors against the simulator's exact values and hand-computed models."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.studies.testprog import jointwise
from robodyn.studies.virtual_lab import Sensors, virtual_lab

IDEAL = Sensors(jitter=0.0, counts_per_rev=0.0, current_noise=0.0, current_offset=0.0,
                torque_constant_error=0.0, torque_noise=0.0, tracker_noise=0.0, tracker_latency=0.005)


@pytest.fixture(scope="module")
def program(puma):
    return jointwise(puma, joints=["q2"], speeds=(1.0,), dwell=0.2)


@pytest.fixture(scope="module")
def ideal(puma, program):
    return virtual_lab(puma, program, sensors=IDEAL)


@pytest.fixture(scope="module")
def real(puma, program):
    return virtual_lab(puma, program, seed=1)


def test_ideal_sensors_measure_the_truth(puma, ideal):
    rec, tr = ideal.recording, ideal.truth
    assert np.array_equal(rec.t, tr.t) and np.array_equal(tr.t_actual, tr.t)
    assert np.allclose(rec.q, tr.q, atol=1e-15)
    assert np.allclose(rec.tau, tr.tau, atol=1e-12)
    # current = tau / (G k_t), signed gear ratio, from the PUMA description
    g = np.array([-62.6111, 107.815, -53.7063, 76.0364, 71.923, 76.686])
    kt = np.array([0.223, 0.226, 0.240, 0.069, 0.072, 0.066])
    assert np.allclose(tr.drive_gain, g * kt, rtol=1e-12)
    assert np.allclose(rec.current, tr.tau / (g * kt), atol=1e-12)
    # the tracker lags 5 ms: its point at t is the exact tool position at t - 5 ms
    k = np.arange(1, rec.tool_t.size)
    lagged = np.searchsorted(tr.t, rec.tool_t[k] - 0.005 - 1e-12)
    assert np.allclose(rec.tool_points[k], puma.forward_kinematics(tr.q[lagged])[:, :3, 3], atol=1e-12)
    # the controller tracks the program
    assert np.max(np.abs(tr.q - tr.reference.at(tr.t)[0])) < 0.02


def test_encoder_quantisation(puma, program):
    sens = Sensors(jitter=0.0, counts_per_rev=1000.0)
    run = virtual_lab(puma, program, sensors=sens)
    step = 2 * np.pi / (np.abs([-62.6111, 107.815, -53.7063, 76.0364, 71.923, 76.686]) * 1000.0)
    err = run.recording.q - run.truth.q
    assert np.all(np.abs(err) <= step / 2 + 1e-15)
    counts = run.recording.q / step
    assert np.allclose(counts, np.round(counts), atol=1e-6)
    # quantisation error is roughly uniform on a moving joint: std step / sqrt(12)
    assert np.std(err[:, 1]) == pytest.approx(step[1] / np.sqrt(12), rel=0.2)


def test_noise_offset_and_gain_error(puma, program, real):
    run = virtual_lab(puma, program, sensors=Sensors(jitter=0.0), seed=1)
    rec, tr, s = run.recording, run.truth, run.sensors
    # the drawn gains differ from the nominal ones by the torque-constant error
    nominal = np.array([-62.6111, 107.815, -53.7063, 76.0364, 71.923, 76.686]) * np.array(
        [0.223, 0.226, 0.240, 0.069, 0.072, 0.066])
    rel = tr.drive_gain / nominal - 1
    assert np.all(np.abs(rel) < 5 * s.torque_constant_error) and np.any(np.abs(rel) > 1e-3)
    # without jitter, current residual = offset + white noise at every sample
    resid = rec.current - tr.current
    assert np.allclose(resid.mean(axis=0), tr.current_offset, atol=5 * s.current_noise / np.sqrt(tr.t.size))
    assert np.allclose(resid.std(axis=0), s.current_noise, rtol=0.05)
    # tracker noise
    assert np.std(rec.tool_points[:3] - rec.tool_points[:3].mean(axis=0)) < 1e-3
    # jitter (the default sensors): actual sample instants spread about the stamps
    spread = np.std(real.truth.t_actual[1:-1] - real.truth.t[1:-1])
    assert spread == pytest.approx(real.sensors.jitter, rel=0.1)


def test_estimated_velocity_against_truth(real):
    """The Recording estimates qd from the quantised, jittered encoder positions."""
    rec, tr = real.recording, real.truth
    assert "qd" in rec.estimated
    moving = 1
    err = rec.qd[:, moving] - tr.qd[:, moving]
    rms = np.sqrt(np.mean(err**2)) / np.sqrt(np.mean(tr.qd[:, moving] ** 2))
    print(f"virtual lab: relative RMS velocity error of the estimate {rms:.3%}")
    assert rms < 0.05


def test_bad_input(puma, program):
    with pytest.raises(ValueError, match="Sensors.sample_period must be > 0"):
        Sensors(sample_period=0.0)
    with pytest.raises(ValueError, match="Sensors.current_noise must be a finite number >= 0"):
        Sensors(current_noise=-1.0)
    with pytest.raises(TypeError, match="trajectory must be a JointTrajectory"):
        virtual_lab(puma, np.zeros((10, 6)))
    planar = rd.compile_model(rd.load("planar_2r"))
    with pytest.raises(ValueError, match="the trajectory has 6 joints, robot 'planar_2r' has 2"):
        virtual_lab(planar, program)


def test_synchronisation_recovers_the_lab_tracker_latency(puma):
    """The tracker stream of the virtual lab lags by a latency the sync step must find (1 sample)."""
    from robodyn.measure.sync import synchronise
    from robodyn.studies.testprog import jointwise as program_of

    prog = program_of(puma, joints=["q1", "q2"], speeds=(1.0,), dwell=0.1)
    latency = 0.0137
    run = virtual_lab(puma, prog, sensors=Sensors(tracker_latency=latency), seed=3)
    assert run.truth.latency == pytest.approx(latency)
    sync = synchronise(run.recording, puma)
    # the tracker sees the tool ``latency`` late: shifting it back by the found offset aligns them
    assert abs(abs(sync.offset) - latency) <= run.sensors.sample_period
    assert sync.correlation > 0.9
