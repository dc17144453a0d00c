"""Position ripple (``ripple=``): a torque once per revolution of a joint, fitted on what the
identified model leaves (robodyn.identification.ripple).

Simulated PUMA 560 data with known truth: the test adds ``a sin q_1 + b cos q_1`` to the
description's own torque of the first joint, whose axis is vertical (gravity gives it no
torque, so no rigid-body parameter carries that harmonic).
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification.choices import candidates
from robodyn.identification.ripple import (
    RippleFit,
    gravity_free_joints,
    ripple_columns,
    separated_joints,
)
from robodyn.robot.errors import IdentificationError
from tests.identification.helpers import fourier, load_quiet

A, B = 0.8, -0.5  # the ripple's sine and cosine amplitudes on joint 1, N m


@pytest.fixture(scope="module")
def puma():
    robot = load_quiet("puma560")
    return robot, rd.compile_model(robot)


def _run(model, seed: int, ripple: bool, seconds: float = 30.0, noise: float = 0.05) -> rd.Recording:
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, seconds, 0.01)
    q, qd, qdd = fourier(t, model.dof, rng, f0=1.0 / seconds)
    tau = model.inverse_dynamics(q, qd, qdd)
    if ripple:
        tau[:, 0] += A * np.sin(q[:, 0]) + B * np.cos(q[:, 0])
    tau = tau + noise * rng.standard_normal(tau.shape)
    return rd.Recording(t=t, q=q, qd=qd, qdd=qdd, tau=tau, joint_names=model.robot.joint_names,
                        source=f"run{seed}")


def _error(ident, rec) -> float:
    return float(np.linalg.norm(ident.predict(rec) - rec.tau) / np.linalg.norm(rec.tau))


def test_ripple_is_kept_when_the_plant_has_one(puma):
    robot, model = puma
    fit = [_run(model, 1, True), _run(model, 2, True)]
    check = _run(model, 3, True, noise=0.0)
    ident = rd.identify(robot, fit, cutoff=None, method="ols", regularization=None, model=model)
    assert ident.choices.ripple is True
    without = rd.identify(robot, fit, cutoff=None, method="ols", regularization=None, model=model,
                          ripple=False)
    assert without.ripple_fit is None and without.choices.ripple is None
    e_with, e_without = _error(ident, check), _error(without, check)
    # the ripple is fitted on what the rigid-body fit leaves: over this motion (joint 1 swings
    # about +-1.5 rad, sin q_1 ~ q_1 resembles the inertia column, qdd ~ -w^2 q) the rigid body
    # has already taken part of it, so the held-out error falls by about 40 % (0.0185 -> 0.0112
    # with these seeds), not to the noise; the sine amplitude comes out with the right sign
    assert e_with < 0.7 * e_without
    assert ident.ripple_fit.sine[0] > 0.0 and ident.ripple_fit.cosine[0] < 0.0
    # the other joints carry none: their amplitudes stay near the noise level
    assert np.max(np.abs(ident.ripple_fit.sine[1:])) < 0.05
    assert "position ripple kept" in ident.choices.summary()


def test_ripple_is_not_kept_when_the_plant_has_none(puma):
    robot, model = puma
    fit = [_run(model, 4, False), _run(model, 5, False)]
    ident = rd.identify(robot, fit, cutoff=None, method="ols", regularization=None, model=model)
    assert ident.choices.ripple is False and ident.ripple_fit is None
    scores = dict(ident.choices.ripple_scores)
    assert scores["none"] == 1.0 and scores["ripple"] > 0.99  # no held-out gain from noise
    forced = rd.identify(robot, fit, cutoff=None, method="ols", regularization=None, model=model,
                         ripple=True)
    # forced on noise alone, the amplitudes stay at the noise's level
    assert np.max(np.abs(forced.ripple_fit.sine)) < 0.02
    assert np.max(np.abs(forced.ripple_fit.cosine)) < 0.02


def test_prismatic_joint_carries_no_ripple():
    q = np.array([[0.3, 0.25], [-1.2, 0.5]])  # joint 1 revolute (rad), joint 2 prismatic (m)
    cols = ripple_columns(q, np.array([True, False]))
    np.testing.assert_array_equal(cols[:, 0, 0], np.sin(q[:, 0]))
    np.testing.assert_array_equal(cols[:, 0, 1], np.cos(q[:, 0]))
    np.testing.assert_array_equal(cols[:, 1, :], 0.0)
    fit = RippleFit(np.array([1.0, 2.0]), np.array([0.5, 3.0]), np.array([True, False]),
                    np.array([0.1, 0.0]))
    np.testing.assert_allclose(fit.torque(q)[:, 0], np.sin(q[:, 0]) + 0.5 * np.cos(q[:, 0]) + 0.1)
    np.testing.assert_array_equal(fit.torque(q)[:, 1], 0.0)


def test_bad_ripple_option_is_refused(puma):
    robot, model = puma
    with pytest.raises(IdentificationError, match="ripple: expected False, True or 'auto'"):
        rd.identify(robot, _run(model, 6, False, seconds=5.0), ripple="sometimes", model=model)


def test_measured_velocity_is_the_plain_candidate_when_every_recording_has_one():
    plain = candidates("auto", 0.0, False, True, False, 1e-3)[0]
    assert plain.velocity == "measured"
    assert candidates("auto", 0.0, False, False, False, 1e-3)[0].velocity == "position"


def test_ripple_is_offered_only_where_gravity_does_not_carry_the_joints_own_harmonic(puma):
    # PUMA 560: joint 1 has a vertical axis (no gravity torque); joint 2 lifts link 2, whose
    # first moments give its torque exactly a sin q2 + b cos q2; joint 3's gravity depends on
    # q2 + q3 and the wrist's on several angles, never on their own angle alone.
    robot, model = puma
    np.testing.assert_array_equal(gravity_free_joints(model, np.ones(6, bool)),
                                  [True, False, True, True, True, True])
    np.testing.assert_array_equal(gravity_free_joints(model, np.array([False, True, True] * 2)),
                                  [False, False, True, False, True, True])


def _small_travel_run(model, seed: int, centre: np.ndarray, amplitude: float) -> rd.Recording:
    """Exact motion about ``centre`` with Fourier amplitude ``amplitude`` (rad), the ripple in
    joint 1's torque, 0.05 N m noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 20.0, 0.01)
    q, qd, qdd = fourier(t, model.dof, rng, f0=0.05, amplitude=amplitude)
    q = q - q[0] + centre
    tau = model.inverse_dynamics(q, qd, qdd)
    tau[:, 0] += A * np.sin(q[:, 0]) + B * np.cos(q[:, 0])
    tau = tau + 0.05 * rng.standard_normal(tau.shape)
    return rd.Recording(t=t, q=q, qd=qd, qdd=qdd, tau=tau, joint_names=model.robot.joint_names,
                        source=f"small{seed}")


