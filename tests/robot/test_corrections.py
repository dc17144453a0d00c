"""Joint-reading corrections in a description: YAML round trip, refusals, evaluation by hand.

The evaluation checks use references written here: the transmission terms by their formula, the
holding torque of point masses as the gradient of their potential energy (central differences of
positions from the compiled model's forward kinematics of a description with those masses), and
the compiled model's own gravity torque for a description's links.
"""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml

import robodyn as rd
from robodyn.numeric.joint_corrections import holding_torque, link_positions
from robodyn.robot.corrections import HoldingTorque
from robodyn.robot.errors import DescriptionError
from robodyn.robot.yaml_loader import load_yaml_text
from robodyn.robot.yaml_writer import dump_yaml

TWO_LINK = """
name: arm
gravity: [0, 0, -9.81]
joints:
  - {name: j1, type: revolute, origin: {xyz: [0, 0, 0.3]}, axis: [0, 1, 0],
     drive: {gear_ratio: 100},
     link: {name: l1, mass: 2.0, com: [0.2, 0, 0], inertia: {ixx: 0.01, iyy: 0.02, izz: 0.02}}}
  - {name: j2, type: revolute, origin: {xyz: [0.4, 0, 0]}, axis: [0, 1, 0],
     link: {name: l2, mass: 1.5, com: [0.15, 0, 0.01], inertia: {ixx: 0.01, iyy: 0.02, izz: 0.02}}}
tool: {xyz: [0.3, 0, 0]}
"""

CORRECTIONS = """
corrections:
  deflection: linear
  joints:
    j1: {ratio: 2.0e-4, cos1: 1.0e-4, sin1: -3.0e-5, motor_cos1: 2.0e-5, motor_sin1: -1.0e-5,
         compliance: 3.0e-4}
    j2: {compliance: 5.0e-4, sin1: 4.0e-5}
  holding_torque:
    source: test masses
    gravity: [0, 0, -9.81]
    axes:
      - {point: [0, 0, 0.3], direction: [0, 1, 0], type: revolute}
      - {point: [0.4, 0, 0.3], direction: [0, 1, 0], type: revolute}
    masses:
      - {mass: 2.0, moment: [0.4, 0, 0.6], moved_by: 1}
      - {mass: 1.5, moment: [0.825, 0, 0.465], moved_by: 2}
"""


def _load(text: str) -> rd.Robot:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_yaml_text(text, source="arm.yaml")


@pytest.fixture(scope="module")
def arm() -> rd.Robot:
    return _load(TWO_LINK + CORRECTIONS)


def test_round_trip_is_exact_and_changes_the_hash(arm):
    back = _load(dump_yaml(arm))
    assert back.corrections == arm.corrections
    rigid = _load(TWO_LINK)
    assert rigid.corrections is None and rigid.description_hash != arm.description_hash
    q = np.random.default_rng(0).uniform(-2, 2, (20, 2))
    np.testing.assert_array_equal(link_positions(back, q), link_positions(arm, q))
    np.testing.assert_array_equal(link_positions(rigid, q), q)


def test_link_angles_by_hand(arm):
    q = np.random.default_rng(1).uniform(-2, 2, (30, 2))
    # the holding torque of the two links (their masses are the test masses): the compiled gravity
    g = rd.compile_model(dataclasses.replace(arm, corrections=None)).gravity(q)
    x = link_positions(arm, q)
    a1, a2 = q[:, 0], q[:, 1]
    expected1 = (a1 + 2e-4 * a1 + 1e-4 * np.cos(a1) - 3e-5 * np.sin(a1) + 2e-5 * np.cos(100 * a1)
                 - 1e-5 * np.sin(100 * a1) - 3e-4 * g[:, 0])
    expected2 = a2 + 4e-5 * np.sin(a2) - 5e-4 * g[:, 1]  # gear 1: no motor harmonic
    np.testing.assert_allclose(x[:, 0], expected1, rtol=0, atol=1e-13)
    np.testing.assert_allclose(x[:, 1], expected2, rtol=0, atol=1e-13)
    # the forward kinematics of the readings are those of the link angles
    model = rd.compile_model(arm)
    rigid = rd.compile_model(dataclasses.replace(arm, corrections=None))
    np.testing.assert_allclose(model.forward_kinematics(q), rigid.forward_kinematics(x), rtol=0, atol=1e-15)


def test_exact_deflection_is_the_fixed_point(arm):
    exact = dataclasses.replace(arm, corrections=dataclasses.replace(arm.corrections, deflection="exact"))
    q = np.random.default_rng(2).uniform(-2, 2, (30, 2))
    x = link_positions(exact, q)
    u = link_positions(dataclasses.replace(exact, corrections=dataclasses.replace(
        exact.corrections, table=tuple(r[:5] + (0.0,) for r in exact.corrections.table))), q)
    c = exact.corrections.array[:, 5]
    np.testing.assert_allclose(x, u - c * holding_torque(exact.corrections.holding, x), rtol=0, atol=1e-13)


