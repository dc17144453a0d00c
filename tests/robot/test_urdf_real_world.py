"""URDFs as ROS-Industrial and robot makers publish them, the tool link, singular mass matrices.

The fixtures in ``fixtures/`` are written in the style of the ROS-Industrial support packages: a
``world`` root, the REP-103 ``base`` frame, ``flange``/``tool0``/``ee_link`` fixed to the last
link, a wrist camera (with inertia) and its optical frame, transmissions and gazebo tags, and
(``kr_ros_industrial.urdf``) blank lines before the XML declaration. Pinocchio, reading the same
files, is the independent oracle for dynamics and frame poses.
"""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn import spatial as S
from robodyn.robot.errors import DescriptionError, DescriptionWarning
from robodyn.robot.load import KNOWN_PROPERTIES
from robodyn.robot.model import Robot
from tests.numeric_eval import program_evaluator
from tests.urdf_chains import pin_q

try:  # test-only oracle: the tests that use it are marked and skip alone (see tests/conftest.py)
    import pinocchio as pin
except ImportError:
    pin = None

FIXTURES = Path(__file__).resolve().parent / "fixtures"
UR5 = FIXTURES / "ur5_ros_industrial.urdf"
KR = FIXTURES / "kr_ros_industrial.urdf"
GEN3 = Path(__file__).resolve().parents[3] / "shared" / "data" / "kinova-gen3" / "gen3.urdf"

UR5_JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
              "wrist_2_joint", "wrist_3_joint")


def load_strict_warnings(path: Path, **kwargs: object) -> Robot:
    """``rd.load`` with every warning turned into an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return rd.load(path, **kwargs)


def end_pose(robot: Robot, q: np.ndarray) -> np.ndarray:
    """``base @ prod(pre @ motion(q) @ post) @ tool`` evaluated numerically, shape (4, 4)."""
    t = np.array(robot.base, dtype=float)
    for joint, qi in zip(robot.joints, q, strict=True):
        if joint.type == "revolute":
            motion = S.rot_h(S.axis_angle(joint.axis, sp.Float(qi)))
        else:
            motion = S.trans(*(joint.axis * sp.Float(qi)))
        t = t @ np.array(joint.pre * motion * joint.post, dtype=float)
    return t @ np.array(robot.tool, dtype=float)


def pin_frame(path: Path, frame: str, q: np.ndarray) -> np.ndarray:
    """Pose of URDF link ``frame`` in the root link's frame, from Pinocchio, shape (4, 4)."""
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    pin.forwardKinematics(model, data, pin_q(model, q))
    pin.updateFramePlacements(model, data)
    return data.oMf[model.getFrameId(frame)].homogeneous


# ----------------------------------------------------------------------------------------------
# the files load


def test_whitespace_before_the_xml_declaration_is_accepted(tmp_path: Path) -> None:
    text = UR5.read_text()
    path = tmp_path / "pasted.urdf"
    path.write_text("\n  \n\t" + text)
    robot = load_strict_warnings(path)
    assert robot.joint_names == UR5_JOINTS
    original = load_strict_warnings(UR5)
    assert (robot.joints, robot.links, robot.tool) == (original.joints, original.links, original.tool)
    assert KR.read_bytes().startswith(b"\n")  # the KUKA-style fixture starts that way too
    assert load_strict_warnings(KR).dof == 6


def test_ur5_style_file_with_world_base_ee_link_and_tool0_loads() -> None:
    robot = load_strict_warnings(UR5)
    assert robot.joint_names == UR5_JOINTS
    assert [lk.name for lk in robot.links] == ["shoulder_link", "upper_arm_link", "forearm_link",
                                                "wrist_1_link", "wrist_2_link", "wrist_3_link"]
    # ee_link and tool0 both hang off wrist_3_link: the tool defaults to the last moving link
    assert robot.tool == sp.eye(4)
    # world -> base_link is the identity; base_link's own mass is carried by the ground
    assert robot.base == sp.eye(4)
    masses = [3.7, 8.393, 2.275, 1.219, 1.219, 0.1879]
    np.testing.assert_allclose([float(lk.mass) for lk in robot.links], masses, rtol=1e-15)


