"""robodyn: equations of motion, simulation code, identification and calibration for manipulators.

Public API::

    import robodyn as rd
    robot = rd.load("puma560")
    eom = rd.derive(robot, method="newton_euler")   # or "lagrange", "kane"
"""

from robodyn.robot.load import builtin_names, load
from robodyn.robot.model import Drive, Friction, Joint, Link, Robot
from robodyn.symbolic.eom import EquationsOfMotion, derive

__all__ = [
    "Drive",
    "EquationsOfMotion",
    "Friction",
    "Joint",
    "Link",
    "Robot",
    "builtin_names",
    "derive",
    "load",
]
__version__ = "0.1.0"
