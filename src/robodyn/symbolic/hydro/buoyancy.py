"""Buoyancy: the fluid's upthrust ``-rho V g`` at each link's centre of buoyancy.

Buoyancy is exactly a gravity term of mass ``-rho V`` placed at the centre of buoyancy ``c_B``,
so it enters ``g(q)`` (the torques that hold the arm still) and is linear in ``rho V``::

    U_B(q)  = rho V g_w . x_B(q)                  (potential energy; g_w the gravity vector)
    g_B(q)  = dU_B/dq = rho V J_B(q)^T g_w        (J_B: translational Jacobian of x_B)
"""

from __future__ import annotations

import sympy as sp

from robodyn import spatial as S
from robodyn.robot.hydro import Fluid, LinkHydro
from robodyn.robot.model import Robot
from robodyn.symbolic.kinematics import Kinematics, point_jacobian

__all__ = ["buoyancy_torque"]


def buoyancy_torque(robot: Robot, kin: Kinematics, fluid: Fluid,
                    hydro: tuple[LinkHydro | None, ...]) -> sp.ImmutableMatrix:
    """Joint torques that hold the arm still against buoyancy, shape (n, 1) (N m or N).

    Parameters
    ----------
    robot : Robot
    kin : Kinematics
        Link poses in the world frame (expressions in q).
    fluid : Fluid
    hydro : tuple of LinkHydro or None, length n

    Returns
    -------
    ImmutableMatrix, shape (n, 1)
        ``sum_i rho V_i J_Bi^T g_w``: add it to the gravity load ``g(q)``.
    """
    out = sp.zeros(robot.dof, 1)
    g_w = sp.Matrix(robot.gravity)
    for i, h in enumerate(hydro):
        if h is None or h.volume == 0:
            continue
        t = kin.links[i]
        # x_B = p_i + R_i c_B
        x_b = S.translation(t) + S.rotation(t) * h.center_of_buoyancy
        jac = point_jacobian(robot, kin, x_b, i + 1)[:3, :]
        # g_B += rho V J_B^T g_w   (a gravity term of mass -rho V)
        out += fluid.density * h.volume * jac.T * g_w
    return sp.ImmutableMatrix(out)