def test_kr_style_file_default_tool_follows_the_unbranched_fixed_run() -> None:
    robot = load_strict_warnings(KR)
    assert robot.joint_names == tuple(f"joint_a{k}" for k in range(1, 7))
    # link_6 -> flange -> tool0 is one unbranched run: the tool is tool0
    assert robot.tool == load_strict_warnings(KR, tool="tool0").tool
    assert robot.tool != sp.eye(4)
    # the world -> base_link placement becomes the base; the camera's 0.4 kg joins link_5
    base = np.array(robot.base, dtype=float)
    np.testing.assert_allclose(base[:3, 3], [0.5, -0.2, 0.8], atol=1e-15)
    assert float(robot.links[4].mass) == pytest.approx(1.2 + 0.4, rel=1e-15)


def test_massless_side_frames_change_nothing(tmp_path: Path) -> None:
    """Removing base, ee_link and tool0 (no inertia) gives the same links and joints."""
    text = UR5.read_text()
    for start, end in [('<link name="base"/>', "</joint>\n  <!-- Frame"),
                       ('<joint name="ee_fixed_joint"', "</link>\n  <transmission"),
                       ('<link name="tool0"/>', "</joint>\n</robot>")]:
        i = text.index(start)
        j = text.index(end, i) + len(end.split("\n")[0])
        text = text[:i] + text[j:]
    for gone in ('"tool0"', '"ee_link"', '"base"'):
        assert f"<link name={gone}" not in text
    path = tmp_path / "bare.urdf"
    path.write_text(text)
    bare, full = load_strict_warnings(path), load_strict_warnings(UR5)
    assert bare.links == full.links
    assert bare.joints == full.joints
    assert bare.tool == full.tool == sp.eye(4)


# ----------------------------------------------------------------------------------------------
# the tool link


@pytest.mark.oracle("pinocchio")
@pytest.mark.parametrize(("path", "tool"), [(UR5, "tool0"), (UR5, "ee_link"), (UR5, None),
                                            (KR, "flange"), (KR, "tool0"), (KR, "link_6")])
def test_tool_pose_is_the_chosen_links_pose(path: Path, tool: str | None) -> None:
    robot = load_strict_warnings(path, tool=tool)
    frame = tool or "wrist_3_link"
    rng = np.random.default_rng(3)
    for _ in range(4):
        q = rng.uniform(-math.pi, math.pi, robot.dof)
        np.testing.assert_allclose(end_pose(robot, q), pin_frame(path, frame, q), atol=1e-12)


@pytest.mark.oracle("pinocchio")
def test_compiled_forward_kinematics_returns_the_tool_link_pose() -> None:
    robot = load_strict_warnings(UR5, tool="tool0")
    model = rd.compile_model(robot, backend="numpy")
    q = np.random.default_rng(5).uniform(-math.pi, math.pi, (3, 6))
    poses = model.forward_kinematics(q)
    assert poses.shape == (3, 4, 4)
    for k in range(3):
        np.testing.assert_allclose(poses[k], pin_frame(UR5, "tool0", q[k]), atol=1e-12)
        assert not np.allclose(poses[k], pin_frame(UR5, "wrist_3_link", q[k]), atol=1e-3)


@pytest.mark.parametrize(("tool", "match"), [
    ("gripper", r"ur5_ros_industrial\.urdf: tool link 'gripper' is not a link of the file.*"
                r"'ee_link'.*'tool0'"),
    ("forearm_link", r"tool link 'forearm_link' is not beyond the last moving joint "
                     r"'wrist_3_joint'"),
    ("base", r"tool link 'base' is not beyond the last moving joint"),
])
def test_bad_tool_link_is_a_clear_error(tool: str, match: str) -> None:
    with pytest.raises(DescriptionError, match=match):
        rd.load(UR5, tool=tool)


def test_camera_off_the_wrist_is_not_beyond_the_last_joint() -> None:
    with pytest.raises(DescriptionError, match=r"tool link 'camera_link' is not beyond .*'joint_a6'"):
        rd.load(KR, tool="camera_link")


def test_tool_needs_a_urdf() -> None:
    with pytest.raises(DescriptionError, match=r"puma560: tool='tool0' selects a link of a URDF"):
        rd.load("puma560", tool="tool0")


# ----------------------------------------------------------------------------------------------
# dynamics against Pinocchio on the same files


