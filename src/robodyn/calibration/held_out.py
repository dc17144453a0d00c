"""A calibration's error statistics on poses it was not fitted to (positions and orientations).
"""

from __future__ import annotations

import numpy as np

from robodyn.calibration.data_checks import check_data
from robodyn.calibration.result import Calibration, ErrorStats
from robodyn.calibration.solve import rotation_vector
from robodyn.robot.errors import InputError

__all__ = ["validate", "validate_orientation"]

def validate(calibration: Calibration, q, points) -> ErrorStats:
    """Error statistics of the calibrated model on other (held-out) poses.

    Parameters
    ----------
    calibration : Calibration
    q : array_like, shape (N, n)
    points : array_like, shape (N, 3)
        Measured target positions, instrument frame, m.
    """
    q, points, _, _ = check_data(calibration.robot, q, points)
    return ErrorStats.from_residuals(points - calibration.predict(q))


def validate_orientation(calibration: Calibration, q, orientations) -> ErrorStats:
    """Orientation error statistics of the calibrated model on other (held-out) poses.

    Parameters
    ----------
    calibration : Calibration
        Fitted with measured orientations.
    q : array_like, shape (N, n)
    orientations : array_like, shape (N, 3, 3)
        Measured orientations (one per pose, the targets' common frame), instrument frame.

    Returns
    -------
    ErrorStats
        Of the rotation vectors ``log(R_measured R_predicted^T)``: angles in rad.
    """
    if not calibration.model.orientation:
        raise InputError("validate_orientation: the calibration was fitted without orientations")
    q = np.atleast_2d(np.asarray(q, dtype=float))
    dummy = np.zeros((len(q), 3))
    q, _, orientations, _ = check_data(calibration.robot, q, dummy, orientations)
    k = calibration.model.targets
    predicted = calibration.predict_frames(q)[::k, :3, :3]
    return ErrorStats.from_residuals(rotation_vector(orientations @ np.swapaxes(predicted, 1, 2)))
