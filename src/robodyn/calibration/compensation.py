"""Compensation: the joint readings that put the calibrated robot's target where the nominal
robot would put it (inverse kinematics of the calibrated model, Gauss-Newton from a seed).
"""

from __future__ import annotations

import numpy as np

from robodyn.calibration.data_checks import check_data
from robodyn.calibration.models import ErrorModel
from robodyn.calibration.result import Calibration
from robodyn.robot.errors import InputError

__all__ = ["compensate", "readings_for_points"]

def compensate(
    calibration: Calibration,
    points,
    q_seed,
    *,
    frame: str = "instrument",
    tol: float = 1e-10,
    max_iter: int = 100,
) -> np.ndarray:
    """Corrected joint targets that put the target on desired points (calibrated inverse kinematics).

    From ``q_seed`` (typically the nominal controller's joint solution), Newton steps with the
    minimum-norm (pseudo-inverse) joint correction, so redundant degrees of freedom change as
    little as possible.

    Parameters
    ----------
    calibration : Calibration
    points : array_like, shape (M, 3)
        Desired target positions, m.
    q_seed : array_like, shape (M, n)
    frame : {"instrument", "base"}
        Frame of ``points``: the instrument's, or the robot's chain base frame.
    tol : float
        Position tolerance, m.
    max_iter : int

    Returns
    -------
    numpy.ndarray, shape (M, n)

    Raises
    ------
    ValueError
        If a point is out of reach (no convergence from its seed).
    """
    q, pts, _, _ = check_data(calibration.robot, q_seed, points)
    if pts.ndim != 2:
        raise InputError(f"compensate: points must have shape (M, 3) (positions of the first target); "
                         f"got {pts.shape}")
    if frame == "base":
        b = calibration.base()
        pts = pts @ b[:3, :3].T + b[:3, 3]
    elif frame != "instrument":
        raise InputError(f"frame must be 'instrument' or 'base', got {frame!r}")
    return readings_for_points(calibration.model, calibration.params, pts, q, tol=tol, max_iter=max_iter)


def readings_for_points(model: ErrorModel, params: np.ndarray, points: np.ndarray, q_seed: np.ndarray,
                       *, tol: float = 1e-10, max_iter: int = 100) -> np.ndarray:
    """Readings (M, n) that put the model's target on ``points`` (M, 3), from ``q_seed`` (M, n).

    Newton steps with the minimum-norm (pseudo-inverse) joint correction, all poses at once, on
    a calibration's error model (``params`` its parameters). Not the robot's own inverse
    kinematics (:func:`robodyn.simulation.inverse_kinematics`: one pose of a compiled model, with
    joint limits and restarts): this one inverts the calibrated kinematics near a good seed.

    Raises
    ------
    ValueError
        If a point is not reached within ``tol`` (m).
    """
    q = np.array(q_seed, dtype=float)
    step = model.targets  # the first target of each pose
    for _ in range(max_iter):
        ev = model.evaluate(params, q)
        err = points - ev.position[::step]
        if np.all(np.linalg.norm(err, axis=1) < tol):
            return q
        # dq = J^+ e (minimum-norm step)
        q += np.einsum("mij,mj->mi", np.linalg.pinv(ev.jac_joint[::step, :3], rcond=1e-10), err)
    err = np.linalg.norm(points - model.evaluate(params, q, derivatives=False).position[::step], axis=1)
    bad = np.flatnonzero(err >= tol)
    if bad.size:
        raise InputError(f"compensate: {bad.size} point(s) not reached (first: index {bad[0]}, "
                         f"{err[bad[0]] * 1e3:.3g} mm away); out of reach or a poor seed")
    return q