def test_point_mass_torque_is_the_gradient_of_the_potential():
    """A spatial 3-joint chain (one prismatic joint) with masses and a mass-free first moment."""
    holding = HoldingTorque(
        axis_points=((0.0, 0.0, 0.0), (0.1, 0.0, 0.5), (0.3, 0.2, 0.5)),
        axis_directions=((0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0)),
        joint_types=("revolute", "prismatic", "revolute"),
        masses=(1.0, 2.0, 0.5, 0.0),
        moments=((0.1, 0.0, 0.2), (0.6, 0.4, 1.0), (0.2, 0.1, 0.3), (0.0, 0.3, 0.1)),
        moved_by=(1, 2, 3, 3), gravity=(0.3, -0.2, -9.7))

    def poe(q):  # positions of the masses' moments by explicit homogeneous transforms
        out = []
        for row in q:
            frames = []
            t = np.eye(4)
            for j in range(3):
                p, d = np.array(holding.axis_points[j]), np.array(holding.axis_directions[j])
                m = np.eye(4)
                if holding.joint_types[j] == "revolute":
                    k = np.array([[0, -d[2], d[1]], [d[2], 0, -d[0]], [-d[1], d[0], 0]])
                    r = np.eye(3) + np.sin(row[j]) * k + (1 - np.cos(row[j])) * k @ k
                    m[:3, :3], m[:3, 3] = r, p - r @ p
                else:
                    m[:3, 3] = row[j] * d
                t = t @ m
                frames.append(t.copy())
            v = 0.0
            for mass, h, b in zip(holding.masses, holding.moments, holding.moved_by, strict=True):
                f = frames[b - 1]
                v -= np.array(holding.gravity) @ (f[:3, :3] @ np.array(h) + mass * f[:3, 3])  # V = -g . m p
            out.append(v)
        return np.array(out)

    q = np.random.default_rng(3).uniform(-1.5, 1.5, (10, 3))
    h = 1e-6
    fd = np.stack([(poe(q + h * e) - poe(q - h * e)) / (2 * h) for e in np.eye(3)], axis=1)
    np.testing.assert_allclose(holding_torque(holding, q), fd, rtol=0, atol=1e-7)


BAD = [
    ("corrections: {joints: {j9: {ratio: 1.0e-4}}}", r"arm.yaml: corrections.joints.j9: no such joint"),
    ("corrections: {joints: {j1: {scale: 1.0e-4}}}", r"corrections.joints.j1.scale: unknown key"),
    ("corrections: {joints: {j1: {ratio: .nan}}}", r"corrections.joints.j1.ratio: expected a finite number"),
    ("corrections: {joints: {j1: {compliance: 1.0e-4}}}", r"arm.yaml: corrections: a joint has a compliance "
                                                          r"but there is no holding_torque"),
    ("corrections: {joints: {}, deflection: cubic}",
     r"corrections.deflection: expected one of linear, exact"),
    ("corrections: [1, 2]", r"arm.yaml: corrections: expected a mapping"),
]


@pytest.mark.parametrize(("block", "pattern"), BAD)
def test_bad_blocks_are_refused_naming_the_field(block, pattern):
    with pytest.raises(DescriptionError, match=pattern):
        _load(TWO_LINK + block)


@pytest.mark.parametrize(("change", "pattern"), [
    (("masses", 0, "moved_by", 3), r"masses\[0\].moved_by: expected a joint count 1..2"),
    (("masses", 1, "mass", -1.0), r"masses\[1\].mass: expected a finite number >= 0"),
    (("axes", 0, "direction", [0, 2, 0]), r"axes\[0\].direction: not a unit vector"),
    (("axes", 1, "type", "spherical"), r"axes\[1\].type: expected revolute or prismatic"),
    (("masses", 0, "moment", [1, 2]), r"masses\[0\].moment: expected a list of 3 numbers"),
])
def test_bad_holding_torque_is_refused_naming_the_field(change, pattern):
    data = yaml.safe_load(CORRECTIONS)
    key, index, field, value = change
    data["corrections"]["holding_torque"][key][index][field] = value
    with pytest.raises(DescriptionError, match=r"arm.yaml: corrections.holding_torque." + pattern):
        _load(TWO_LINK + yaml.safe_dump(data))


def test_urdf_states_what_it_cannot_hold(arm, tmp_path: Path):
    from robodyn.export.urdf import to_urdf
    from robodyn.robot.errors import DescriptionWarning

    with pytest.warns(DescriptionWarning, match="joint-reading corrections .* are not written"):
        to_urdf(arm, tmp_path / "arm.urdf")
    assert "<!-- joint-reading corrections" in (tmp_path / "arm.urdf").read_text()
