"""Per-joint error metrics of a predicted signal against a measured one."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robodyn.robot.errors import InputError

__all__ = ["ErrorMetrics", "error_metrics"]


@dataclass(frozen=True, eq=False)
class ErrorMetrics:
    """Errors ``e = predicted - measured`` per joint (arrays read-only).

    Attributes
    ----------
    rms : (n,) ndarray
        ``sqrt(mean(e^2))``, in the signal's unit.
    max : (n,) ndarray
        ``max |e|``, in the signal's unit.
    relative : (n,) ndarray
        ``||e|| / ||y||`` (2-norms over the samples): 0 is perfect, 1 is as bad as predicting
        zero. NaN where the measured signal is identically zero.
    nrmse : (n,) ndarray
        ``rms(e) / (max y - min y)``: RMS error normalised by the measured range. NaN where the
        measured signal is constant.
    total_relative : float
        ``||E||_F / ||Y||_F`` over all joints together (those with a measurement).
    """

    rms: np.ndarray
    max: np.ndarray
    relative: np.ndarray
    nrmse: np.ndarray
    total_relative: float

    def rows(self, names: tuple[str, ...] | list[str]) -> list[list[object]]:
        """``[name, rms, max, relative, nrmse]`` per joint, formatted to 4 significant digits."""
        return [[name, f"{self.rms[k]:.4g}", f"{self.max[k]:.4g}", f"{self.relative[k]:.4g}",
                 f"{self.nrmse[k]:.4g}"] for k, name in enumerate(names)]


def error_metrics(measured: np.ndarray, predicted: np.ndarray) -> ErrorMetrics:
    """RMS, maximum, relative error and NRMSE per column.

    Parameters
    ----------
    measured, predicted : (N, n) array_like
        Same unit, same samples.

    Returns
    -------
    ErrorMetrics

    Raises
    ------
    ValueError
        When the shapes differ, there are no samples, or a value is not finite (a measured
        column that is entirely NaN, a joint without that sensor, gives NaN metrics instead).
    """
    y = np.asarray(measured, dtype=float)
    p = np.asarray(predicted, dtype=float)
    if y.ndim != 2 or y.shape != p.shape:
        raise InputError(f"error_metrics: measured and predicted must both be (N, n), got {y.shape} "
                         f"and {p.shape}")
    if y.shape[0] == 0:
        raise InputError("error_metrics: no samples")
    absent = np.all(np.isnan(y), axis=0)  # a joint without this sensor
    for name, arr in (("measured", y), ("predicted", p)):
        bad = np.argwhere(~np.isfinite(arr) & ~absent)
        if bad.size:
            row, col = bad[0]
            raise InputError(f"error_metrics: {name} is not finite at row {row}, column {col}")
    e = p - y
    # rms_j = sqrt(mean_k e_kj^2)
    rms = np.sqrt(np.mean(e**2, axis=0))
    norm_y = np.linalg.norm(y, axis=0)
    span = y.max(axis=0) - y.min(axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        # relative_j = ||e_j|| / ||y_j||
        relative = np.where(norm_y > 0, np.linalg.norm(e, axis=0) / norm_y, np.nan)
        nrmse = np.where(span > 0, rms / span, np.nan)
    total_y = float(np.linalg.norm(y[:, ~absent]))
    total = float(np.linalg.norm(e[:, ~absent])) / total_y if total_y > 0 else float("nan")
    out = ErrorMetrics(rms, np.abs(e).max(axis=0), relative, nrmse, total)
    for arr in (out.rms, out.max, out.relative, out.nrmse):
        arr.flags.writeable = False
    return out
