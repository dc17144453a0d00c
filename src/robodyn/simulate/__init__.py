"""Simulation: integrators, controllers, planned trajectories, inverse kinematics, case studies.

Public entry points::

    from robodyn.simulate import simulate, PD, quintic
    model = rd.compile_model(rd.load("puma560"))
    traj = simulate(model, q0, None, duration=2.0, dt=1e-3, controller=PD(100, 20, q_ref))

The AA300 design study and the double-pendulum balance are in
:mod:`robodyn.simulate.aa300_study` and :mod:`robodyn.simulate.balance` (they import matplotlib).
"""

from robodyn.simulate.controllers import LQR, PD, PID, ComputedTorque, Controller, GravityCompensation
from robodyn.simulate.energy import frame_origins, potential_energy
from robodyn.simulate.ik import IKResult, UnreachableError, inverse_kinematics
from robodyn.simulate.linearize import Linearization, linearize
from robodyn.simulate.simulation import ADAPTIVE, FIXED_STEP, Trajectory, simulate
from robodyn.simulate.trajectory import (
    JointTrajectory,
    cartesian_line,
    concatenate,
    quintic,
    trapezoidal,
    via_points,
)

__all__ = [
    "ADAPTIVE",
    "FIXED_STEP",
    "IKResult",
    "JointTrajectory",
    "LQR",
    "PD",
    "PID",
    "ComputedTorque",
    "Controller",
    "GravityCompensation",
    "Linearization",
    "Trajectory",
    "UnreachableError",
    "cartesian_line",
    "concatenate",
    "frame_origins",
    "inverse_kinematics",
    "linearize",
    "potential_energy",
    "quintic",
    "simulate",
    "trapezoidal",
    "via_points",
]
