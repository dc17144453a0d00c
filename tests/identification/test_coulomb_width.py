"""The prediction's smoothed Coulomb step (``rd.identify(..., coulomb_width=w)``).

The fit keeps the step ``H(qd)``; the prediction replaces it by ``max(tanh(qd / w), 0)``. Checked
on noise-free simulated torque of a planar arm whose friction is known, against the closed form
of that change written here from the true Coulomb levels.
"""

from __future__ import annotations

import argparse

import numpy as np
import pytest

import robodyn as rd
from robodyn.cli.identify import _width
from robodyn.identification.coulomb_width import (
    HOLD_SECONDS,
    HOLD_SPEED,
    WIDTH_PER_NOISE,
    auto_coulomb_width,
    holds,
    velocity_noise,
)
from robodyn.identification.pipeline import nominal_standard
from robodyn.identification.preprocess import Preprocess
from robodyn.robot.errors import IdentificationError
from robodyn.symbolic.regressor import INERTIAL_NAMES, PER_JOINT
from tests.identification.helpers import fourier, load_quiet

FV = len(INERTIAL_NAMES) + 1  # Fv within a joint's 15 parameters (Ia, Fv, Fcp, Fcn, Fo)
LEVELS = ((1.5, 0.9), (0.8, 1.2))  # true (Fcp, Fcn) per joint, N m


def _planar_run():
    robot = load_quiet("planar_2r")
    model = rd.compile_model(robot)
    p = nominal_standard(robot).copy()
    for j, (pos, neg) in enumerate(LEVELS):
        p[PER_JOINT * j + FV:PER_JOINT * j + FV + 4] = (0.3, pos, neg, 0.0)  # Fv, Fcp, Fcn, Fo
    t = np.arange(0.0, 20.0, 0.01)
    q, qd, qdd = fourier(t, 2, np.random.default_rng(11))
    # the last second at rest: the offsets are told apart from the Coulomb levels
    rest = t > 19.0
    q[rest], qd[rest], qdd[rest] = q[rest][0], 0.0, 0.0
    tau = model.regressor(q, qd, qdd) @ p
    rec = rd.Recording(t=t, q=q, qd=qd, qdd=qdd, tau=tau, joint_names=robot.joint_names,
                       source="planar")
    return robot, model, rec


@pytest.fixture(scope="module")
def planar_run():
    return _planar_run()


def _identify(robot, model, rec, **kwargs):
    return rd.identify(robot, rec, method="ols", cutoff=None, regularization=None, model=model,
                       velocity="measured", ripple=False, resonance=False, friction="linear",
                       local=False, **kwargs)


def test_width_smooths_the_prediction_and_not_the_fit(planar_run):
    robot, model, rec = planar_run
    width = 0.2
    plain = _identify(robot, model, rec)
    smooth = _identify(robot, model, rec, coulomb_width=width)
    # without a filter the recording's own velocities are taken as exact: "auto" smooths nothing
    assert plain.options.coulomb_width == "auto" and not np.any(plain.coulomb_width)
    assert smooth.coulomb_width == width
    assert smooth.options.coulomb_width == width
    np.testing.assert_array_equal(smooth.standard, plain.standard)  # the fit is the same
    tau = np.asarray(rec.tau)
    scale = np.abs(tau).max()
    np.testing.assert_allclose(plain.predict(rec), tau, rtol=0, atol=1e-8 * scale)
    # closed form: the Coulomb torque Fcp H(qd) - Fcn H(-qd) of a moving joint becomes
    # Fcp P(qd > 0) - Fcn P(qd < 0), P(qd > 0) = (1 + tanh(qd / w)) / 2; at rest it stays 0
    qd = np.asarray(rec.qd)
    expected = tau.copy()
    for j, (pos, neg) in enumerate(LEVELS):
        step = pos * (qd[:, j] > 0) - neg * (qd[:, j] < 0)
        up = 0.5 * (1.0 + np.tanh(qd[:, j] / width))
        expected_step = np.where(qd[:, j] != 0, pos * up - neg * (1.0 - up), 0.0)
        expected[:, j] += expected_step - step
    assert np.max(np.abs(expected - tau)) > 0.1  # the smoothing is visible in this run
    np.testing.assert_allclose(smooth.predict(rec), expected, rtol=0, atol=1e-8 * scale)


