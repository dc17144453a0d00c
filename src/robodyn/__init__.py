"""robodyn: equations of motion, simulation code, identification and calibration for manipulators.

Public API::

    import robodyn as rd
    robot = rd.load("puma560")
    eom = rd.derive(robot, method="newton_euler")   # or "lagrange", "kane"
    model = rd.compile_model(robot)                  # generated C, loaded in-process
    model.inverse_dynamics(q, qd, qdd)               # (n,) or (N, n)
    x, tau = rd.rollout(model, x0, rd.RolloutOptions(steps=1000, dt=1e-3))  # one C call
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from robodyn._version import __version__ as __version__

# Public names and the module each comes from. They are imported on first use (PEP 562), so
# ``import robodyn`` and the command line do not pay for SciPy's signal processing, cvxpy or
# Dask unless a command needs them. The packages beside the public functions ``simulate``,
# ``calibrate``, ``identify`` and ``validate`` are named for what they hold (``simulation``,
# ``calibration``, ``identification``, ``validation``), so ``import robodyn.X`` always gives a
# module and ``rd.simulate`` is always the function.
_EXPORTS = {
    "Calibration": "robodyn.calibration",
    "CalibrateOptions": "robodyn.calibration",
    "calibrate": "robodyn.calibration",
    "Identification": "robodyn.identification",
    "IdentifyOptions": "robodyn.identification",
    "identify": "robodyn.identification",
    "Payload": "robodyn.identification",
    "Recording": "robodyn.measure",
    "excitation": "robodyn.studies.excitation",
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
    "Trajectory": "robodyn.simulation",
    "SimulateOptions": "robodyn.simulation",
    "simulate": "robodyn.simulation",
    "FeedbackLaw": "robodyn.simulation.rollouts",
    "RolloutOptions": "robodyn.simulation.rollouts",
    "rollout": "robodyn.simulation.rollouts",
    "sweep": "robodyn.studies.sweeps",
    "EquationsOfMotion": "robodyn.symbolic.eom",
    "derive": "robodyn.symbolic.eom",
    "Validation": "robodyn.validation",
    "validate": "robodyn.validation",
}

if TYPE_CHECKING:  # static analysers see ordinary imports
    from robodyn.calibration import Calibration, calibrate
    from robodyn.identification import Identification, Payload, identify
    from robodyn.measure import Recording, read_recording
    from robodyn.numeric.model import Model, compile_model
    from robodyn.robot.load import builtin_names, load
    from robodyn.robot.model import Drive, Friction, Joint, Link, Robot
    from robodyn.simulation import Trajectory, simulate
    from robodyn.simulation.rollouts import FeedbackLaw, RolloutOptions, rollout
    from robodyn.studies.excitation import excitation
    from robodyn.studies.sweeps import sweep
    from robodyn.symbolic.eom import EquationsOfMotion, derive
    from robodyn.validation import Validation, validate


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
    "CalibrateOptions",
    "Calibration",
    "Drive",
    "EquationsOfMotion",
    "FeedbackLaw",
    "Identification",
    "IdentifyOptions",
    "Payload",
    "Friction",
    "Joint",
    "Link",
    "Model",
    "Recording",
    "Robot",
    "RolloutOptions",
    "SimulateOptions",
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
    "rollout",
    "simulate",
    "sweep",
    "validate",
]
