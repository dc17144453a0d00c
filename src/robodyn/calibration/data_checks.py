"""Calibration data checked and converted: shapes, finite values, units, plausible magnitudes.

What :func:`robodyn.calibration.calibrate` and the functions that use a calibration refuse, with
messages naming the array and the reason, before anything is fitted.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from robodyn.calibration.models import build_model
from robodyn.calibration.nominal import RobotGeometry
from robodyn.robot.errors import InputError
from robodyn.robot.numbers import RobotNumbers, robot_numbers

if TYPE_CHECKING:
    from robodyn.robot.model import Robot

__all__ = ["ANGLE_UNITS", "LENGTH_UNITS", "check_data", "check_magnitude", "convert_units"]

def _array(name: str, value, shape_text: str) -> np.ndarray:
    try:
        a = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be a numeric array of shape {shape_text}: {exc}") from None
    bad = np.argwhere(~np.isfinite(a))
    if bad.size:
        row = int(bad[0][0])
        col = f", column {int(bad[0][1])}" if bad.shape[1] > 1 else ""
        raise InputError(f"{name} has NaN or infinite values ({len(bad)} entries; first at row {row}{col})")
    return a


def check_data(robot: Robot | RobotNumbers, q, points, orientations=None, sigma=5e-5,
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray]:
    """Validate calibration data; returns q (N, n), points, orientations and sigma (shape of points).

    ``points`` is (N, 3), or (N, K, 3) for K targets measured at each pose.

    Raises
    ------
    ValueError
        On wrong shapes, mismatched lengths, NaN or infinite values, non-rotations, bad sigma.
    """
    n = robot.dof
    q = _array("q", q, f"(N, {n})")
    points = _array("points", points, "(N, 3) or (N, K, 3)")
    if q.ndim != 2 or q.shape[1] != n:
        raise InputError(f"q must have shape (N, {n}) for {robot.name}'s {n} joints "
                         f"({', '.join(robot.joint_names)}); got {q.shape}")
    if points.ndim not in (2, 3) or points.shape[-1] != 3 or (points.ndim == 3 and points.shape[1] < 1):
        raise InputError(f"points must have shape (N, 3) or (N, K, 3) for K targets per pose; "
                         f"got {points.shape}")
    if len(q) != len(points):
        raise InputError(f"mismatched lengths: q has {len(q)} poses but points has {len(points)}")
    if orientations is not None:  # one per pose: the frame of the body that carries the targets
        orientations = _array("orientations", orientations, "(N, 3, 3)")
        if orientations.shape != (len(q), 3, 3):
            raise InputError(f"orientations must have shape ({len(q)}, 3, 3); got {orientations.shape}")
        err = np.abs(orientations @ np.swapaxes(orientations, 1, 2) - np.eye(3)).max(axis=(1, 2))
        det = np.linalg.det(orientations)
        bad = np.flatnonzero((err > 1e-6) | (det < 0))
        if bad.size:
            raise InputError(f"orientations[{bad[0]}] is not a rotation matrix ({bad.size} such rows)")
    s = _array("sigma", sigma, "scalar, (N,), (N, 3) or the shape of points")
    if s.ndim == 1:
        s = s.reshape((-1,) + (1,) * (points.ndim - 1))
    elif s.ndim == 2 and points.ndim == 3:
        s = s[:, None, :]
    try:
        s = np.broadcast_to(s, points.shape).copy()
    except ValueError:
        raise InputError(f"sigma must be a scalar, (N,), (N, 3) or {points.shape} for N = {len(points)}; "
                         f"got shape {np.shape(sigma)}") from None
    if not np.all(s > 0):
        raise InputError("sigma must be positive")
    return q, points, orientations, s


#: Length and angle units accepted by :func:`calibrate`, with their factor to SI.
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3}


ANGLE_UNITS = {"rad": 1.0, "deg": math.pi / 180}


def convert_units(robot: Robot | RobotNumbers, q, points, sigma, sigma_rot, length_unit: str,
                  angle_unit: str):
    """Copies of q, points, sigma and sigma_rot in m and rad (revolute joints' readings only).

    Raises
    ------
    ValueError
        An unknown unit.
    """
    if length_unit not in LENGTH_UNITS:
        raise InputError(f"length_unit must be one of {', '.join(LENGTH_UNITS)}, got {length_unit!r}")
    if angle_unit not in ANGLE_UNITS:
        raise InputError(f"angle_unit must be one of {', '.join(ANGLE_UNITS)}, got {angle_unit!r}")
    if length_unit == "m" and angle_unit == "rad":
        return q, points, sigma, sigma_rot
    lf, af = LENGTH_UNITS[length_unit], ANGLE_UNITS[angle_unit]
    q = _array("q", q, f"(N, {robot.dof})")
    if q.ndim == 2 and q.shape[1] == robot.dof:
        scale = np.array([af if t == "revolute" else 1.0 for t in robot_numbers(robot).joint_types])
        q = q * scale  # a new array: the caller's is not modified
    return q, _array("points", points, "(N, 3)") * lf, _array("sigma", sigma, "") * lf, sigma_rot * af


def check_magnitude(geometry: RobotGeometry, q: np.ndarray, points: np.ndarray, length_unit: str) -> None:
    """Reject data whose spread contradicts the declared length unit.

    The spread (RMS distance from the mean) of the measured points is compared with that of the
    nominal model's target over the same readings; they differ by a rigid placement and small
    errors only, so a ratio beyond 30 (or below 1/30) means the unit is wrong (millimetres given
    as metres gives 1000).

    Raises
    ------
    ValueError
        Naming the declared unit, the two spreads and the likely unit.
    """
    if len(q) < 3:
        return
    nominal = build_model("dh", geometry)
    p = nominal.evaluate(nominal.initial, q, derivatives=False).position
    y = points.reshape(len(q), -1, 3)[:, 0]
    spread_n = float(np.sqrt(((p - p.mean(axis=0)) ** 2).sum(axis=1).mean()))
    spread_y = float(np.sqrt(((y - y.mean(axis=0)) ** 2).sum(axis=1).mean()))
    if spread_n <= 0 or spread_y <= 0:
        return
    ratio = spread_y / spread_n
    if ratio > 30 or ratio < 1 / 30:
        hint = ("the data look like millimetres: give length_unit='mm' (CLI --length-unit mm)"
                if 300 < ratio < 3000 else
                "the data look like metres: give length_unit='m'" if 3e-4 < ratio < 3e-3 else
                "check the units of the points and of the joint readings (deg vs rad)")
        raise InputError(f"points contradict length_unit {length_unit!r}: the measured points spread "
                         f"{spread_y:.4g} {'units' if length_unit != 'm' else 'm'} (as given, converted: "
                         f"{spread_y:.4g} m) where the nominal model's target spreads {spread_n:.4g} m over "
                         f"the same readings (ratio {ratio:.3g}); {hint}")
