"""Thesis test programs: one joint at a time (trapezoidal strokes) and the ISO 9283 cube poses."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from robodyn.simulation import UnreachableError
from robodyn.studies.testprog import iso_cube, jointwise


@pytest.fixture(scope="module")
def program(puma):
    return jointwise(puma, speeds=(0.5, 1.0), velocity=1.0, acceleration=3.0, dt=2e-3)


def test_jointwise_one_joint_at_a_time(puma, program):
    lower = np.array([float(j.lower) for j in puma.robot.joints])
    upper = np.array([float(j.upper) for j in puma.robot.joints])
    home = 0.5 * (lower + upper)
    t, q, qd = program.t, program.q, program.qd
    assert np.all(q >= lower - 1e-12) and np.all(q <= upper + 1e-12)
    assert np.allclose(q[0], home) and np.allclose(q[-1], home)
    assert np.allclose(qd[0], 0) and np.allclose(qd[-1], 0)
    moves = [s for s in program.segments if s.kind == "move"]
    # 6 joints x 2 speeds x 2 directions
    assert len(moves) == 24
    for s in moves:
        i = puma.robot.joint_names.index(s.joint)
        inside = (t > s.t0 + 1e-9) & (t < s.t1 - 1e-9)
        others = np.delete(np.arange(6), i)
        assert np.allclose(q[inside][:, others], home[others], atol=1e-12)
        # a 180 deg stroke in the stated direction, displacement = integral of the velocity
        q0, q1 = program.trajectory.at(s.t0)[0], program.trajectory.at(s.t1)[0]
        assert s.direction * (q1[i] - q0[i]) == pytest.approx(np.pi, abs=1e-12)
        fine = np.linspace(s.t0, s.t1, 4001)
        assert s.direction * np.trapezoid(program.trajectory.at(fine)[1][:, i], fine) == pytest.approx(
            np.pi, rel=1e-6)
        seg_qd = qd[inside, i]
        # trapezoid: cruise at speed x 1 rad/s, acceleration 3 rad/s^2
        assert np.max(np.abs(seg_qd)) == pytest.approx(s.speed * 1.0, rel=1e-9)
        assert np.max(np.abs(program.qdd[inside, i])) == pytest.approx(3.0, rel=1e-9)
    assert {(s.joint, s.speed, s.direction) for s in moves} == {
        (j, v, d) for j in puma.robot.joint_names for v in (0.5, 1.0) for d in (1, -1)}


def test_jointwise_stroke_shortened_to_range(puma):
    # q5 spans -100..100 deg: a 4 rad stroke becomes the full 200 deg range
    prog = jointwise(puma, joints=["q5"], stroke=4.0, speeds=(1.0,), dwell=0.0, dt=5e-3)
    q5 = prog.trajectory.at(np.array([s.t0 for s in prog.segments] + [prog.duration]))[0][:, 4]
    assert q5.min() == pytest.approx(np.radians(-100), abs=1e-12)
    assert q5.max() == pytest.approx(np.radians(100), abs=1e-12)
    assert [s.label for s in prog.segments if s.kind == "move"] == [
        "q5 +200.0 deg at 100 %", "q5 -200.0 deg at 100 %"]


def test_program_csv(tmp_path, puma):
    prog = jointwise(puma, joints=["q2"], speeds=(1.0,), dt=0.01)
    traj_path, seg_path = prog.to_csv(tmp_path / "out")
    df = pd.read_csv(traj_path)
    assert np.array_equal(df["q[q2]"].to_numpy(), prog.q[:, 1])
    assert np.array_equal(df["t"].to_numpy(), prog.t)
    segs = pd.read_csv(seg_path)
    assert list(segs["kind"]) == [s.kind for s in prog.segments]
    assert np.array_equal(segs["t1"].to_numpy(), [s.t1 for s in prog.segments])


def test_iso_cube_poses(puma):
    prog = iso_cube(puma, size=0.5, cycles=2, dt=5e-3)
    pts = prog.points
    # FK of the IK solutions reaches the points
    assert np.allclose(puma.forward_kinematics(prog.poses)[:, :3, 3], pts, atol=1e-8)
    # ISO geometry, independent of the point construction: P2..P5 at 40 % of the space diagonal
    # (sqrt(3) x 0.5 m) from the centre P1, in one plane through P1 containing the x axis
    d = np.linalg.norm(pts[1:] - pts[0], axis=1)
    assert np.allclose(d, 0.4 * np.sqrt(3) * 0.5, atol=1e-12)
    normal = np.cross(pts[1] - pts[0], pts[2] - pts[0])
    assert np.allclose((pts[1:] - pts[0]) @ normal, 0.0, atol=1e-12)
    # the program dwells at each pose, at rest, in order
    dwells = [s for s in prog.segments if s.kind == "dwell"]
    assert [s.label for s in dwells] == ["P1", "P2", "P3", "P4", "P5"] * 2 + ["P1"]
    for s in dwells:
        k = np.searchsorted(prog.t, 0.5 * (s.t0 + s.t1))
        assert np.allclose(prog.q[k], prog.poses[int(s.label[1]) - 1], atol=1e-12)
        assert np.allclose(prog.qd[k], 0.0)


def test_iso_cube_unreachable(puma):
    with pytest.raises(UnreachableError,
                       match=r"test point P2 .* of a 3 m cube is out of reach of .puma560."):
        iso_cube(puma, size=3.0, center=[0.5, 0.0, 0.7])


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"speeds": (0.0,)}, r"speeds must be fractions in \[0.001, 1\] of the velocity limit"),
    ({"speeds": (1.5,)}, r"speeds must be fractions in \[0.001, 1\] of the velocity limit"),
    ({"joints": ["elbow"]}, "unknown joint 'elbow'; the robot's joints are q1, q2"),
    ({"stroke": -1.0}, "stroke must be a positive angle"),
    ({"velocity": [1.0, 2.0]}, "velocity must be positive"),
    ({"home": [9.0, 0, 0, 0, 0, 0]}, "home must be a"),
])
def test_jointwise_bad_arguments(puma, kwargs, message):
    with pytest.raises(ValueError, match=message):
        jointwise(puma, **kwargs)
