"""Simulation: integrators, controllers, planned trajectories, inverse kinematics, case studies.

Public entry points::

    from robodyn.simulation import simulate, PD, quintic
    model = rd.compile_model(rd.load("puma560"))
    traj = simulate(model, q0, None, duration=2.0, dt=1e-3, controller=PD(100, 20, q_ref))
    x, tau = rollout(model, x0, RolloutOptions(steps=2000, dt=1e-3))   # the bare integrator

The AA300 design study and the double-pendulum balance are in
:mod:`robodyn.studies.aa300` and :mod:`robodyn.studies.balance` (they import matplotlib).
"""

from robodyn.simulation.controllers import LQR, PD, PID, ComputedTorque, Controller, GravityCompensation
from robodyn.simulation.energy import frame_origins, potential_energy
from robodyn.simulation.ik import IKResult, UnreachableError, inverse_kinematics
from robodyn.simulation.linearization import Linearization, linearize
from robodyn.simulation.options import SimulateOptions
from robodyn.simulation.rollouts import FeedbackLaw, RolloutOptions, rollout
from robodyn.simulation.simulation import ADAPTIVE, FIXED_STEP, Trajectory, simulate
from robodyn.simulation.trajectory import (
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
    "SimulateOptions",
    "JointTrajectory",
    "LQR",
    "PD",
    "PID",
    "ComputedTorque",
    "Controller",
    "FeedbackLaw",
    "GravityCompensation",
    "Linearization",
    "RolloutOptions",
    "Trajectory",
    "UnreachableError",
    "cartesian_line",
    "concatenate",
    "frame_origins",
    "inverse_kinematics",
    "linearize",
    "potential_energy",
    "quintic",
    "rollout",
    "simulate",
    "trapezoidal",
    "via_points",
]
