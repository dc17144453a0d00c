"""URDF loading: serial chains only, fixed-joint merging, and Pinocchio as a kinematic oracle."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from robodyn import spatial as S
from robodyn.robot.errors import DescriptionError, DescriptionWarning
from robodyn.robot.model import Robot
from robodyn.robot.urdf import load_urdf, number

try:  # test-only oracle: the tests that use it are marked and skip alone (see tests/conftest.py)
    import pinocchio as pin
except ImportError:
    pin = None

GEN3 = Path(__file__).resolve().parents[3] / "shared" / "data" / "kinova-gen3" / "gen3.urdf"
needs_gen3 = pytest.mark.data(GEN3)

_INERTIA = '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'


def link_xml(name: str, mass: float = 1.0, xyz: str = "0 0 0", rpy: str = "0 0 0") -> str:
    """A link with a simple inertial block."""
    return (
        f'<link name="{name}"><inertial><origin xyz="{xyz}" rpy="{rpy}"/>'
        f'<mass value="{mass}"/>{_INERTIA}</inertial></link>'
    )


def joint_xml(
    name: str, parent: str, child: str, jtype: str = "revolute", xyz: str = "0 0 0.1",
    extra: str = "",
) -> str:
    """A joint about z with limits."""
    return (
        f'<joint name="{name}" type="{jtype}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}" rpy="0 0 0"/><axis xyz="0 0 1"/>'
        f'<limit lower="-1" upper="1" velocity="1" effort="10"/>{extra}</joint>'
    )


def write(tmp_path: Path, body: str, name: str = "arm") -> Path:
    """Write ``<robot>`` with ``body`` to ``tmp_path/arm.urdf``."""
    path = tmp_path / "arm.urdf"
    path.write_text(f'<?xml version="1.0"?>\n<robot name="{name}">{body}</robot>\n')
    return path


def load_quiet(path: Path) -> Robot:
    """Load, ignoring plausibility warnings (random inertias are plausible anyway)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DescriptionWarning)
        return load_urdf(path)


# ----------------------------------------------------------------------------------------------
# bad input


def test_branching_tree_is_rejected(tmp_path: Path) -> None:
    body = "".join(link_xml(n) for n in ("base", "a", "b")) + joint_xml(
        "ja", "base", "a"
    ) + joint_xml("jb", "base", "b")
    path = write(tmp_path, body)
    with pytest.raises(DescriptionError, match=r"arm\.urdf.*link 'base'.*'ja'.*'jb'.*branching"):
        load_urdf(path)


@pytest.mark.parametrize("jtype", ["floating", "planar"])
def test_floating_and_planar_joints_are_not_supported_yet(tmp_path: Path, jtype: str) -> None:
    body = link_xml("base") + link_xml("a") + joint_xml("j1", "base", "a", jtype)
    with pytest.raises(DescriptionError, match=rf"joint 'j1'.*{jtype}.*not supported yet"):
        load_urdf(write(tmp_path, body))


def test_mimic_joint_is_not_supported_yet(tmp_path: Path) -> None:
    body = "".join(link_xml(n) for n in ("base", "a", "b")) + joint_xml("j1", "base", "a")
    body += joint_xml("j2", "a", "b", extra='<mimic joint="j1" multiplier="2" offset="0"/>')
    with pytest.raises(DescriptionError, match=r"joint 'j2'.*mimic.*not supported yet"):
        load_urdf(write(tmp_path, body))


def test_malformed_xml_names_the_file(tmp_path: Path) -> None:
    path = tmp_path / "broken.urdf"
    path.write_text('<robot name="x"><link name="a"></robot>')
    with pytest.raises(DescriptionError, match=r"broken\.urdf: not a parseable URDF"):
        load_urdf(path)


def test_not_a_robot_element(tmp_path: Path) -> None:
    path = tmp_path / "other.urdf"
    path.write_text("<model/>")
    with pytest.raises(DescriptionError, match=r"other\.urdf.*root element is <model>"):
        load_urdf(path)


