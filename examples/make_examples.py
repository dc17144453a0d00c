"""Regenerate the example data files in this folder (deterministic: fixed random seeds).

    .venv/bin/python examples/make_examples.py

* ``poses.csv`` / ``held.csv``: 60 / 20 PUMA 560 poses measured by a simulated laser tracker
  (0.05 mm noise per coordinate) on a "true" PUMA with about 1 mm / 0.1 degree of manufacturing
  errors (:func:`robodyn.studies.calibration_study.perturbed_robot`), in the instrument frame;
  input of ``robodyn calibrate``.
* ``cycles.csv``: ISO 9283 pose accuracy and repeatability data, 5 commanded poses (the test
  cube's P1-P5) each attained 30 times; input of ``robodyn iso9283``.
* ``approach.csv``: one measured approach to a pose (a damped oscillation settling at the
  attained position); input of ``robodyn iso9283 --approach``.
* ``run.mcap``: a ROS 2 bag (``sensor_msgs/JointState`` on ``/joint_states``) of a PUMA 560 in
  the virtual lab: 4 s of an excitation at 100 Hz with encoder quantisation and joint torque
  sensors (position, velocity left out so it is estimated, effort); input of ``robodyn record``
  and ``rd.read_recording("run.mcap", robot=robot)``.
"""

from __future__ import annotations

import csv
import warnings
from pathlib import Path

import numpy as np

import robodyn as rd
from robodyn.calibration.iso9283 import cube_points
from robodyn.calibration.pipeline import random_configurations
from robodyn.studies.calibration_study import perturbed_robot, robot_positions

HERE = Path(__file__).resolve().parent


def _write(name: str, header: list[str], rows: np.ndarray | list, comment: str) -> None:
    with (HERE / name).open("w", newline="") as fh:
        fh.write(f"# {comment}\n")
        writer = csv.writer(fh, lineterminator="\n")
        writer.writerow(header)
        for row in rows:
            writer.writerow([v if isinstance(v, str) else f"{v:.9g}" for v in row])


def poses() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        nominal = rd.load("puma560")
    true = perturbed_robot(nominal, 7)
    rng = np.random.default_rng(8)
    for name, count in (("poses.csv", 60), ("held.csv", 20)):
        q = random_configurations(nominal, count, rng)
        points = robot_positions(true, q) + rng.normal(0.0, 5e-5, (count, 3))
        _write(name, [*nominal.joint_names, "x", "y", "z"], np.hstack([q, points]),
               f"PUMA 560 joint readings (rad) and tracker x, y, z (m); simulated, {count} poses")


def cycles() -> None:
    rng = np.random.default_rng(9)
    commanded = cube_points(np.array([0.5, 0.0, 0.4]), size=0.5)
    rows = []
    for p, c in enumerate(commanded, start=1):
        bias = rng.normal(0.0, 2e-4, 3)  # accuracy error of this pose
        for _ in range(30):
            x = c + bias + rng.normal(0.0, 2e-5, 3)  # repeatability scatter
            rows.append([str(p), *c, *x])
    _write("cycles.csv", ["pose", "x_cmd", "y_cmd", "z_cmd", "x", "y", "z"], rows,
           "ISO 9283: 5 commanded poses (m) each attained 30 times; simulated")


def approach() -> None:
    t = np.arange(0.0, 1.5, 2e-3)
    target = np.array([0.5, 0.0, 0.4])
    direction = np.array([1.0, 0.0, 0.0])
    # under-damped arrival along x from 5 mm short: overshoot about 1.1 mm (near t = 1/6 s), then
    # inside a 0.1 mm band after about 0.3 s
    s = -0.005 * np.exp(-10.0 * t) * np.cos(2 * np.pi * 3.0 * t)
    x = target + np.outer(s, direction)
    _write("approach.csv", ["t", "x", "y", "z"], np.column_stack([t, x]),
           "ISO 9283 overshoot: one approach to a pose, t (s), x, y, z (m); simulated")


def bag() -> None:
    from robodyn.measure.mcap_io import write_mcap
    from robodyn.studies.virtual_lab import Sensors, virtual_lab

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("puma560")
    model = rd.compile_model(robot)
    ex = rd.excitation(model, harmonics=3, base_frequency=0.25, starts=1, seed=5,
                       max_iterations=5, dt=0.01)
    sensors = Sensors(sample_period=0.01, jitter=0.0, torque_noise=0.05, tracker_period=0.0)
    rec = virtual_lab(model, ex, sensors=sensors, seed=5).recording
    # a controller's bag: positions and efforts at its own stamps (no current, no temperature)
    out = rd.Recording(t=rec.t + 1.7e9, q=rec.q, tau=np.round(rec.tau, 4),
                       joint_names=robot.joint_names, source="run.mcap")
    write_mcap(out, HERE / "run.mcap")


if __name__ == "__main__":
    poses()
    cycles()
    approach()
    bag()
