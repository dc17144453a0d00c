"""Lagrange-Euler equations from kinetic and potential energy.

``M(q) = sum_i m_i Jv_i^T Jv_i + Jw_i^T R_i I_i R_i^T Jw_i`` from the centre-of-mass Jacobians,
``C`` from the Christoffel symbols of ``M`` (:mod:`robodyn.symbolic.coriolis`) and
``g = dV/dq`` with ``V = -sum_i m_i g . p_ci``.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from robodyn import spatial as S
from robodyn.robot.model import Robot
from robodyn.symbolic.kinematics import forward_kinematics, point_jacobian


def mass_matrix_and_potential(robot: Robot, q: Sequence[sp.Symbol]) -> tuple[sp.ImmutableMatrix, sp.Expr]:
    """Rigid-body inertia matrix (n, n) and potential energy (J) from the link Jacobians."""
    kin = forward_kinematics(robot, q)
    n = robot.dof
    m_total = sp.zeros(n, n)
    potential = sp.Integer(0)
    for i, link in enumerate(robot.links):
        t = kin.links[i]
        rot = S.rotation(t)
        # p_c = R_i c_i + o_i : centre of mass in the world frame
        p_c = rot * link.com + S.translation(t)
        jac = point_jacobian(robot, kin, p_c, i + 1)
        jv, jw = jac[:3, :], jac[3:, :]
        # world-frame inertia about the COM: R I R^T
        inertia_w = rot * link.inertia * rot.T
        # M += m Jv^T Jv + Jw^T (R I R^T) Jw
        m_total += link.mass * (jv.T * jv) + jw.T * inertia_w * jw
        # V -= m g . p_c
        potential -= link.mass * (robot.gravity.T * p_c)[0, 0]
    return sp.ImmutableMatrix(m_total), potential


def gravity_from_potential(potential: sp.Expr, q: Sequence[sp.Symbol]) -> sp.ImmutableMatrix:
    """``g_k = dV/dq_k``, shape (n, 1)."""
    return sp.ImmutableMatrix([sp.diff(potential, qk) for qk in q])
