"""robodyn: equations of motion, simulation code, identification and calibration for manipulators.

Public API::

    import robodyn as rd
    robot = rd.load("puma560")
    eom = rd.derive(robot, method="newton_euler")   # or "lagrange", "kane"
    model = rd.compile_model(robot)                  # generated C, loaded in-process
    model.inverse_dynamics(q, qd, qdd)               # (n,) or (N, n)
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import TYPE_CHECKING, Any

# Public names and the module each comes from. They are imported on first use (PEP 562), so
# ``import robodyn`` and the command line do not pay for SciPy's signal processing, cvxpy or
# Dask unless a command needs them.
_EXPORTS = {
    "Calibration": "robodyn.calibrate",
    "calibrate": "robodyn.calibrate",
    "Identification": "robodyn.identify",
    "identify": "robodyn.identify",
    "Payload": "robodyn.identify",
    "Recording": "robodyn.measure",
    "excitation": "robodyn.measure",
    "read_recording": "robodyn.measure",
    "Model": "robodyn.numeric.model",
    "compile_model": "robodyn.numeric.model",
    "builtin_names": "robodyn.robot.load",
    "load": "robodyn.robot.load",
    "Drive": "robodyn.robot.model",
    "Friction": "robodyn.robot.model",
    "Joint": "robodyn.robot.model",
    "Link": "robodyn.robot.model",
    "Robot": "robodyn.robot.model",
    "Trajectory": "robodyn.simulate",
    "simulate": "robodyn.simulate",
    "sweep": "robodyn.study.sweep",
    "EquationsOfMotion": "robodyn.symbolic.eom",
    "derive": "robodyn.symbolic.eom",
    "Validation": "robodyn.validate",
    "validate": "robodyn.validate",
}

if TYPE_CHECKING:  # static analysers see ordinary imports
    from robodyn.calibrate import Calibration, calibrate
    from robodyn.identify import Identification, Payload, identify
    from robodyn.measure import Recording, excitation, read_recording
    from robodyn.numeric.model import Model, compile_model
    from robodyn.robot.load import builtin_names, load
    from robodyn.robot.model import Drive, Friction, Joint, Link, Robot
    from robodyn.simulate import Trajectory, simulate
    from robodyn.study.sweep import sweep
    from robodyn.symbolic.eom import EquationsOfMotion, derive
    from robodyn.validate import Validation, validate


class _Package(types.ModuleType):
    """``robodyn`` itself: keeps public functions that share a subpackage's name bound.

    After importing a subpackage the import system binds it on its parent (``robodyn.simulate``
    = the package); for ``simulate``, ``calibrate``, ``identify`` and ``validate`` the public name
    is the function of that name, so the package's own function is bound instead.
    """

    def __setattr__(self, name: str, value: Any) -> None:
        if isinstance(value, types.ModuleType) and _EXPORTS.get(name) == value.__name__:
            value = getattr(value, name)
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'robodyn' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))


__all__ = [
    "Calibration",
    "Drive",
    "EquationsOfMotion",
    "Identification",
    "Payload",
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