def test_a_narrow_width_is_the_step_away_from_rest(planar_run):
    robot, model, rec = planar_run
    smooth = _identify(robot, model, rec, coulomb_width=1e-9)
    qd = np.asarray(rec.qd)
    moving = np.all(np.abs(qd) > 1e-6, axis=1)
    np.testing.assert_allclose(smooth.predict(rec)[moving], np.asarray(rec.tau)[moving], rtol=0,
                               atol=1e-8 * np.abs(rec.tau).max())


def test_holds_are_sustained_slow_stretches_on_any_stamps():
    rng = np.random.default_rng(5)
    t = np.cumsum(rng.uniform(0.008, 0.012, 600))  # ~6 s of irregular stamps
    qd = np.column_stack([np.cos(2 * np.pi * 0.5 * t),  # brisk: reversals pass in milliseconds
                          np.where((t > 2.0) & (t < 3.0), 1e-4 * np.sin(40 * t), 0.5),  # 1 s hold
                          np.where((t > 4.0) & (t < 4.1), 0.0, 0.5)])  # 0.1 s: too short
    held = holds(t, qd)
    assert not held[:, 0].any() and not held[:, 2].any()
    np.testing.assert_array_equal(held[:, 1], (t > 2.0) & (t < 3.0))
    assert HOLD_SECONDS > 0.1 and HOLD_SPEED > 1e-4


def test_a_held_joint_is_smoothed_over_at_least_the_hold_speed(planar_run):
    """Joint 1 creeps (+-2e-4 rad/s) for 2 s while joint 2 moves on; a plant with the exact step
    flips its friction with each creep, which the sign of so slow a motion hardly predicts: the
    prediction smooths the step over the hold speed there, and keeps the step (a narrow width)
    everywhere else."""
    robot, model, rec = planar_run
    t = np.asarray(rec.t)
    q, qd, qdd = (np.array(a) for a in (rec.q, rec.qd, rec.qdd))
    hold = (t >= 10.0) & (t < 12.0)
    w = 2 * np.pi * 3.0
    th = t[hold] - 10.0
    q[hold, 0] = q[hold, 0][0] + 2e-4 / w * (1.0 - np.cos(w * th))
    qd[hold, 0], qdd[hold, 0] = 2e-4 * np.sin(w * th), 2e-4 * w * np.cos(w * th)
    p = nominal_standard(robot).copy()
    for j, (pos, neg) in enumerate(LEVELS):
        p[PER_JOINT * j + FV:PER_JOINT * j + FV + 4] = (0.3, pos, neg, 0.0)
    tau = model.regressor(q, qd, qdd) @ p
    crept = rd.Recording(t=t, q=q, qd=qd, qdd=qdd, tau=tau, joint_names=robot.joint_names,
                         source="creep")
    ident = _identify(robot, model, crept, coulomb_width=1e-9)
    expected = tau.copy()
    pos, neg = LEVELS[0]
    inside = hold & (qd[:, 0] != 0)
    # the step Fcp H(qd) - Fcn H(-qd) becomes Fcp P(qd > 0) - Fcn P(qd < 0) in the hold,
    # P(qd > 0) = (1 + tanh(qd / HOLD_SPEED)) / 2
    v = qd[inside, 0]
    up = 0.5 * (1.0 + np.tanh(v / HOLD_SPEED))
    expected[inside, 0] += pos * up - neg * (1.0 - up) - (pos * (v > 0) - neg * (v < 0))
    assert np.max(np.abs(expected - tau)) > 0.5  # the hold is visible
    moving = np.abs(qd) > 1e-6
    np.testing.assert_allclose(ident.predict(crept)[moving], expected[moving], rtol=0,
                               atol=1e-8 * np.abs(tau).max())


def test_the_widths_are_reported(planar_run):
    from robodyn.cli.identify import _smoothing_note
    from robodyn.report.identification_report import _choices_html

    robot, model, rec = planar_run
    smooth = _identify(robot, model, rec, coulomb_width=0.25)
    assert "smoothed over <b>0.25 rad/s</b>" in _choices_html(smooth)
    assert _smoothing_note(np.array([0.0031, 0.0024])) == \
        ", Coulomb step smoothed over 0.0031, 0.0024 rad/s (at least 0.001 where held)"
    assert _smoothing_note(np.zeros(2)) == ""
    assert "smoothed" not in _choices_html(_identify(robot, model, rec, coulomb_width=0.0))


