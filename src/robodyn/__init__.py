"""robodyn: equations of motion, simulation code, identification and calibration for manipulators.

Public API::

    import robodyn as rd
    robot = rd.load("puma560")
    eom = rd.derive(robot, method="newton_euler")   # or "lagrange", "kane"
    model = rd.compile_model(robot)                  # generated C, loaded in-process
    model.inverse_dynamics(q, qd, qdd)               # (n,) or (N, n)
"""

from robodyn.calibrate import Calibration, calibrate
from robodyn.identify import Identification, identify
from robodyn.measure import Recording, excitation, read_recording
from robodyn.numeric.model import Model, compile_model
from robodyn.robot.load import builtin_names, load
from robodyn.robot.model import Drive, Friction, Joint, Link, Robot
from robodyn.simulate import Trajectory, simulate
from robodyn.study.sweep import sweep
from robodyn.symbolic.eom import EquationsOfMotion, derive
from robodyn.validate import Validation, validate

__all__ = [
    "Calibration",
    "Drive",
    "EquationsOfMotion",
    "Identification",
    "Friction",
    "Joint",
    "Link",
    "Model",
    "Recording",
    "Robot",
    "Trajectory",
    "Validation",
    "builtin_names",
    "calibrate",
    "compile_model",
    "derive",
    "excitation",
    "identify",
    "load",
    "read_recording",
    "simulate",
    "sweep",
    "validate",
]
__version__ = "0.1.0"
