"""``rd.validate`` rejects what it cannot compare, with messages naming field, row and reason."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from robodyn.robot.errors import ValidationError
from robodyn.validation import validate
from tests.validation.helpers import recording, slider


@pytest.fixture()
def cart(tmp_path):
    robot = slider(tmp_path)
    t = np.arange(200) * 1e-3
    q = (0.1 * np.sin(2 * np.pi * 2 * t))[:, None]
    return robot, dict(t=t, q=q, qd=np.gradient(q[:, 0], t)[:, None], qdd=np.zeros_like(q),
                       tau=np.ones_like(q))


def test_joints_that_do_not_match_the_robot(cart):
    robot, f = cart
    rec = recording(**f, joint_names=("elbow",), source="run.csv")
    with pytest.raises(ValidationError, match=r"run.csv: joint_names: .*do not match robot "
                                              r"'slider'.*missing x; not in the robot elbow"):
        validate(robot, rec)
    two = recording(t=f["t"], q=np.hstack([f["q"], f["q"]]), tau=np.ones((200, 2)))
    with pytest.raises(ValidationError, match="recording has 2: q1, q2"):
        validate(robot, two)


def test_too_few_samples(cart):
    robot, f = cart
    short = {k: v[:20] for k, v in f.items()}
    with pytest.raises(ValidationError, match="20 samples; validation needs at least 50"):
        validate(robot, recording(**short, joint_names=("x",)))


def test_nan_is_named_by_field_row_and_column(cart):
    robot, f = cart
    tau = f["tau"].copy()
    tau[17, 0] = np.nan
    # a Recording refuses NaN itself; a duck-typed one reaches validate's own check
    rec = SimpleNamespace(**{**f, "tau": tau}, current=None, joint_names=("x",), source="log.csv")
    with pytest.raises(ValidationError, match=r"log.csv: field tau, row 17, column 0 \(x\): value nan"):
        validate(robot, rec)


def test_missing_or_unknown_target(cart):
    robot, f = cart
    rec = recording(**f, joint_names=("x",), source="run.csv")
    with pytest.raises(ValidationError, match="run.csv: field current: the recording has no current"):
        validate(robot, rec, target="current")
    with pytest.raises(ValidationError, match="unknown target 'torque'"):
        validate(robot, rec, target="torque")
    bare = recording(t=f["t"], q=f["q"], joint_names=("x",), source="q_only.csv")
    with pytest.raises(ValidationError, match="q_only.csv: the recording has neither tau nor current"):
        validate(robot, bare)


def test_bad_gains_and_a_mismatched_identification(cart):
    robot, f = cart
    rec = recording(t=f["t"], q=f["q"], current=f["tau"], joint_names=("x",))
    with pytest.raises(ValidationError, match=r"gains: expected 1 finite non-zero"):
        validate(robot, rec, gains=[1.0, 2.0])
    with pytest.raises(ValidationError, match=r"gains: .* got \[0.0\]"):
        validate(robot, rec, gains=[0.0])
    ident = SimpleNamespace(target="tau", predict=lambda r: np.zeros((200, 1)))
    with pytest.raises(ValidationError, match="identification predicts 'tau'"):
        validate(robot, rec, target="current", ident=ident)


def test_a_window_longer_than_the_recording_is_a_note_not_an_error(cart):
    robot, f = cart
    val = validate(robot, recording(**f, joint_names=("x",)), window=5.0)
    assert val.simulation is None
    assert any("shorter than one simulation window" in n for n in val.notes)
