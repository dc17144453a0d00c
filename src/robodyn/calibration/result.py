"""Frozen results of a kinematic calibration: :class:`Calibration` and :class:`ErrorStats`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from robodyn.calibration.identifiability import Observability, Unidentifiable
from robodyn.calibration.joint_axes import CirclePointResult
from robodyn.calibration.models import ErrorModel, model_frames
from robodyn.calibration.options import CalibrateOptions

if TYPE_CHECKING:
    from robodyn.robot.model import Robot

__all__ = ["Calibration", "ErrorStats", "Parameter"]


@dataclass(frozen=True)
class ErrorStats:
    """Statistics of position errors ``|measured - predicted|`` over a set of poses, in metres.

    Attributes
    ----------
    mean, rms, max : float
        Mean, root mean square and largest distance error, m.
    std : float
        Sample standard deviation of the distance errors (``ddof = 1``; 0 for one pose), m.
    count : int
        Number of poses.
    """

    mean: float
    rms: float
    max: float
    std: float
    count: int

    @classmethod
    def from_residuals(cls, residuals: np.ndarray) -> ErrorStats:
        """Statistics of residual vectors of shape (N, 3) (m)."""
        d = np.linalg.norm(np.asarray(residuals, dtype=float).reshape(-1, 3), axis=1)
        if d.size == 0:
            return cls(0.0, 0.0, 0.0, 0.0, 0)
        std = float(np.std(d, ddof=1)) if d.size > 1 else 0.0
        return cls(float(d.mean()), float(np.sqrt(np.mean(d**2))), float(d.max()), std, int(d.size))

    def text(self) -> str:
        """One line in millimetres."""
        return (f"mean {self.mean * 1e3:.4f} mm, RMS {self.rms * 1e3:.4f} mm, "
                f"max {self.max * 1e3:.4f} mm, std {self.std * 1e3:.4f} mm ({self.count} poses)")

    def angle_text(self) -> str:
        """One line in milliradians, for statistics of rotation vectors (rad)."""
        return (f"mean {self.mean * 1e3:.4f} mrad, RMS {self.rms * 1e3:.4f} mrad, "
                f"max {self.max * 1e3:.4f} mrad, std {self.std * 1e3:.4f} mrad ({self.count} poses)")


@dataclass(frozen=True)
class Parameter:
    """One identified parameter.

    Attributes
    ----------
    name : str
    value : float
        Estimate, m or rad.
    std : float
        Standard uncertainty, same unit.
    initial : float
        Value before calibration (nominal, or the circle-point estimate).
    unit : str
    """

    name: str
    value: float
    std: float
    initial: float
    unit: str


#: Display scale and unit of each parameter unit in :meth:`Calibration.summary`.
_DISPLAY = {"m": (1e3, "mm"), "rad": (180 / np.pi, "deg"), "rad/(N m)": (1e6, "urad/(N m)"),
            "m/N": (1e6, "um/N")}


def _frozen(a: np.ndarray | None) -> np.ndarray | None:
    if a is None:
        return None
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class Calibration:
    """A calibrated kinematic model and how well it fits.

    Attributes
    ----------
    robot : Robot
        The calibrated robot: its base places the robot in the measuring instrument's frame, its
        tool frame is the measured target, its links, drives and friction are the nominal robot's
        (see :mod:`robodyn.calibration.to_robot`).
    model : ErrorModel
        The error model, with ``params`` its parameter values.
    params : numpy.ndarray, shape (P,)
        All parameter values (identified and held).
    parameters : tuple of Parameter
        The identified parameters with standard uncertainties.
    covariance : numpy.ndarray, shape (L, L)
        Their covariance (order of ``parameters``).
    unidentifiable : tuple of Unidentifiable
        Parameters held at their initial value, and why.
    residuals : numpy.ndarray, shape (N, 3)
        Measured minus predicted target positions after calibration, m.
    rotation_residuals : numpy.ndarray or None, shape (N, 3)
        Orientation residuals (rotation vectors), rad, when orientations were measured.
    before_residuals : numpy.ndarray, shape (N, 3)
        The same for the nominal kinematics with only the instrument placement and the target
        offset fitted.
    before, after : ErrorStats
        Statistics of ``before_residuals`` and ``residuals``.
    observability : Observability
        Indices O1-O5 of the identification Jacobian at the solution.
    variance_factor : float
        Weighted residual sum of squares per degree of freedom (about 1 when ``sigma`` is right).
    pose_count : int
    sigma : float
        The measurement standard uncertainty used (m; the mean when it varied).
    loss : str
    initial : str
        ``"nominal"`` or ``"circle-point"``.
    nfev : int
        Residual evaluations of the final fit.
    converged : bool
    message : str
        The solver's own report.
    circle_point : CirclePointResult or None
    before_robot : Robot or None
        The nominal robot placed in the instrument frame with the fitted target as its tool: the
        model behind ``before_residuals``.
    targets_axis : bool
        The points were given as (N, K, 3): residuals and predictions keep that shape.
    options : CalibrateOptions or None
        The choices the run was made with (:mod:`robodyn.calibration.options`).
    """

    robot: Robot
    model: ErrorModel
    params: np.ndarray
    parameters: tuple[Parameter, ...]
    covariance: np.ndarray
    unidentifiable: tuple[Unidentifiable, ...]
    residuals: np.ndarray
    rotation_residuals: np.ndarray | None
    before_residuals: np.ndarray
    before: ErrorStats
    after: ErrorStats
    observability: Observability
    variance_factor: float
    pose_count: int
    sigma: float
    loss: str
    initial: str
    nfev: int
    converged: bool
    message: str
    circle_point: CirclePointResult | None = None
    before_robot: Robot | None = None
    targets_axis: bool = False
    options: CalibrateOptions | None = None

    def __post_init__(self) -> None:
        for name in ("params", "covariance", "residuals", "rotation_residuals", "before_residuals"):
            object.__setattr__(self, name, _frozen(getattr(self, name)))

    @property
    def model_name(self) -> str:
        """The error model's name."""
        return self.model.name

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """Names of the identified parameters."""
        return tuple(p.name for p in self.parameters)

    @property
    def values(self) -> np.ndarray:
        """Identified values, shape (L,)."""
        return np.array([p.value for p in self.parameters])

    @property
    def std(self) -> np.ndarray:
        """Standard uncertainties of the identified values, shape (L,)."""
        return np.array([p.std for p in self.parameters])

    def predict(self, q: np.ndarray) -> np.ndarray:
        """Predicted target positions in the instrument frame for readings (N, n), m.

        Every term is included (geometry, targets, non-geometric corrections). Shape (N, 3), or
        (N, K, 3) when the calibration's points were (N, K, 3).
        """
        q = np.atleast_2d(np.asarray(q, dtype=float))
        pos = self.model.evaluate(self.params, q, derivatives=False).position
        return pos.reshape(len(q), -1, 3) if self.targets_axis else pos

    @property
    def nongeometric(self) -> dict:
        """The non-geometric terms and their values (``{}`` without them), plain data."""
        ng = self.model.nongeometric
        return ng.as_dict(self.params[self.model.nongeometric_slice]) if ng is not None else {}

    def target_offsets(self) -> np.ndarray:
        """Positions of all targets in the last link frame, shape (K, 3), m."""
        names = ["tool"] + [f"tool{k}" for k in range(2, self.model.targets + 1)]
        return np.array([[self.params[self.model.index(f"{t}.{a}")] for a in "xyz"] for t in names])

    def predict_frames(self, q: np.ndarray) -> np.ndarray:
        """Predicted target frames (N, 4, 4); the orientation is meaningful only when measured."""
        q = np.atleast_2d(np.asarray(q, dtype=float))
        ev = self.model.evaluate(self.params, q, derivatives=False)
        out = np.zeros((len(ev.position), 4, 4))
        out[:, :3, :3], out[:, :3, 3], out[:, 3, 3] = ev.rotation, ev.position, 1.0
        return out

    def axes(self) -> tuple[np.ndarray, np.ndarray]:
        """Calibrated joint axes at zero readings, instrument frame: points (n, 3), directions (n, 3)."""
        _, motion, _ = model_frames(self.model, self.params)
        return motion[:, :3, 3].copy(), motion[:, :3, 2].copy()

    def base(self) -> np.ndarray:
        """The robot's chain base frame in the instrument frame, shape (4, 4)."""
        frame0, _, _ = model_frames(self.model, self.params)
        return frame0 @ self.model.base_to_robot

    def target(self) -> np.ndarray:
        """Target position at zero readings, instrument frame, shape (3,)."""
        return model_frames(self.model, self.params)[2][:3, 3].copy()

    def summary(self) -> str:
        """A plain-text report: statistics, parameters, unidentifiable parameters, indices."""
        lines = [
            f"Kinematic calibration of {self.robot.name} ({self.model.name} error model, "
            f"{self.initial} initial estimate, {self.loss} loss)",
            f"poses: {self.pose_count}; measurement sigma {self.sigma * 1e3:.4g} mm; "
            f"variance factor {self.variance_factor:.4g}; "
            f"{'converged' if self.converged else 'NOT converged'} ({self.message})",
            f"before: {self.before.text()}",
            f"after:  {self.after.text()}",
            *([] if self.rotation_residuals is None else
              [f"orientation after: {ErrorStats.from_residuals(self.rotation_residuals).angle_text()}"]),
            "",
            f"{'parameter':<18}{'initial':>14}{'estimate':>14}{'std':>12}  unit",
        ]
        for p in self.parameters:
            scale, unit = _DISPLAY.get(p.unit, (1.0, p.unit))
            lines.append(f"{p.name:<18}{p.initial * scale:>14.6f}{p.value * scale:>14.6f}"
                         f"{p.std * scale:>12.3g}  {unit}")
        if self.unidentifiable:
            lines += ["", "not identifiable (held at their initial value):"]
            for u in self.unidentifiable:
                lines.append(f"  {u.name} [{u.kind}]: {u.reason}")
        obs = self.observability.as_dict()
        lines += ["", "observability: " + ", ".join(f"{k} {v:.4g}" for k, v in obs.items())]
        return "\n".join(lines)

