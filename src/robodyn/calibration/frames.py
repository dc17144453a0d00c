"""Tool frames and positions of a robot description for joint readings (the Hayati chain)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from robodyn.calibration.models import build_model
from robodyn.calibration.nominal import robot_geometry
from robodyn.numeric.joint_corrections import link_positions
from robodyn.robot.numbers import RobotNumbers

if TYPE_CHECKING:
    from robodyn.robot.model import Robot

__all__ = ["robot_frames", "robot_positions"]


def robot_positions(robot: Robot | RobotNumbers, q: np.ndarray) -> np.ndarray:
    """Tool positions of ``robot`` in its world frame for readings (N, n), shape (N, 3), m.

    Evaluated through the Hayati chain, which stays well conditioned at nearly parallel axes.
    """
    return robot_frames(robot, q)[:, :3, 3]


def robot_frames(robot: Robot | RobotNumbers, q: np.ndarray) -> np.ndarray:
    """Tool frames of ``robot`` in its world frame for readings (N, n), shape (N, 4, 4).

    The description's joint-reading corrections (``robot.corrections``) are applied first.
    """
    model = build_model("hayati", robot_geometry(robot), orientation=True)
    x = link_positions(robot, np.atleast_2d(np.asarray(q, dtype=float)))
    ev = model.evaluate(model.initial, x, derivatives=False)
    out = np.zeros((len(ev.position), 4, 4))
    out[:, :3, :3], out[:, :3, 3], out[:, 3, 3] = ev.rotation, ev.position, 1.0
    return out