def test_no_joints(tmp_path: Path) -> None:
    with pytest.raises(DescriptionError, match=r"arm\.urdf.*has no joints"):
        load_urdf(write(tmp_path, link_xml("base")))


def test_only_fixed_joints(tmp_path: Path) -> None:
    body = link_xml("base") + link_xml("a") + joint_xml("j1", "base", "a", "fixed")
    with pytest.raises(DescriptionError, match=r"no moving joint"):
        load_urdf(write(tmp_path, body))


def test_undefined_link(tmp_path: Path) -> None:
    body = link_xml("base") + joint_xml("j1", "base", "ghost")
    with pytest.raises(DescriptionError, match=r"joint 'j1': child link 'ghost' is not defined"):
        load_urdf(write(tmp_path, body))


def test_joint_without_parent(tmp_path: Path) -> None:
    body = link_xml("base") + link_xml("a") + joint_xml("j1", "base", "a").replace(
        '<parent link="base"/>', ""
    )
    with pytest.raises(DescriptionError, match=r"joint 'j1' has no <parent link=...>"):
        load_urdf(write(tmp_path, body))


def test_loop_is_rejected(tmp_path: Path) -> None:
    body = link_xml("a") + link_xml("b") + joint_xml("j1", "a", "b") + joint_xml("j2", "b", "a")
    with pytest.raises(DescriptionError, match=r"no root link"):
        load_urdf(write(tmp_path, body))


def test_zero_axis_and_non_finite_numbers(tmp_path: Path) -> None:
    body = link_xml("base") + link_xml("a") + joint_xml("j1", "base", "a").replace(
        '<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'
    )
    with pytest.raises(DescriptionError, match=r"joint 'j1'.*axis is the zero vector"):
        load_urdf(write(tmp_path, body))
    body = link_xml("base") + link_xml("a") + joint_xml("j1", "base", "a", xyz="0 nan 0")
    with pytest.raises(DescriptionError, match=r"joint 'j1'.*finite"):
        load_urdf(write(tmp_path, body))


def test_negative_mass_is_rejected(tmp_path: Path) -> None:
    body = link_xml("base") + link_xml("a", mass=-1.0) + joint_xml("j1", "base", "a")
    with pytest.raises(DescriptionError, match=r"arm\.urdf.*'a'.*negative"):
        load_urdf(write(tmp_path, body))


def test_strict_turns_implausible_inertia_into_an_error(tmp_path: Path) -> None:
    bad = '<inertia ixx="1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/>'
    body = link_xml("base") + link_xml("a").replace(_INERTIA, bad) + joint_xml("j1", "base", "a")
    path = write(tmp_path, body)
    with pytest.warns(DescriptionWarning, match="triangle inequality"):
        load_urdf(path)
    with pytest.raises(DescriptionError, match="triangle inequality"):
        load_urdf(path, strict=True)


# ----------------------------------------------------------------------------------------------
# mapping of URDF fields


def test_numbers_keep_exact_zeros_and_ones() -> None:
    assert number("0", where="w") is sp.S.Zero
    assert number(-0.0, where="w") is sp.S.Zero
    assert number("1.0", where="w") is sp.S.One
    assert number(-1.0, where="w") is sp.S.NegativeOne
    assert number("0.1", where="w") == sp.Float(0.1)
    with pytest.raises(DescriptionError, match="w: expected a number"):
        number("abc", where="w")


