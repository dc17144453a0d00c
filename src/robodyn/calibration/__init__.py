"""Kinematic calibration from measured end-effector positions (Stone's method, S-model, ISO 9283).

``calibrate(robot, q, points, model="s-model")`` returns a frozen :class:`Calibration`: the
calibrated robot (base = the measuring instrument's frame, tool = the measured target), the
identified parameters with standard uncertainties, the parameters found unidentifiable and why,
residuals, before/after error statistics and observability indices. See ``docs/calibration.md``.

Modules: :mod:`~.models` (DH, Hayati, S-model, POE), :mod:`~.nominal` (geometry of a robot),
:mod:`~.kinematics` (vectorised chain and Jacobians), :mod:`~.identifiability`,
:mod:`~.solve` (weighted Levenberg-Marquardt), :mod:`~.circle_point`, :mod:`~.to_robot`,
:mod:`~.iso9283`, :mod:`~.io` (CSV in, YAML/URDF/report out), :mod:`~.simulate_study`.
"""

from robodyn.calibration.compensation import compensate
from robodyn.calibration.held_out import validate
from robodyn.calibration.identifiability import Observability, Unidentifiable, observability, select_poses
from robodyn.calibration.joint_axes import CirclePointResult, circle_point
from robodyn.calibration.models import MODELS, ErrorModel, build_model
from robodyn.calibration.nominal import robot_geometry
from robodyn.calibration.options import CalibrateOptions
from robodyn.calibration.pipeline import calibrate, random_configurations
from robodyn.calibration.result import Calibration, ErrorStats, Parameter

__all__ = [
    "MODELS",
    "CalibrateOptions",
    "Calibration",
    "CirclePointResult",
    "ErrorModel",
    "ErrorStats",
    "Observability",
    "Parameter",
    "Unidentifiable",
    "build_model",
    "calibrate",
    "circle_point",
    "compensate",
    "observability",
    "random_configurations",
    "robot_geometry",
    "select_poses",
    "validate",
]