def test_separation_of_the_ripple_columns_follows_the_travel():
    revolute = np.array([True, True, True, False])
    t = np.linspace(0.0, 1.0, 2001)
    # a whole turn (orthogonal columns), 2 rad, 0.01 rad of travel, and a prismatic joint
    q = np.column_stack([2 * np.pi * t, 0.4 + 2.0 * t, 0.3 + 0.01 * t, 2 * np.pi * t])
    np.testing.assert_array_equal(separated_joints(q, revolute), [True, True, False, False])
    # the 0.02 threshold lies between 1.0 and 1.5 rad of travel (closed form: the columns'
    # smallest singular value grows like travel^2 for a short travel)
    for travel, expected in ((1.0, False), (1.5, True)):
        qq = np.column_stack([0.3 + travel * t])
        assert separated_joints(qq, np.array([True]))[0] is np.bool_(expected)


def test_no_ripple_is_fitted_where_the_joints_hardly_move(puma):
    robot, model = puma
    centre = np.array([0.6, -0.35, 0.37, 0.67, -0.2, 0.0])
    fit = [_small_travel_run(model, 11, centre, 0.004)]  # each joint travels about 0.01 rad
    assert np.max(np.ptp(fit[0].q, axis=0)) < 0.05
    check = _small_travel_run(model, 12, centre + 0.5, 0.004)  # another posture
    # the default estimator: forced, the ripple would be fitted on a travel where sin q, cos q
    # and 1 are nearly dependent (measured without the gate: amplitudes of 30-60 N m, held-out
    # error 0.56 against 0.21)
    forced = rd.identify(robot, fit, model=model, ripple=True)
    auto = rd.identify(robot, fit, model=model)
    assert forced.ripple_fit is None and auto.ripple_fit is None
    assert auto.choices.ripple is False and auto.choices.ripple_scores == ()
    assert "no joint travels far enough" in auto.choices.summary()
    # the prediction at the other posture is the ripple-free fit's, bit for bit
    np.testing.assert_array_equal(forced.predict(check), auto.predict(check))