def test_fields_limits_friction_and_continuous(tmp_path: Path) -> None:
    body = "".join(link_xml(n) for n in ("base", "a", "b", "c"))
    dynamics = '<dynamics damping="0.5" friction="2"/>'
    body += joint_xml("j1", "base", "a", "continuous", extra=dynamics)
    body += joint_xml("j2", "a", "b", "prismatic")
    body += joint_xml("j3", "b", "c")
    robot = load_urdf(write(tmp_path, body, name="my_arm"))
    assert robot.name == "my_arm"
    assert robot.dof == 3
    assert [j.type for j in robot.joints] == ["revolute", "prismatic", "revolute"]
    j1, j2, _ = robot.joints
    assert j1.lower is None and j1.upper is None
    assert (j1.velocity_limit, float(j1.effort_limit)) == (1, 10.0)
    assert (j2.lower, j2.upper) == (-1, 1)
    assert j1.friction.viscous == sp.Float(0.5)
    assert j1.friction.coulomb_positive == j1.friction.coulomb_negative == sp.Float(2.0)
    assert j2.friction.is_zero
    assert j1.pre == S.trans(0, 0, sp.Float(0.1))  # exact zeros and ones in the rotation
    assert robot.gravity == sp.ImmutableMatrix([0, 0, sp.Rational(-981, 100)])
    assert robot.source == str(tmp_path / "arm.urdf")


def test_link_without_inertial_has_zero_mass(tmp_path: Path) -> None:
    body = link_xml("base") + '<link name="a"/>' + joint_xml("j1", "base", "a")
    # the only moving link is then massless: the load says the mass matrix is singular
    with pytest.warns(DescriptionWarning, match=r"joint 'j1' moves no inertia.*'a' have no <inertial>"):
        robot = load_urdf(write(tmp_path, body))
    assert robot.links[0].mass == 0
    assert robot.links[0].inertia == sp.zeros(3)


def test_inertial_origin_rotates_the_inertia(tmp_path: Path) -> None:
    inertia = '<inertia ixx="1" iyy="2" izz="3" ixy="0" ixz="0" iyz="0"/>'
    link = link_xml("a", mass=2.0, xyz="0.1 0.2 0.3", rpy=f"0 0 {math.pi / 2!r}")
    body = link_xml("base") + link.replace(_INERTIA, inertia) + joint_xml("j1", "base", "a")
    lk = load_urdf(write(tmp_path, body)).links[0]
    assert list(lk.com) == [sp.Float(0.1), sp.Float(0.2), sp.Float(0.3)]
    # a quarter turn about z swaps the x and y principal moments
    np.testing.assert_allclose(np.array(lk.inertia, dtype=float), np.diag([2, 1, 3]), atol=1e-15)


