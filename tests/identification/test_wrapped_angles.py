"""Continuous joints logged within [-pi, pi): the wrap steps undone before filtering (issue 20 item 3)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import robodyn as rd
from robodyn.robot.errors import RecordingWarning
from tests.identification.helpers import fourier, load_quiet


@pytest.fixture(scope="module")
def arm():
    robot = load_quiet("puma560")
    return robot, rd.compile_model(robot)


def test_unwrapped_undoes_whole_turns_only():
    """``unwrap_turns`` against numpy's unwrap on a continuous angle logged within [-pi, pi); a step
    across a gap that is not near a whole turn, and a prismatic joint's metres, are kept."""
    from robodyn.measure.angles import unwrap_turns as unwrapped

    t = np.linspace(0.0, 10.0, 2001)
    angle = 3.0 * np.sin(0.7 * t) + 0.4 * t  # crosses +-pi both ways
    logged = (angle + np.pi) % (2 * np.pi) - np.pi
    assert np.sum(np.abs(np.diff(logged)) > np.pi) >= 3
    slide = 0.3 * np.cos(t)  # a prismatic joint, m
    q = np.column_stack([logged, slide])
    out = unwrapped(q)
    np.testing.assert_allclose(out[:, 0], np.unwrap(logged), atol=1e-12)
    np.testing.assert_allclose(out[:, 0] - angle, out[0, 0] - angle[0], atol=1e-12)
    assert np.array_equal(out[:, 1], slide)
    # a jump of 2 rad across a lost stretch of the log: motion, not a wrap
    gap = np.concatenate([np.zeros(50), np.full(50, 2.0)])[:, None]
    assert np.array_equal(unwrapped(gap), gap)
    from robodyn.measure.angles import wrap_steps

    assert list(wrap_steps(q)) == [int(np.sum(np.abs(np.diff(logged)) > np.pi)), 0]
    assert list(wrap_steps(gap)) == [0]
    assert unwrapped(q[:1]) is not None and np.array_equal(unwrapped(q[:, 1:]), q[:, 1:])


def test_wrapped_angle_log_identifies_as_the_continuous_one(arm):
    """A joint logged within [-pi, pi) (its angle crossing +-pi) gives the identification of the
    same log recorded continuously: the wrap steps are undone before filtering, so neither the
    fit nor a prediction sees a burst of velocity."""
    robot, model = arm
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 12.0, 0.01)
    q, qd, qdd = fourier(t, robot.dof, rng)
    q[:, 3] += 2.5 - q[:, 3].mean() + 0.15 * t  # joint 4 turns through +-pi
    qd[:, 3] += 0.15
    tau = model.inverse_dynamics(q, qd, qdd) + rng.normal(0, 0.05, q.shape)
    logged = q.copy()
    logged[:, 3] = (q[:, 3] + np.pi) % (2 * np.pi) - np.pi
    assert np.sum(np.abs(np.diff(logged[:, 3])) > np.pi) >= 2
    cont = rd.Recording(t=t, q=q, tau=tau, joint_names=robot.joint_names, source="continuous")
    wrap = rd.Recording(t=t, q=logged, tau=tau, joint_names=robot.joint_names, source="wrapped")
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        a = rd.identify(robot, cont, model=model, resonance=False, ripple=False)
    assert not [w for w in seen if "modulo a turn" in str(w.message)]
    steps = int(np.sum(np.abs(np.diff(logged[:, 3])) > np.pi))
    with pytest.warns(RecordingWarning, match=rf"wrapped: q: angle logged modulo a turn on "
                                              rf"{robot.joint_names[3]} \({steps}\)"):
        b = rd.identify(robot, wrap, model=model, resonance=False, ripple=False)
    np.testing.assert_allclose(b.predict(wrap), a.predict(cont), rtol=1e-9, atol=1e-9)
    assert float(np.linalg.norm(a.predict(cont) - tau) / np.linalg.norm(tau)) < 0.05


def test_recording_estimates_velocity_through_a_wrap():
    """A Recording without velocities estimates them from positions: across a wrap-around step
    of a logged angle they are those of the continuous angle, not a burst."""
    t = np.arange(0.0, 6.0, 0.005)
    angle = 2.8 + 0.6 * np.sin(1.3 * t)  # crosses pi
    logged = (angle + np.pi) % (2 * np.pi) - np.pi
    cont = rd.Recording(t=t, q=angle[:, None], tau=np.zeros((t.size, 1)), source="continuous")
    wrap = rd.Recording(t=t, q=logged[:, None], tau=np.zeros((t.size, 1)), source="wrapped")
    np.testing.assert_allclose(wrap.qd, cont.qd, atol=1e-9)
    np.testing.assert_allclose(wrap.qdd, cont.qdd, atol=1e-6)
    assert np.array_equal(wrap.q[:, 0], logged)  # the logged positions are kept as given
