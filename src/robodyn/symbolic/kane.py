"""Kane's method: partial velocities, generalised active and inertia forces.

Generalised speeds are the joint velocities ``u = qd``. For each link ``i`` the angular velocity
``w_i`` and the centre-of-mass velocity ``v_i`` are written in link-frame components (so the link's
inertia is constant); their coefficients of ``qd_r`` are the partial angular velocities and
partial velocities. Accelerations are the time derivatives seen from the link frame plus the
transport term (``alpha = dw/dt``, ``a = dv/dt + w x v``). Kane's equations ``F_r + F*_r = 0`` with

    F_r  = tau_r + sum_i m_i g_i . v_i^r                         (generalised active forces)
    F*_r = -sum_i (m_i a_i . v_i^r + (I_i alpha_i + w_i x I_i w_i) . w_i^r)   (inertia forces)

give the rigid-body inverse dynamics ``tau_r = -F*_r - sum_i m_i g_i . v_i^r``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp

from robodyn import spatial as S
from robodyn.robot.model import Robot
from robodyn.symbolic.coriolis import time_derivative
from robodyn.symbolic.kinematics import link_transform


@dataclass(frozen=True)
class KaneTerms:
    """Kane's equations split into their parts, each shape (n, 1) or (n, n).

    Attributes
    ----------
    inertia_forces : generalised inertia forces ``F*`` (functions of q, qd, qdd).
    gravity_forces : generalised active forces of gravity.
    mass_matrix : ``-dF*/dqdd``.
    """

    inertia_forces: sp.ImmutableMatrix
    gravity_forces: sp.ImmutableMatrix
    mass_matrix: sp.ImmutableMatrix

    @property
    def tau(self) -> sp.ImmutableMatrix:
        """Rigid-body joint torques ``-(F* + F_gravity)``."""
        return sp.ImmutableMatrix(-(self.inertia_forces + self.gravity_forces))

    @property
    def gravity(self) -> sp.ImmutableMatrix:
        """Gravity load ``g(q) = -F_gravity``."""
        return sp.ImmutableMatrix(-self.gravity_forces)


def kane(robot: Robot, q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol],
         qdd: Sequence[sp.Symbol]) -> KaneTerms:
    """Generalised active and inertia forces of a serial chain."""
    n = robot.dof
    w = sp.zeros(3, 1)  # angular velocity of the previous link, its frame
    v = sp.zeros(3, 1)  # velocity of the previous link frame origin, its frame
    g = S.rotation(robot.base).T * robot.gravity  # gravity in the previous link frame
    f_star = sp.zeros(n, 1)
    f_grav = sp.zeros(n, 1)
    for i, (joint, link) in enumerate(zip(robot.joints, robot.links, strict=True)):
        t = link_transform(joint, q[i])
        rt = S.rotation(t).T
        r_post = S.rotation(joint.post)
        z = r_post.T * joint.axis
        s_vec = r_post.T * S.translation(joint.post)
        if joint.type == "prismatic":
            s_vec = s_vec + q[i] * z
        # velocity of the motion-frame origin (fixed in link i-1): v + w x p
        v_j = v + S.cross(w, S.translation(joint.pre))
        w_new = rt * w
        if joint.type == "revolute":
            w_new = w_new + z * qd[i]
        # v_i = R^T v_J + w_i x s (+ z qd prismatic)
        v_new = rt * v_j + S.cross(w_new, s_vec)
        if joint.type == "prismatic":
            v_new = v_new + z * qd[i]
        g = rt * g
        w, v = sp.Matrix(w_new), sp.Matrix(v_new)
        # centre of mass velocity and accelerations, link-frame components
        v_c = v + S.cross(w, link.com)
        alpha = time_derivative(w, q, qd, qdd)
        a_c = time_derivative(v_c, q, qd, qdd) + S.cross(w, v_c)
        # partial angular velocities and partial velocities: coefficients of qd_r
        w_r = w.jacobian(qd)
        v_r = v_c.jacobian(qd)
        inertia = link.inertia
        # inertia torque and force: -(I alpha + w x I w), -m a_c
        t_star = -(inertia * alpha + S.cross(w, inertia * w))
        r_star = -link.mass * a_c
        # F*_r += v_r . R* + w_r . T*
        f_star += v_r.T * r_star + w_r.T * t_star
        # F_r (gravity) += v_r . m g
        f_grav += v_r.T * (link.mass * g)
    mass = -f_star.jacobian(qdd)
    return KaneTerms(sp.ImmutableMatrix(f_star), sp.ImmutableMatrix(f_grav), sp.ImmutableMatrix(mass))