def test_fixed_joints_are_merged(tmp_path: Path) -> None:
    """A fixed child's mass adds to its parent; the combined COM is the mass-weighted mean."""
    body = "".join(
        [
            link_xml("world", 5.0),
            link_xml("base", 3.0, xyz="0 0 0.05"),
            link_xml("a", 2.0, xyz="0.1 0 0"),
            link_xml("a_cover", 1.0, xyz="0 0.2 0", rpy="0 0 1.5707963267948966"),
            link_xml("b", 1.5, xyz="0 0 0.3"),
            link_xml("flange", 0.5, xyz="0 0 0.01"),
            '<link name="tcp"/>',
            joint_xml("world_fix", "world", "base", "fixed", xyz="0 0 0.2"),
            joint_xml("j1", "base", "a", xyz="0 0 0.1"),
            # the cover is welded 0.3 m along x of link a, turned a quarter about z
            '<joint name="cover_fix" type="fixed"><parent link="a"/><child link="a_cover"/>'
            '<origin xyz="0.3 0 0" rpy="0 0 1.5707963267948966"/></joint>',
            joint_xml("j2", "a_cover", "b", xyz="0 0 0.4"),
            joint_xml("flange_fix", "b", "flange", "fixed", xyz="0 0 0.5"),
            joint_xml("tcp_fix", "flange", "tcp", "fixed", xyz="0 0 0.05"),
        ]
    )
    robot = load_urdf(write(tmp_path, body))
    assert robot.joint_names == ("j1", "j2")
    a, b = robot.links
    # link a + cover: the cover COM (0, 0.2, 0) in its own frame is at (0.3 - 0.2, 0, 0) in a
    assert float(a.mass) == pytest.approx(3.0)
    np.testing.assert_allclose(
        np.array(a.com, dtype=float).ravel(), [(2.0 * 0.1 + 1.0 * 0.1) / 3.0, 0.0, 0.0],
        atol=1e-15,
    )
    # link b + flange (COM 0.5 + 0.01 along z) + massless tcp
    assert float(b.mass) == pytest.approx(2.0)
    np.testing.assert_allclose(
        np.array(b.com, dtype=float).ravel(), [0, 0, (1.5 * 0.3 + 0.5 * 0.51) / 2.0], atol=1e-15
    )
    total = sum(float(lk.mass) for lk in robot.links)
    assert total == pytest.approx(5.0)  # world and base (before j1) are carried by the ground
    # parallel-axis check of the combined inertia of b about its COM (z offsets only)
    c = (1.5 * 0.3 + 0.5 * 0.51) / 2.0
    ixx = 0.01 + 1.5 * (0.3 - c) ** 2 + 0.01 + 0.5 * (0.51 - c) ** 2
    assert float(b.inertia[0, 0]) == pytest.approx(ixx, rel=1e-14)
    assert float(b.inertia[2, 2]) == pytest.approx(0.02, rel=1e-14)
    # the fixed joints before the first moving joint go into the base, after the last: tool
    np.testing.assert_allclose(np.array(robot.base, dtype=float), translation(0, 0, 0.2))
    np.testing.assert_allclose(np.array(robot.tool, dtype=float), translation(0, 0, 0.55))
    # the cover's fixed transform is folded into j2's pre
    expected = np.array(S.rot_h(S.rotz(math.pi / 2)), dtype=float) @ translation(0, 0, 0.4)
    expected[:3, 3] += [0.3, 0, 0]
    np.testing.assert_allclose(np.array(robot.joints[1].pre, dtype=float), expected, atol=1e-15)


def translation(x: float, y: float, z: float) -> np.ndarray:
    """A numeric translation, shape (4, 4)."""
    t = np.eye(4)
    t[:3, 3] = [x, y, z]
    return t


# ----------------------------------------------------------------------------------------------
# Pinocchio as an independent oracle


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


def pinocchio_pose(model: object, tip: str, q: np.ndarray) -> np.ndarray:
    """Pose of link ``tip`` from Pinocchio (continuous joints take ``cos, sin``)."""
    data = model.createData()
    qp = np.zeros(model.nq)
    for k, jm in enumerate(model.joints[1:]):
        if jm.nq == 2:
            qp[jm.idx_q : jm.idx_q + 2] = [math.cos(q[k]), math.sin(q[k])]
        else:
            qp[jm.idx_q] = q[k]
    pin.forwardKinematics(model, data, qp)
    pin.updateFramePlacements(model, data)
    return data.oMf[model.getFrameId(tip)].homogeneous


def check_against_pinocchio(
    robot: Robot, model: object, tip: str, rng: np.random.Generator
) -> None:
    """End pose at random q, and each moving body's mass, COM and inertia, to 1e-9."""
    assert model.nv == robot.dof
    for _ in range(5):
        q = rng.uniform(-math.pi, math.pi, robot.dof)
        np.testing.assert_allclose(end_pose(robot, q), pinocchio_pose(model, tip, q), atol=1e-9)
    for k, link in enumerate(robot.links):
        body = model.inertias[k + 1]
        assert float(link.mass) == pytest.approx(body.mass, rel=1e-12, abs=1e-15)
        np.testing.assert_allclose(np.array(link.com, dtype=float).ravel(), body.lever, atol=1e-9)
        np.testing.assert_allclose(np.array(link.inertia, dtype=float), body.inertia, atol=1e-9)
    total = sum(float(lk.mass) for lk in robot.links)
    assert total == pytest.approx(sum(model.inertias[k].mass for k in range(1, model.njoints)))


