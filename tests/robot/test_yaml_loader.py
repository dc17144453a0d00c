"""robodyn YAML descriptions: loading, kinematics against closed forms, and bad input."""

from __future__ import annotations

import copy
import dataclasses
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
import yaml

from robodyn import spatial as S
from robodyn.robot.errors import DescriptionError, DescriptionWarning
from robodyn.robot.expressions import parameter_symbol
from robodyn.robot.model import Joint, Robot
from robodyn.robot.yaml_loader import load_yaml_file, load_yaml_text

DOCS = Path(__file__).resolve().parents[2] / "docs" / "description-format.md"

TWO_LINK = """\
name: planar2r
description: test arm
parameters: {l1: 1.0, l2: 0.8, m1: 2.0, m2: 1.5, g: 9.81}
gravity: [0, 0, -g]
joints:
  - name: j1
    type: revolute
    dh: {a: l1, alpha: 0, d: 0, theta: 0}
    limits: {lower: -pi, upper: pi, velocity: 2, effort: 50}
    link:
      name: upper
      mass: m1
      com: [-l1/2, 0, 0]
      inertia: {ixx: 0, iyy: m1*l1^2/12, izz: m1*l1^2/12}
  - name: j2
    type: continuous
    dh: {a: l2}
    link:
      mass: m2
      com: [-l2/2, 0, 0]
      inertia: [[0.001, 0, 0], [0, m2*l2**2/12, 0], [0, 0, m2*l2**2/12]]
      hydro: {cylinders: [{radius: 0.05, length: l2, axis: [1, 0, 0], start: [-l2, 0, 0]}]}
"""

Q1, Q2 = sp.symbols("q1 q2", real=True)