@pytest.mark.oracle("pinocchio")
@pytest.mark.parametrize("path", [UR5, KR], ids=["ur5", "kr"])
def test_dynamics_match_pinocchio(path: Path) -> None:
    """M, g and inverse dynamics; the camera's inertia is in link_5, massless frames nowhere."""
    robot = load_strict_warnings(path, tool="tool0")
    eom = rd.derive(robot, method="newton_euler")
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    f_m = program_evaluator(eom, eom.M_rigid_form)
    f_g = program_evaluator(eom, eom.g_form)
    f_tau = program_evaluator(eom, eom.program)
    rng = np.random.default_rng(11)
    for _ in range(4):
        q, qd, qdd = rng.uniform(-2, 2, (3, robot.dof))
        pq = pin_q(model, q)
        np.testing.assert_allclose(f_m(q), pin.crba(model, data, pq), atol=1e-12, rtol=1e-12)
        np.testing.assert_allclose(f_g(q).ravel(), pin.computeGeneralizedGravity(model, data, pq),
                                   atol=1e-12, rtol=1e-12)
        np.testing.assert_allclose(f_tau(q, qd, qdd).ravel(), pin.rnea(model, data, pq, qd, qdd),
                                   atol=1e-12, rtol=1e-12)
    moving = sum(model.inertias[k].mass for k in range(1, model.njoints))
    assert sum(float(lk.mass) for lk in robot.links) == pytest.approx(moving, rel=1e-14)


# ----------------------------------------------------------------------------------------------
# branching movable trees keep their clear error


def _with(text: str, extra: str) -> str:
    return text.replace("</robot>", extra + "</robot>")


def _finger(name: str, parent: str) -> str:
    return (f'<link name="{name}"><inertial><mass value="0.1"/>'
            '<inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>'
            f'<joint name="{name}_joint" type="prismatic"><parent link="{parent}"/>'
            f'<child link="{name}"/><axis xyz="0 1 0"/>'
            '<limit lower="0" upper="0.04" effort="10" velocity="0.1"/></joint>')


def test_two_fingers_are_a_branching_tree(tmp_path: Path) -> None:
    path = tmp_path / "gripper.urdf"
    path.write_text(_with(UR5.read_text(), _finger("left", "tool0") + _finger("right", "tool0")))
    with pytest.raises(DescriptionError, match=r"gripper\.urdf: link 'tool0' has 2 child joints "
                       r"\('left_joint', 'right_joint'\).*branching trees are not supported"):
        rd.load(path)


def test_moving_joint_on_a_side_branch_is_a_branching_tree(tmp_path: Path) -> None:
    path = tmp_path / "rail.urdf"
    path.write_text(_with(UR5.read_text(), _finger("slide", "base")))
    with pytest.raises(DescriptionError, match=r"link 'base_link' has 2 child joints "
                       r"\('shoulder_pan_joint', 'base_link-base_fixed_joint'\) leading to the "
                       r"moving joints"):
        rd.load(path)


def test_one_finger_after_the_arm_is_still_a_serial_chain(tmp_path: Path) -> None:
    path = tmp_path / "one_finger.urdf"
    path.write_text(_with(UR5.read_text(), _finger("finger", "tool0")))
    robot = load_strict_warnings(path)
    assert robot.joint_names == (*UR5_JOINTS, "finger_joint")


# ----------------------------------------------------------------------------------------------
# links without <inertial>: a singular mass matrix is named at load


def _arm(tmp_path: Path, links: str, joints: str) -> Path:
    path = tmp_path / "arm.urdf"
    path.write_text(f'<?xml version="1.0"?>\n<robot name="arm">{links}{joints}</robot>\n')
    return path


def _link(name: str, mass: float | None, xyz: str = "0 0 0") -> str:
    if mass is None:
        return f'<link name="{name}"/>'
    return (f'<link name="{name}"><inertial><origin xyz="{xyz}"/><mass value="{mass}"/>'
            '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>')


def _joint(name: str, parent: str, child: str, axis: str = "0 0 1", xyz: str = "0 0 0.1",
           jtype: str = "revolute") -> str:
    return (f'<joint name="{name}" type="{jtype}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>'
            '<limit lower="-3" upper="3" effort="10" velocity="1"/></joint>')


