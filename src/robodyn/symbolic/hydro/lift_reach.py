"""Whether lift can reach an arm's joints at all.

Lift acts along ``e x u_n``, normal to the cylinder's axis and to the relative flow. On a planar
arm (parallel revolute joint axes, cylinders in the plane, a current in the plane) both ``e`` and
``u_n`` lie in the plane, so the lift is normal to it: the bearings carry it and no joint torque
changes, whatever ``C_L``. That is physics, not a modelling gap (a symmetric section's mean lift
is zero, and the lift of an asymmetric one is still normal to the axis and the flow). The effect
series uses :func:`lift_reaches_joints` to drop its ``+ lift`` row where it could only repeat
``+ drag``, and says why.

The test is numerical: the lift torques with ``C_L = 1`` at random states (and the given current)
against the drag torques with ``C_d = 1`` at the same states (the same ``|u_n|^2`` scale).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence

import numpy as np
import sympy as sp

from robodyn.robot.hydro import fluid_of, hydro_of
from robodyn.robot.model import Robot
from robodyn.symbolic.hydro.drag import drag_torque
from robodyn.symbolic.hydro.geometry import cylinder_motion
from robodyn.symbolic.hydro.lift import lift_torque
from robodyn.symbolic.kinematics import forward_kinematics

__all__ = ["lift_reaches_joints"]

#: Lift below this fraction of the drag at every sampled state counts as none.
RELATIVE_TOLERANCE = 1e-9

#: Answers by (description hash, current, parameter values, samples, seed).
_MEMO: dict[tuple, bool] = {}


def lift_reaches_joints(robot: Robot, current: Sequence[float],
                        parameters: Mapping[str, float] | None = None, *, samples: int = 8,
                        seed: int = 0) -> bool:
    """True when a lift coefficient on the robot's wet links can change any joint torque.

    Parameters
    ----------
    robot : Robot
        With ``hydro`` blocks.
    current : (3,) sequence of float
        Uniform current, base frame, m/s.
    parameters : mapping of str to float, optional
        Values of the description's named parameters (default: its own).
    samples : int
        Random states ``q, qd`` in [-2, 2] (rad, rad/s; m, m/s) tried.
    seed : int

    Returns
    -------
    bool
    """
    values = {**{k: float(v) for k, v in robot.parameters.items()}, **(parameters or {})}
    key = (robot.description_hash, tuple(float(c) for c in current),
           tuple(sorted(values.items())), samples, seed)
    if robot.description_hash and key in _MEMO:
        return _MEMO[key]  # a study runs the same check for every case
    answer = _reaches(robot, current, values, samples, seed)
    if robot.description_hash:
        _MEMO[key] = answer
    return answer


def _reaches(robot: Robot, current: Sequence[float], values: Mapping[str, float], samples: int,
             seed: int) -> bool:
    fluid = fluid_of(robot)
    if fluid is None:
        return False
    n = robot.dof
    q, qd = sp.symbols(f"q1:{n + 1}", real=True), sp.symbols(f"qd1:{n + 1}", real=True)
    fluid = dataclasses.replace(fluid, current=sp.ImmutableMatrix([float(c) for c in current]))
    kin = forward_kinematics(robot, q)
    lift, drag = sp.zeros(n, 1), sp.zeros(n, 1)
    for i, h in enumerate(hydro_of(robot)):
        if h is None:
            continue
        unit = dataclasses.replace(h, lift=sp.Integer(1), drag=sp.Integer(1))
        for cyl in h.cylinders:
            motion = cylinder_motion(robot, kin, i, cyl, q)
            lift += lift_torque(fluid, unit, cyl, motion, qd, h.quadrature)
            drag += drag_torque(fluid, unit, cyl, motion, qd, h.quadrature)
    subs = {sp.Symbol(k, real=True): v for k, v in values.items()}
    f = sp.lambdify([q, qd], [lift.xreplace(subs), drag.xreplace(subs)], "numpy", cse=True)
    rng = np.random.default_rng(seed)
    for qv, qdv in rng.uniform(-2, 2, (samples, 2, n)):
        tau_l, tau_d = (np.abs(np.asarray(x, dtype=float)).max() for x in f(qv, qdv))
        if tau_l > RELATIVE_TOLERANCE * max(tau_d, 1e-300):
            return True
    return False