def write(tmp_path: Path, text: str, name: str = "arm.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def motion(joint: Joint, q: sp.Expr) -> sp.ImmutableMatrix:
    """Joint motion: rotation about / translation along the joint axis."""
    if joint.type == "revolute":
        return S.rot_h(S.axis_angle(joint.axis, q))
    return S.trans(*(joint.axis * q))


def chain_pose(robot: Robot, qs) -> sp.Matrix:
    """Base-to-tool pose: base @ prod(pre @ motion(q) @ post) @ tool."""
    t = sp.Matrix(robot.base)
    for joint, q in zip(robot.joints, qs, strict=True):
        t = t * joint.pre * motion(joint, q) * joint.post
    return t * robot.tool


def numeric(m) -> np.ndarray:
    return np.array(sp.N(m), dtype=float)


# -- loading ------------------------------------------------------------------------------------


def test_two_link_arm_loads(tmp_path: Path) -> None:
    path = write(tmp_path, TWO_LINK)
    robot = load_yaml_file(path)
    l1, l2, m1, m2, g = (parameter_symbol(n) for n in ("l1", "l2", "m1", "m2", "g"))
    assert robot.name == "planar2r"
    assert robot.source == str(path)
    assert robot.dof == 2
    assert robot.joint_names == ("j1", "j2")
    assert [j.type for j in robot.joints] == ["revolute", "revolute"]  # continuous -> revolute
    assert dict(robot.parameters) == {"l1": 1.0, "l2": 0.8, "m1": 2.0, "m2": 1.5, "g": 9.81}
    assert robot.gravity == sp.ImmutableMatrix([0, 0, -g])
    up, fore = robot.links
    assert (up.name, fore.name) == ("upper", "j2_link")
    assert up.mass == m1
    assert up.com == sp.ImmutableMatrix([-l1 / 2, 0, 0])
    assert up.inertia == sp.ImmutableMatrix(sp.diag(0, m1 * l1**2 / 12, m1 * l1**2 / 12))
    assert fore.inertia[1, 1] == m2 * l2**2 / 12
    # the hydro block, parsed: expressions over the parameters, the defaults filled in
    (cyl,) = fore.hydro.cylinders
    assert (cyl.radius, cyl.length) == (sp.Float(0.05), l2)
    assert cyl.axis == sp.ImmutableMatrix([1, 0, 0]) and cyl.start == sp.ImmutableMatrix([-l2, 0, 0])
    assert (fore.hydro.added_mass, fore.hydro.drag, fore.hydro.lift) == (1.0, 1.2, 0.0)
    assert sp.simplify(fore.hydro.volume - sp.pi * sp.Float(0.05) ** 2 * l2) == 0
    assert sp.simplify(fore.hydro.center_of_buoyancy - sp.ImmutableMatrix([-l2 / 2, 0, 0])) == sp.zeros(3, 1)
    assert robot.fluid is None and fore.hydro.quadrature == 6
    j1 = robot.joints[0]
    assert j1.lower == -sp.pi and j1.upper == sp.pi
    assert j1.velocity_limit == 2 and j1.effort_limit == 50
    assert j1.convention == "dh"
    assert dict(j1.source_params) == {"a": l1, "alpha": 0, "d": 0, "theta": 0}
    assert robot.joints[1].lower is None
    assert robot.joints[1].friction.is_zero


def test_defaults_without_optional_sections() -> None:
    text = "name: one\njoints: [{name: j, type: prismatic, mdh: {}, link: {mass: 1}}]\n"
    robot = load_yaml_text(text, source="mem")
    assert robot.source == "mem"
    assert robot.gravity == sp.ImmutableMatrix([0, 0, sp.Rational(-981, 100)])
    assert robot.base == sp.eye(4) and robot.tool == sp.eye(4)
    assert robot.parameters == {}
    assert robot.links[0].com == sp.zeros(3, 1) and robot.links[0].inertia == sp.zeros(3)
    assert robot.joints[0].type == "prismatic"
    assert robot.joints[0].drive.gear_ratio == 1


def test_description_example_in_docs_loads() -> None:
    text = DOCS.read_text()
    block = re.search(r"```yaml\n(.*?)```", text, re.S).group(1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        robot = load_yaml_text(block, source="docs")
    assert robot.joint_names == ("shoulder", "elbow")  # fixed flange merged
    m2 = parameter_symbol("m2")
    assert sp.simplify(robot.links[1].mass - (m2 + sp.Float(0.3))) == 0
    fr = robot.joints[0].friction
    assert float(fr.viscous) == pytest.approx(2.0e-5 * 100**2)
    assert float(fr.coulomb_positive) == pytest.approx(0.4)
    assert float(fr.coulomb_negative) == pytest.approx(0.4)


def test_user_data_is_not_mutated(tmp_path: Path) -> None:
    data = yaml.safe_load(TWO_LINK)
    before = copy.deepcopy(data)
    robot = load_yaml_text(yaml.safe_dump(data), source="mem")
    assert data == before
    with pytest.raises(dataclasses.FrozenInstanceError):
        robot.links[1].hydro.drag = 2.0  # type: ignore[misc]


def test_exact_pi_over_2_folding() -> None:
    text = """\
name: a
joints:
  - {name: j1, type: revolute, dh: {a: 0, alpha: pi/2, d: 0.3, theta: 0}, link: {mass: 1}}
  - {name: j2, type: revolute, dh: {alpha: -pi/2}, link: {mass: 1}}
"""
    robot = load_yaml_text(text, source="mem")
    post = robot.joints[0].post
    d = sp.Float(0.3)
    assert post == sp.ImmutableMatrix([[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, d], [0, 0, 0, 1]])
    assert all(isinstance(e, sp.Integer) for k, e in enumerate(post) if k != 11)
    assert robot.joints[1].post == sp.ImmutableMatrix(
        [[1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]]
    )


# -- kinematics against closed forms ---------------------------------------------------------


def test_dh_chain_matches_planar_2r_closed_form() -> None:
    robot = load_yaml_text(TWO_LINK, source="mem")
    l1, l2 = parameter_symbol("l1"), parameter_symbol("l2")
    t = chain_pose(robot, (Q1, Q2))
    expected = [l1 * sp.cos(Q1) + l2 * sp.cos(Q1 + Q2), l1 * sp.sin(Q1) + l2 * sp.sin(Q1 + Q2), 0]
    for k in range(3):
        assert sp.simplify(t[k, 3] - expected[k]) == 0
    assert sp.simplify(t[0, 0] - sp.cos(Q1 + Q2)) == 0
    # and equals the product of standard DH matrices
    dh = S.dh_standard(l1, 0, 0, Q1) * S.dh_standard(l2, 0, 0, Q2)
    assert sp.simplify(t - dh) == sp.zeros(4)


def test_spatial_dh_chain_matches_dh_products_numerically() -> None:
    text = """\
name: puma_like
parameters: {a2: 0.4318, d3: 0.15005}
base: {xyz: [0, 0, 0.6]}
tool: {xyz: [0, 0, 0.1]}
joints:
  - {name: j1, type: revolute, dh: {alpha: pi/2}, link: {mass: 1}}
  - {name: j2, type: revolute, dh: {a: a2, theta: 0.1}, link: {mass: 1}}
  - {name: j3, type: prismatic, dh: {a: 0.0203, alpha: -pi/2, d: d3, theta: pi/6}, link: {mass: 1}}
"""
    robot = load_yaml_text(text, source="mem")
    q = (0.3, -1.1, 0.25)
    t = chain_pose(robot, q).subs(robot.defaults())
    a2, d3 = 0.4318, 0.15005
    ref = (
        S.trans(0, 0, 0.6)
        * S.dh_standard(0, sp.pi / 2, 0, q[0])
        * S.dh_standard(a2, 0, 0, 0.1 + q[1])
        * S.dh_standard(0.0203, -sp.pi / 2, d3 + q[2], sp.pi / 6)
        * S.trans(0, 0, 0.1)
    )
    np.testing.assert_allclose(numeric(t), numeric(ref), atol=1e-12)


def test_mdh_chain_matches_planar_2r_closed_form() -> None:
    text = """\
name: a
parameters: {l1: 0.7, l2: 0.5}
tool: {xyz: [l2, 0, 0]}
joints:
  - {name: j1, type: revolute, mdh: {a: 0, alpha: 0}, link: {mass: 1}}
  - {name: j2, type: revolute, mdh: {a: l1}, link: {mass: 1}}
"""
    robot = load_yaml_text(text, source="mem")
    assert robot.joints[1].convention == "mdh"
    for q in [(0.0, 0.0), (0.4, -1.3), (2.5, 0.9)]:
        p = numeric(chain_pose(robot, q).subs(robot.defaults()))[:3, 3]
        x = 0.7 * np.cos(q[0]) + 0.5 * np.cos(q[0] + q[1])
        y = 0.7 * np.sin(q[0]) + 0.5 * np.sin(q[0] + q[1])
        np.testing.assert_allclose(p, [x, y, 0.0], atol=1e-12)


def test_origin_placement_and_axis_normalisation() -> None:
    text = """\
name: a
joints:
  - name: slide
    type: prismatic
    origin: {xyz: [0.1, 0.2, 0.3], rpy: [0, 0, pi/2]}
    axis: [0, 0, 2]
    link: {mass: 1}
  - name: turn
    type: revolute
    origin: {xyz: [1, 0, 0]}
    axis: [1, 1, 0]
    link: {mass: 1}
"""
    robot = load_yaml_text(text, source="mem")
    slide, turn = robot.joints
    assert slide.axis == sp.ImmutableMatrix([0, 0, 1])
    assert turn.axis == sp.ImmutableMatrix([1, 1, 0]) / sp.sqrt(2)
    assert slide.convention == "origin"
    assert slide.source_params["z"] == sp.Float(0.3) and slide.source_params["yaw"] == sp.pi / 2
    # slide by 0.5 along z, then turn by pi about (1,1,0)/sqrt2 maps x -> y
    t = numeric(chain_pose(robot, (0.5, sp.pi)))
    rz = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]])
    np.testing.assert_allclose(t[:3, 3], [0.1, 0.2 + 1.0, 0.8], atol=1e-12)
    np.testing.assert_allclose(t[:3, :3] @ [1, 0, 0], rz @ [0, 1, 0], atol=1e-12)