def test_last_link_without_inertial_warns_naming_the_joint_and_link(tmp_path: Path) -> None:
    path = _arm(tmp_path, _link("base", 1.0) + _link("a", 2.0, "0.2 0 0") + _link("b", None),
                _joint("j1", "base", "a") + _joint("j2", "a", "b", axis="0 1 0", xyz="0.3 0 0"))
    with pytest.warns(DescriptionWarning, match=r"arm\.urdf: the mass matrix is singular: "
                      r"joint 'j2' moves no inertia.*'b'.*no <inertial>") as record:
        robot = rd.load(path)
    assert "'j1'" not in str(record[0].message)
    assert robot.dof == 2  # kinematics still work
    with pytest.raises(DescriptionError, match=r"joint 'j2' moves no inertia.*strict mode"):
        rd.load(path, strict=True)


def test_massless_link_with_massive_children_is_fine(tmp_path: Path) -> None:
    """A massless intermediate link, a massless link with a massive fixed child: no warning."""
    links = (_link("base", 1.0) + _link("a", None) + _link("b", None) + _link("b_tool", 0.5,
             "0.1 0 0"))
    joints = (_joint("j1", "base", "a") + _joint("j2", "a", "b", axis="0 1 0", xyz="0.3 0 0")
              + _joint("fix", "b", "b_tool", jtype="fixed"))
    robot = load_strict_warnings(_arm(tmp_path, links, joints))
    assert float(robot.links[1].mass) == 0.5


def test_coincident_axes_with_nothing_between_are_named(tmp_path: Path) -> None:
    links = _link("base", 1.0) + _link("a", None) + _link("b", 2.0, "0.3 0 0")
    joints = _joint("j1", "base", "a") + _joint("j2", "a", "b", xyz="0 0 0.2")
    with pytest.warns(DescriptionWarning, match=r"singular: the motions of joints 'j1', 'j2' "
                      r"move the inertia in the same way"):
        rd.load(_arm(tmp_path, links, joints))


# ----------------------------------------------------------------------------------------------
# built-ins load quietly; user files still warn


@pytest.mark.parametrize("name", rd.builtin_names())
def test_every_builtin_loads_without_warnings(name: str) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rd.load(name)
        rd.load(name, strict=True)


def test_known_properties_name_links_of_the_builtins() -> None:
    for name, links in KNOWN_PROPERTIES.items():
        robot = rd.load(name)
        assert set(links) <= {lk.name for lk in robot.links}, name


def test_a_user_copy_of_a_builtin_still_warns(tmp_path: Path) -> None:
    from importlib import resources

    path = tmp_path / "my_puma.yaml"
    path.write_text((resources.files("robodyn.robot.library") / "puma560.yaml").read_text())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rd.load(path)
    messages = [str(w.message) for w in caught]
    assert any(re.search(r"my_puma\.yaml.*link 'link3'.*triangle", m) for m in messages)
    assert any(re.search(r"my_puma\.yaml.*link 'link1'.*triangle", m) for m in messages)


# ----------------------------------------------------------------------------------------------
# the Kinova Gen3 file as published


@pytest.mark.data(GEN3)
def test_kinova_gen3_file_loads_and_its_tool_can_be_chosen() -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = rd.load(GEN3)  # a user file: the manufacturer's shoulder inertia is reported
    assert any(re.search(r"gen3\.urdf.*'shoulder_link'.*triangle", str(w.message)) for w in caught)
    assert robot.dof == 7
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DescriptionWarning)
        bracelet = rd.load(GEN3, tool="bracelet_link")
    assert bracelet.tool == sp.eye(4)
    assert robot.tool != sp.eye(4)  # end_effector_link by default
    assert bracelet.links == robot.links


def test_yaml_description_with_a_massless_last_link_warns_too(tmp_path: Path) -> None:
    path = tmp_path / "arm.yaml"
    path.write_text(
        "name: arm\njoints:\n"
        "  - {name: j1, type: revolute, dh: {a: 0.5, alpha: 0, d: 0, theta: 0},\n"
        "     link: {name: upper, mass: 1.0, com: [-0.25, 0, 0]}}\n"
        "  - {name: j2, type: revolute, dh: {a: 0.4, alpha: 0, d: 0, theta: 0},\n"
        "     link: {name: empty, mass: 0}}\n"
    )
    with pytest.warns(DescriptionWarning, match=r"arm\.yaml: the mass matrix is singular: "
                      r"joint 'j2' moves no inertia.*'empty'"):
        rd.load(path)
