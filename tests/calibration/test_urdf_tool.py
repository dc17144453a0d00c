"""A ROS-Industrial-style URDF (world root, ``base`` side frame, ``ee_link`` and ``tool0`` fixed to
the last link, inertial side links) calibrates exactly like the equivalent YAML description, and
``robodyn calibrate --tool LINK`` picks the tool link by name.

The YAML below is transcribed by hand from ``tests/robot/fixtures/ur5_ros_industrial.urdf`` (joint
origins and axes; ``tool`` = the ``tool0`` frame in ``wrist_3_link``), not written by robodyn.
"""

from __future__ import annotations

import csv
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

import robodyn as rd
from robodyn.calibration import calibrate, random_configurations, validate
from robodyn.cli import main
from robodyn.studies.calibration_study import perturbed_robot, robot_positions
from tests.calibration.helpers import TRACKER

UR5 = Path(__file__).resolve().parents[1] / "robot" / "fixtures" / "ur5_ros_industrial.urdf"
HALF_PI = "1.570796325"  # as written in the URDF
_JOINTS = (  # name, origin xyz, origin rpy, axis
    ("shoulder_pan_joint", "[0, 0, 0.089159]", "[0, 0, 0]", "[0, 0, 1]"),
    ("shoulder_lift_joint", "[0, 0.13585, 0]", f"[0, {HALF_PI}, 0]", "[0, 1, 0]"),
    ("elbow_joint", "[0, -0.1197, 0.425]", "[0, 0, 0]", "[0, 1, 0]"),
    ("wrist_1_joint", "[0, 0, 0.39225]", f"[0, {HALF_PI}, 0]", "[0, 1, 0]"),
    ("wrist_2_joint", "[0, 0.093, 0]", "[0, 0, 0]", "[0, 0, 1]"),
    ("wrist_3_joint", "[0, 0, 0.09465]", "[0, 0, 0]", "[0, 1, 0]"),
)
UR5_YAML = "name: ur5\ntool: {xyz: [0, 0.0823, 0], rpy: [-" + HALF_PI + ", 0, 0]}\njoints:\n" + "".join(
    f"  - name: {name}\n    type: revolute\n    origin: {{xyz: {xyz}, rpy: {rpy}}}\n    axis: {axis}\n"
    f"    link: {{name: link{k}, mass: 1.0, com: [0, 0, 0], "
    "inertia: {ixx: 0.01, iyy: 0.01, izz: 0.01}}\n"
    for k, (name, xyz, rpy, axis) in enumerate(_JOINTS, 1))
TARGET = (0.021, 0.034, 0.052)  # reflector in the tool0 frame, m


def _load(source, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rd.load(source, **kw)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("ur5")
    (d / "ur5.yaml").write_text(UR5_YAML)
    yaml_robot = _load(d / "ur5.yaml")
    true = perturbed_robot(yaml_robot, 11, base=TRACKER, target=TARGET)
    rng = np.random.default_rng(12)
    q = random_configurations(yaml_robot, 80, 13)
    y = robot_positions(true, q) + rng.normal(0, 5e-5, (80, 3))
    with open(d / "poses.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([*yaml_robot.joint_names, "x", "y", "z"])
        w.writerows([[repr(float(v)) for v in row] for row in np.hstack((q, y))])
    return d, yaml_robot, true, q, y


def test_yaml_transcription_matches_the_urdf_tool0_pose(files):
    _, yaml_robot, _, q, _ = files
    urdf_robot = _load(UR5, tool="tool0")
    assert urdf_robot.joint_names == yaml_robot.joint_names
    a = rd.compile_model(urdf_robot, backend="numpy").forward_kinematics(q[:5])
    b = rd.compile_model(yaml_robot, backend="numpy").forward_kinematics(q[:5])
    np.testing.assert_allclose(a, b, atol=1e-12)


@pytest.mark.parametrize("model", ["s-model", "hayati"])
def test_urdf_with_side_frames_calibrates_like_the_yaml(files, model):
    _, yaml_robot, true, q, y = files
    cal_y = calibrate(yaml_robot, q, y, model)
    cal_u = calibrate(_load(UR5, tool="tool0"), q, y, model)
    pa = {p.name: p.value for p in cal_y.parameters}
    pb = {p.name: p.value for p in cal_u.parameters}
    assert pa.keys() == pb.keys() and len(pa) > 20
    for k in pa:
        assert pb[k] == pytest.approx(pa[k], abs=1e-9), k
    np.testing.assert_allclose(cal_u.target_offsets(), cal_y.target_offsets(), atol=1e-9)
    q_test = random_configurations(yaml_robot, 40, 14)
    np.testing.assert_allclose(cal_u.predict(q_test), cal_y.predict(q_test), atol=1e-9)
    y_test = robot_positions(true, q_test)
    assert validate(cal_u, q_test, y_test).rms == pytest.approx(validate(cal_y, q_test, y_test).rms,
                                                                 abs=1e-12)
    assert validate(cal_u, q_test, y_test).rms < 1e-4  # and it calibrated


def test_cli_tool_link_by_name(files, tmp_path):
    d = files[0]
    runs = {}
    for key, robot, extra in (("yaml", d / "ur5.yaml", []), ("tool0", UR5, ["--tool", "tool0"]),
                              ("wrist_3", UR5, ["--tool", "wrist_3_link"])):
        out = tmp_path / key
        assert main(["calibrate", str(robot), "--data", str(d / "poses.csv"), *extra,
                     "-o", str(out)]) == 0
        runs[key] = json.loads(next(out.glob("*_report.json")).read_text())
    values = {k: {p["name"]: p["value"] for p in r["parameters"]} for k, r in runs.items()}
    for k in values["yaml"]:
        assert values["tool0"][k] == pytest.approx(values["yaml"][k], abs=1e-9), k
    np.testing.assert_allclose(runs["tool0"]["targets_m"], runs["yaml"]["targets_m"], atol=1e-9)
    # the calibrated robot's tool frame sits at the reflector with the chosen link's orientation
    tools = {k: np.array(_load(next((tmp_path / k).glob("*_calibrated.yaml"))).tool, dtype=float)
             for k in runs}
    np.testing.assert_allclose(tools["tool0"], tools["yaml"], atol=1e-12)
    chosen = np.array(_load(UR5, tool="tool0").tool, dtype=float)
    np.testing.assert_allclose(tools["tool0"][:3, :3], chosen[:3, :3], atol=1e-12)
    assert np.abs(chosen[:3, :3] - np.eye(3)).max() > 0.5  # tool0 is turned against wrist_3_link
    np.testing.assert_allclose(tools["wrist_3"][:3, :3], np.eye(3), atol=1e-12)
    np.testing.assert_allclose(tools["wrist_3"][:3, 3], tools["tool0"][:3, 3], atol=1e-9)
    assert runs["wrist_3"]["after_m"]["rms"] == pytest.approx(runs["tool0"]["after_m"]["rms"], rel=1e-6)