def test_base_and_tool_poses() -> None:
    text = """\
name: a
base: {xyz: [1, 2, 3], rpy: [0, 0, pi]}
tool: {xyz: [0, 0, 0.25]}
joints: [{name: j, type: revolute, dh: {}, link: {mass: 1}}]
"""
    robot = load_yaml_text(text, source="mem")
    assert robot.base == sp.ImmutableMatrix(
        [[-1, 0, 0, 1], [0, -1, 0, 2], [0, 0, 1, 3], [0, 0, 0, 1]]
    )
    assert robot.tool == S.trans(0, 0, sp.Float(0.25))


def test_fixed_joints_are_merged() -> None:
    text = """\
name: a
joints:
  - {name: mount, type: fixed, origin: {xyz: [0, 0, 0.5]}, link: {name: pedestal, mass: 10}}
  - {name: j1, type: revolute, dh: {a: 1}, link: {mass: 2}}
  - {name: flange, type: fixed, origin: {xyz: [0.1, 0, 0]}, link: {mass: 1}}
"""
    robot = load_yaml_text(text, source="mem")
    assert robot.joint_names == ("j1",)
    assert robot.base == S.trans(0, 0, sp.Float(0.5))
    assert robot.links[0].mass == 3
    assert robot.tool == S.trans(sp.Float(0.1), 0, 0)