@needs_gen3
def test_kinova_gen3_loads_with_seven_joints() -> None:
    robot = load_quiet(GEN3)
    assert robot.dof == 7
    assert robot.joint_names == tuple(f"joint_{k}" for k in range(1, 8))
    assert all(j.type == "revolute" for j in robot.joints)
    # joints 1, 3, 5, 7 are continuous: no position limits
    assert [j.lower is None for j in robot.joints] == [True, False] * 3 + [True]
    assert float(robot.joints[1].upper) == 2.41
    assert robot.links[-1].name == "bracelet_link"


@needs_gen3
@pytest.mark.oracle("pinocchio")
def test_kinova_gen3_matches_pinocchio() -> None:
    robot = load_quiet(GEN3)
    model = pin.buildModelFromUrdf(str(GEN3))
    check_against_pinocchio(robot, model, "end_effector_link", np.random.default_rng(7))


def _unit(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def _rot(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def _nums(values: np.ndarray) -> str:
    return " ".join(repr(float(v)) for v in values)


def random_chain_urdf(rng: np.random.Generator, n: int) -> tuple[str, str]:
    """A random serial URDF with ``n`` joints (text, tip link name)."""
    kinds = list(rng.choice(["revolute", "continuous", "prismatic", "fixed"], size=n))
    if all(k == "fixed" for k in kinds):
        kinds[int(rng.integers(n))] = "revolute"
    parts = []
    for k in range(n + 1):
        if rng.uniform() < 0.15:
            parts.append(f'<link name="l{k}"/>')
            continue
        # principal moments of a box (triangle inequality holds), rotated by a random rpy
        a, b, c = rng.uniform(0.05, 0.5, 3) ** 2
        m = rng.uniform(0.2, 5.0)
        moments = m / 12 * np.array([b + c, a + c, a + b])
        r = _rot(rng)
        tensor = r @ np.diag(moments) @ r.T
        parts.append(
            f'<link name="l{k}"><inertial>'
            f'<origin xyz="{_nums(rng.uniform(-0.2, 0.2, 3))}" '
            f'rpy="{_nums(rng.uniform(-math.pi, math.pi, 3))}"/>'
            f'<mass value="{float(m)!r}"/><inertia ixx="{float(tensor[0, 0])!r}" '
            f'iyy="{float(tensor[1, 1])!r}" izz="{float(tensor[2, 2])!r}" '
            f'ixy="{float(tensor[0, 1])!r}" ixz="{float(tensor[0, 2])!r}" '
            f'iyz="{float(tensor[1, 2])!r}"/></inertial></link>'
        )
    for k, kind in enumerate(kinds):
        limit = '<limit lower="-3" upper="3" velocity="2" effort="50"/>'
        parts.append(
            f'<joint name="j{k}" type="{kind}"><parent link="l{k}"/><child link="l{k + 1}"/>'
            f'<origin xyz="{_nums(rng.uniform(-0.5, 0.5, 3))}" '
            f'rpy="{_nums(rng.uniform(-math.pi, math.pi, 3))}"/>'
            f'<axis xyz="{_nums(_unit(rng))}"/>{limit if kind != "fixed" else ""}</joint>'
        )
    text = f'<?xml version="1.0"?>\n<robot name="random{n}">{"".join(parts)}</robot>\n'
    return text, f"l{n}"


@pytest.mark.oracle("pinocchio")
@pytest.mark.parametrize("seed", range(8))
def test_random_chains_match_pinocchio(tmp_path: Path, seed: int) -> None:
    rng = np.random.default_rng(seed)
    text, tip = random_chain_urdf(rng, int(rng.integers(2, 8)))
    path = tmp_path / f"random{seed}.urdf"
    path.write_text(text)
    robot = load_quiet(path)
    model = pin.buildModelFromXML(text)
    check_against_pinocchio(robot, model, tip, rng)