@pytest.mark.parametrize("bad", [-1e-3, float("nan"), float("inf"), "wide", True])
def test_bad_coulomb_width_is_refused(planar_run, bad):
    robot, model, rec = planar_run
    with pytest.raises(IdentificationError, match="coulomb_width"):
        rd.identify(robot, rec, cutoff=None, model=model, coulomb_width=bad)


@pytest.mark.parametrize("bad", ["-0.1", "nan", "fast"])
def test_command_line_width_must_be_auto_or_a_velocity(bad):
    with pytest.raises(argparse.ArgumentTypeError):
        _width(bad)
    assert _width("0.005") == 0.005 and _width("auto") == "auto"


def _noisy_run(noise: np.ndarray, dt: float, seconds: float, jitter: float = 0.0):
    """Smooth motion of joint 1, joint 2 held still, positions with white noise of std
    ``noise`` (2,); stamps ``k dt`` plus uniform jitter of +-``jitter`` s."""
    rng = np.random.default_rng(7)
    count = int(seconds / dt)
    t = np.arange(count) * dt + rng.uniform(-jitter, jitter, count)
    clean = np.column_stack([0.8 * np.sin(2 * np.pi * 0.3 * t), np.full(t.size, 0.4)])
    q = clean + rng.normal(size=clean.shape) * noise
    q[:, 1] = 0.4  # held still: no noise either
    rec = rd.Recording(t=t, q=q, joint_names=("a", "b"), source="noisy")
    return t, clean, q, rec


@pytest.mark.parametrize(("dt", "cutoff", "jitter"), [(0.01, 5.0, 0.0), (1e-3, 4.0, 0.0),
                                                      (0.0106, 5.0, 0.002)])
def test_velocity_noise_is_that_of_the_processed_velocity(dt, cutoff, jitter):
    """The estimate against the measured spread of the velocity the prediction computes: the
    filtered derivative of the noisy positions less that of the clean ones."""
    from robodyn.measure.filtering import differentiate

    sigma = 2e-4
    t, clean, q, rec = _noisy_run(np.array([sigma, 0.0]), dt, 60.0, jitter)
    settings = Preprocess(cutoff=cutoff, order=4, velocity="position")
    s = velocity_noise(rec, settings)
    error = differentiate(t, q[:, :1], cutoff)[1] - differentiate(t, clean[:, :1], cutoff)[1]
    inner = slice(t.size // 10, -t.size // 10)  # away from the filter's ends
    measured = float(np.std(error[inner]))
    assert s[1] == 0.0  # the held joint's processed velocity is exactly zero
    assert 0.85 * measured < s[0] < 1.15 * measured
    # the width is WIDTH_PER_NOISE times that noise, pooled over recordings (the same one twice here)
    np.testing.assert_allclose(auto_coulomb_width([rec, rec], settings), WIDTH_PER_NOISE * s,
                               rtol=1e-12)
    assert velocity_noise(rec, Preprocess(cutoff=None, order=4, velocity="position")).tolist() \
        == [0.0, 0.0]


def test_auto_width_follows_the_noise(planar_run):
    """More position noise, a wider step (in proportion); a noise-free run, a negligible one."""
    robot, model, _ = planar_run
    t = np.arange(0.0, 20.0, 0.01)
    q, qd, qdd = fourier(t, 2, np.random.default_rng(12))
    tau = model.inverse_dynamics(q, qd, qdd)
    widths = []
    for sigma in (0.0, 1e-4, 1e-3):
        noisy = rd.Recording(t=t, q=q + np.random.default_rng(3).normal(size=q.shape) * sigma,
                             tau=tau, joint_names=robot.joint_names, source="n")
        ident = rd.identify(robot, noisy, method="ols", cutoff=4.0, model=model, ripple=False,
                            resonance=False, friction="linear", regularization=1.0)
        widths.append(np.asarray(ident.coulomb_width))
    assert np.all(widths[0] < 1e-5)  # the motion's own content above fs / 4
    # the noise dominates: ten times the noise, ten times the width (linear in the noise)
    np.testing.assert_allclose(widths[2] / widths[1], 10.0, rtol=0.02)
