"""``rd.load(urdf, locked=...)``: joints held still and treated as fixed (a gripper's fingers).

A published arm description often carries more moving joints than the arm: a hand with two
fingers (one a ``<mimic>`` of the other) makes the moving joints a branching tree. Locking them
turns each into a fixed joint at its position, ``origin @ motion(axis, value)``; Pinocchio's
``buildReducedModel`` on the same file with the same joints locked at the same positions is the
independent oracle for the dynamics and the tool frame.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import robodyn as rd
from robodyn.cli import main
from robodyn.robot.errors import DescriptionError
from robodyn.robot.numbers_cache import load_numbers
from tests.robot.test_urdf_real_world import UR5, UR5_JOINTS

try:  # test-only oracle: the test that uses it is marked and skips alone (tests/conftest.py)
    import pinocchio as pin
except ImportError:
    pin = None

#: A mid-chain revolute joint and both fingers, locked at these positions (rad, m).
LOCKS = {"wrist_2_joint": 0.7, "left_joint": 0.01, "right_joint": 0.03}


def _finger(name: str, mimic: str = "") -> str:
    """A prismatic finger on ``tool0``: 0.1 kg off its axis, its origin turned."""
    return (f'<link name="{name}"><inertial><origin xyz="0 0.01 0.02"/><mass value="0.1"/>'
            '<inertia ixx="1e-5" iyy="2e-5" izz="3e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>'
            f'<joint name="{name}_joint" type="prismatic"><parent link="tool0"/>'
            f'<child link="{name}"/><origin xyz="0 0 0.05" rpy="0.1 0.2 0.3"/>'
            f'<axis xyz="0 1 0"/>{mimic}'
            '<limit lower="0" upper="0.04" effort="10" velocity="0.1"/></joint>')


def _gripper(tmp_path: Path, mimic: bool) -> Path:
    """The UR5 fixture with two fingers; with ``mimic`` the right one mirrors the left:
    ``q_right = -q_left + 0.04``."""
    right = _finger("right", '<mimic joint="left_joint" multiplier="-1" offset="0.04"/>'
                    if mimic else "")
    path = tmp_path / ("mimic.urdf" if mimic else "gripper.urdf")
    path.write_text(UR5.read_text().replace("</robot>", _finger("left") + right + "</robot>"))
    return path


def _rail(tmp_path: Path) -> Path:
    """The UR5 fixture on a 20 kg car that a prismatic rail moves along its (turned) x axis."""
    rail = ('<link name="car"><inertial><origin xyz="0.1 0 0.05"/><mass value="20"/>'
            '<inertia ixx="1" iyy="2" izz="3" ixy="0" ixz="0" iyz="0"/></inertial></link>'
            '<joint name="rail" type="prismatic"><parent link="world"/><child link="car"/>'
            '<origin xyz="0 0 0.3" rpy="0 0 0.5"/><axis xyz="1 0 0"/>'
            '<limit lower="-2" upper="2" effort="100" velocity="1"/></joint>')
    text = UR5.read_text()
    on_world = '<joint name="world_joint" type="fixed">\n    <parent link="world"/>'
    assert on_world in text
    text = text.replace(on_world, on_world.replace('"world"', '"car"')).replace("</robot>", rail + "</robot>")
    path = tmp_path / "rail.urdf"
    path.write_text(text)
    return path


@pytest.mark.oracle("pinocchio")
@pytest.mark.parametrize(("make", "locks", "kept"), [
    (lambda tmp: _gripper(tmp, mimic=False), LOCKS, tuple(j for j in UR5_JOINTS if j != "wrist_2_joint")),
    (_rail, {"rail": 0.8}, UR5_JOINTS),
], ids=["fingers-and-wrist", "rail-before-the-arm"])
def test_locked_joints_match_pinocchios_reduced_model(tmp_path: Path, make, locks, kept) -> None:
    path = make(tmp_path)
    robot = rd.load(path, locked=locks, tool="tool0")
    assert robot.joint_names == kept
    model = rd.compile_model(robot)
    full = pin.buildModelFromUrdf(str(path))
    q_ref = pin.neutral(full)
    for name, value in locks.items():
        q_ref[full.joints[full.getJointId(name)].idx_q] = value
    reduced = pin.buildReducedModel(full, [full.getJointId(n) for n in locks], q_ref)
    data = reduced.createData()
    assert list(reduced.names)[1:] == list(robot.joint_names)
    rng = np.random.default_rng(5)
    for _ in range(3):
        q, qd, qdd = rng.uniform(-2, 2, (3, robot.dof))
        tau = model.inverse_dynamics(q[None], qd[None], qdd[None])[0]
        np.testing.assert_allclose(tau, pin.rnea(reduced, data, q, qd, qdd), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(model.mass_matrix(q[None])[0], pin.crba(reduced, data, q),
                                   rtol=1e-12, atol=1e-12)
        pin.framesForwardKinematics(reduced, data, q)
        np.testing.assert_allclose(model.forward_kinematics(q[None])[0],
                                   data.oMf[reduced.getFrameId("tool0")].homogeneous,
                                   rtol=0, atol=1e-12)


def test_a_mimic_joint_follows_the_joint_it_mimics(tmp_path: Path) -> None:
    # right = -1 x 0.01 + 0.04 = 0.03: the same robot as both fingers locked by hand
    mimic = rd.load(_gripper(tmp_path, mimic=True), locked={"left_joint": 0.01})
    by_hand = rd.load(_gripper(tmp_path, mimic=False), locked={"left_joint": 0.01, "right_joint": 0.03})
    other = rd.load(_gripper(tmp_path, mimic=False), locked={"left_joint": 0.01, "right_joint": 0.0})
    assert mimic.joint_names == UR5_JOINTS
    q = np.random.default_rng(2).uniform(-2, 2, (4, 6))
    m, h, o = (rd.compile_model(r) for r in (mimic, by_hand, other))
    np.testing.assert_allclose(m.inverse_dynamics(q, q, q), h.inverse_dynamics(q, q, q),
                               rtol=1e-13, atol=1e-13)
    # the finger's position matters (else the check above could not fail)
    assert np.abs(m.inverse_dynamics(q, q, q) - o.inverse_dynamics(q, q, q)).max() > 1e-5


def test_a_mimic_of_a_mimic_follows_too(tmp_path: Path) -> None:
    # "third" mimics "right" (0.5 x), which mimics "left", and comes first in the file:
    # left 0.01 -> right 0.03 -> third 0.015
    right = '<mimic joint="left_joint" multiplier="-1" offset="0.04"/>'
    text = UR5.read_text().replace("</robot>", _finger("third", '<mimic joint="right_joint" '
                                                       'multiplier="0.5"/>') + _finger("left")
                                   + _finger("right", right) + "</robot>")
    (tmp_path / "chained.urdf").write_text(text)
    plain = text.replace(right, "").replace('<mimic joint="right_joint" multiplier="0.5"/>', "")
    (tmp_path / "plain.urdf").write_text(plain)
    chained = rd.load(tmp_path / "chained.urdf", locked={"left_joint": 0.01})
    by_hand = rd.load(tmp_path / "plain.urdf",
                      locked={"left_joint": 0.01, "right_joint": 0.03, "third_joint": 0.015})
    q = np.random.default_rng(3).uniform(-2, 2, (4, 6))
    a, b = rd.compile_model(chained), rd.compile_model(by_hand)
    np.testing.assert_allclose(a.inverse_dynamics(q, q, q), b.inverse_dynamics(q, q, q),
                               rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize(("locked", "match"), [
    ({"left": 0.0}, r"locked\['left'\]: not a joint of the file \(moving joints: "
                    r"'shoulder_pan_joint'.*'right_joint'\)"),
    ({"ee_fixed_joint": 0.0}, r"locked\['ee_fixed_joint'\]: the joint is already fixed"),
    ({"left_joint": 0.05}, r"locked\['left_joint'\]: position 0.05 is outside the joint's "
                           r"limits \[0, 0.04\]"),
    ({"left_joint": "0.01"}, r"locked\['left_joint'\]: the position must be a number"),
    ({"left_joint": float("nan")}, r"locked\['left_joint'\]: expected a finite number"),
])
def test_bad_locks_are_named(tmp_path: Path, locked: dict, match: str) -> None:
    path = _gripper(tmp_path, mimic=False)
    with pytest.raises(DescriptionError, match=rf"gripper\.urdf: {match}"):
        rd.load(path, locked={"right_joint": 0.0, **locked})


def test_unlocked_mimic_and_non_urdf_are_refused_with_the_way_out(tmp_path: Path) -> None:
    with pytest.raises(DescriptionError, match=r"'right_joint': <mimic> joints .*locked=.*--lock"):
        rd.load(_gripper(tmp_path, mimic=True))
    with pytest.raises(DescriptionError, match=r"branching trees .*locked=.*--lock"):
        rd.load(_gripper(tmp_path, mimic=False))
    with pytest.raises(DescriptionError, match="puma560: locked= holds joints of a URDF file"):
        rd.load("puma560", locked={"j1": 0.0})


def test_cli_lock_and_the_numbers_cache(tmp_path: Path, capsys: pytest.CaptureFixture,
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    path = _gripper(tmp_path, mimic=True)
    assert main(["show", str(path), "--lock", "left_joint=0.01"]) == 0
    assert "6 joints" in capsys.readouterr().out
    assert main(["show", str(path), "--lock", "left_joint=0.01", "--lock", "left_joint=0.02"]) == 2
    assert "--lock: joint 'left_joint' given twice" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        main(["show", str(path), "--lock", "left_joint"])
    assert exc.value.code == 2
    assert "expected JOINT=VALUE" in capsys.readouterr().err
    # cached numbers are keyed by the locks: another finger position, another last-link centre
    # of mass (the second load of 0.0 reads the cache)
    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path / "cache"))
    gripper = _gripper(tmp_path, mimic=False)
    masses = [load_numbers(gripper, locked={"left_joint": v, "right_joint": 0.0}).coms
              for v in (0.0, 0.04, 0.0)]
    assert not np.allclose(masses[0], masses[1])
    np.testing.assert_array_equal(masses[0], masses[2])
    assert len(list((tmp_path / "cache").glob("rd_robot_*.json"))) == 2
