"""Parameter values that override a description's defaults are checked like loaded ones."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import robodyn as rd
from robodyn.robot.errors import DescriptionError, DescriptionWarning
from robodyn.robot.overrides import checked_parameter_values
from robodyn.robot.yaml_loader import load_yaml_text

WHERE = r"compile_model\(parameters=\.\.\.\)"

ARM = """\
name: arm
parameters: {m: 2.0, l: 0.5, J: 1e-4, G: 50, b: 0.1, lo: -1, hi: 1, v: 3}
joints:
  - name: j1
    type: revolute
    dh: {a: l}
    limits: {lower: lo, upper: hi, velocity: v}
    drive: {gear_ratio: G, rotor_inertia: J}
    friction: {viscous: b}
    link: {name: rod, mass: m, com: [-l/2, 0, 0], inertia: {ixx: 0, iyy: m*l^2/12, izz: m*l^2/12}}
"""


def arm() -> rd.Robot:
    return load_yaml_text(ARM, source="arm.yaml")


@pytest.mark.parametrize(
    ("override", "pattern"),
    [
        ({"m": -1.0}, r"\(m = -1\): arm\.yaml: links\[0\]\.mass: mass of link 'rod' is negative"),
        ({"m": float("nan")}, r": 'm': expected a finite real number, got nan"),
        ({"l": float("inf")}, r": 'l': expected a finite real number, got inf"),
        ({"m": "2"}, r": 'm': expected a finite real number, got '2'"),
        ({"J": -1e-3}, r"joints\[0\]\.drive\.rotor_inertia: rotor inertia must not be negative"),
        ({"G": 0.0}, r"joints\[0\]\.drive\.gear_ratio: gear ratio must not be zero"),
        ({"b": -0.5}, r"joints\[0\]\.friction\.viscous: viscous friction must not be negative"),
        ({"v": -3.0}, r"joints\[0\]\.limits\.velocity: velocity limit must not be negative"),
        ({"lo": 2.0}, r"joints\[0\]\.limits: lower limit 2 is above upper limit 1"),
        ({"mass": 1.0}, r": robot 'arm' has no parameter\(s\) mass; it has m, l, J"),
    ],
)
def test_bad_overrides_are_refused_before_compiling(override: dict, pattern: str) -> None:
    # before: negative and NaN masses were compiled into a model without a word
    with pytest.raises(DescriptionError, match=f"^{WHERE}.*{pattern}"):
        rd.compile_model(arm(), backend="numpy", parameters=override)


def test_values_are_merged_and_unchanged_ones_not_rechecked() -> None:
    robot = arm()
    assert checked_parameter_values(robot, None) == dict(robot.parameters)
    values = checked_parameter_values(robot, {"m": np.float64(3.0), "l": 1})
    assert values == {**robot.parameters, "m": 3.0, "l": 1.0}
    assert all(type(v) is float for v in values.values())


def test_implausible_inertia_at_new_values_warns() -> None:
    text = ARM.replace("iyy: m*l^2/12", "iyy: m*l^2/12 - s").replace("J: 1e-4", "J: 1e-4, s: 0")
    robot = load_yaml_text(text, source="arm.yaml")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        checked_parameter_values(robot, {"s": 0.0})  # the same value: nothing to re-check
    with pytest.warns(DescriptionWarning, match=r"links\[0\]: link 'rod': implausible inertia"):
        checked_parameter_values(robot, {"s": 0.1})


def test_valid_override_still_compiles() -> None:
    robot = rd.load("planar_2r")
    model = rd.compile_model(robot, backend="numpy", parameters={"m2": 2.0})
    base = rd.compile_model(robot, backend="numpy")
    q = np.array([0.3, -0.2])
    # g2 = m2 lc2 g cos(q1 + q2) is linear in m2
    np.testing.assert_allclose(model.gravity(q)[1], 2 * base.gravity(q)[1], rtol=1e-12)