# -- drives and friction ------------------------------------------------------------------------


def friction_of(spec: str, drive: str = "") -> object:
    text = f"""\
name: a
joints:
  - name: j
    type: revolute
    dh: {{}}
    {drive}
    friction: {spec}
    link: {{mass: 1}}
"""
    return load_yaml_text(text, source="mem").joints[0].friction


def test_motor_side_friction_is_reflected() -> None:
    fr = friction_of(
        "{side: motor, viscous: 1.48e-3, coulomb: 0.4, offset: 0.01}",
        "drive: {gear_ratio: 62.6111, rotor_inertia: 200e-6, torque_constant: 0.26}",
    )
    assert float(fr.viscous) == pytest.approx(62.6111**2 * 1.48e-3, rel=1e-12)  # 5.8018...
    assert float(fr.viscous) == pytest.approx(5.80185, rel=1e-5)
    assert float(fr.coulomb_positive) == pytest.approx(25.04444, rel=1e-12)
    assert float(fr.coulomb_negative) == pytest.approx(25.04444, rel=1e-12)
    assert float(fr.offset) == pytest.approx(0.626111, rel=1e-12)


def test_motor_side_friction_negative_gear_swaps_directions() -> None:
    fr = friction_of(
        "{side: motor, viscous: 1e-3, coulomb_positive: 0.1, coulomb_negative: 0.2, offset: 0.01}",
        "drive: {gear_ratio: -50}",
    )
    assert float(fr.viscous) == pytest.approx(2.5, rel=1e-12)
    assert float(fr.coulomb_positive) == pytest.approx(10.0, rel=1e-12)  # 50 * 0.2
    assert float(fr.coulomb_negative) == pytest.approx(5.0, rel=1e-12)  # 50 * 0.1
    assert float(fr.offset) == pytest.approx(-0.5, rel=1e-12)


def test_joint_side_friction_is_kept() -> None:
    fr = friction_of("{viscous: 0.5, coulomb_positive: 0.395, coulomb_negative: 0.435}",
                     "drive: {gear_ratio: -62.6}")
    assert float(fr.viscous) == 0.5
    assert (float(fr.coulomb_positive), float(fr.coulomb_negative)) == (0.395, 0.435)
    assert fr.offset == 0


def test_drive_fields() -> None:
    text = """\
name: a
parameters: {k: 0.26}
joints:
  - {name: j, type: revolute, dh: {}, link: {mass: 1},
     drive: {gear_ratio: -62.6111, rotor_inertia: 200e-6, torque_constant: k}}
"""
    drive = load_yaml_text(text, source="mem").joints[0].drive
    assert float(drive.gear_ratio) == -62.6111
    assert float(drive.rotor_inertia) == pytest.approx(2e-4, rel=1e-15)
    assert drive.torque_constant == parameter_symbol("k")


# -- physical plausibility ----------------------------------------------------------------------


def link_yaml(link: str) -> str:
    return f"name: a\njoints:\n  - {{name: j, type: revolute, dh: {{}}, link: {link}}}\n"


def test_thin_rod_does_not_warn() -> None:
    text = "parameters: {m: 2, l: 0.6}\n" + link_yaml(
        "{name: rod, mass: m, inertia: {ixx: m*l^2/12, iyy: m*l^2/12, izz: 0}}"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_yaml_text(text, source="mem", strict=True)


def test_puma_link1_inertia_warns_and_strict_raises(tmp_path: Path) -> None:
    link = "{name: link1, mass: 0, inertia: {ixx: 0, iyy: 0.35, izz: 0}}"
    path = write(tmp_path, link_yaml(link))
    pattern = r"arm\.yaml: joints\[0\]\.link: link 'link1'.*triangle"
    with pytest.warns(DescriptionWarning, match=pattern):
        robot = load_yaml_file(path)
    assert robot.links[0].inertia[1, 1] == sp.Float(0.35)
    with pytest.raises(DescriptionError, match=r"link 'link1'.*triangle inequality"):
        load_yaml_file(path, strict=True)
