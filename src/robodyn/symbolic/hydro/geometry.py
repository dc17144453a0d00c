"""Kinematics of a cylinder fixed in a link, in that LINK's frame: how fast its points move.

A point at arc length ``xi`` along cylinder ``(s, a, L)`` (start ``s``, unit axis ``a``, length
``L``, all constant in the link frame) has, in link-frame components, the velocity::

    v(xi) = J_s qd + xi (omega x a) = (J_s + xi J_b) qd,     J_b = -[a]x J_omega

with ``J_s`` (3, n) the translational Jacobian of the start point and ``J_omega`` (3, n) the
angular-velocity Jacobian of the link, both expressed in the link frame. ``omega x a`` is normal
to the axis and the axial velocity ``a . v(xi) = a . J_s qd`` is the same at every point.

Link-frame components are computed from the RELATIVE poses of the joints as seen from the link
(chaining the inverse joint transforms back from the link): joint ``k`` of link ``i``'s
Jacobian then depends on ``q_(k+1) .. q_i`` only, e.g. ``l1 cos(q2)`` for the elbow link of a
planar arm, where world-frame components hold products of sines and cosines of every angle that
no trigonometric pass needs to undo. Every hydrodynamic quantity is a rotation invariant (``J^T
J``, ``J^T u``, ``|u|``), so the frame changes no value, only the size of the expressions (and of
the generated code). The current, given in the world frame, is rotated in: ``R_i^T c``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp

from robodyn import spatial as S
from robodyn.robot.hydro import Cylinder
from robodyn.robot.model import Robot
from robodyn.symbolic.kinematics import Kinematics, motion

__all__ = ["CylinderMotion", "cylinder_motion", "link_frame_jacobian"]


@dataclass(frozen=True)
class CylinderMotion:
    """Link-frame kinematics of one cylinder, expressions in q.

    Attributes
    ----------
    axis : ImmutableMatrix, shape (3, 1)
        a (unit, constant).
    start : ImmutableMatrix, shape (3, 1)
        s, m (constant).
    j_start : ImmutableMatrix, shape (3, n)
        J_s: velocity of the start point, m/s per joint velocity, link-frame components.
    j_bend : ImmutableMatrix, shape (3, n)
        J_b = -[a]x J_omega: ``d v / d xi`` per joint velocity, 1/s.
    rotation : ImmutableMatrix, shape (3, 3)
        R_i: the link frame's orientation in the world (world components = R_i link components).
    """

    axis: sp.ImmutableMatrix
    start: sp.ImmutableMatrix
    j_start: sp.ImmutableMatrix
    j_bend: sp.ImmutableMatrix
    rotation: sp.ImmutableMatrix

    def normal_projector(self) -> sp.ImmutableMatrix:
        """P = I - a a^T, shape (3, 3)."""
        a = self.axis
        return sp.ImmutableMatrix(sp.eye(3) - a * a.T)

    def to_link(self, world: sp.MatrixBase) -> sp.ImmutableMatrix:
        """A world-frame vector (3, 1) in link-frame components: ``R_i^T w``."""
        return sp.ImmutableMatrix(self.rotation.T * sp.Matrix(world))


def link_frame_jacobian(robot: Robot, q: Sequence[sp.Expr], link: int,
                        point: sp.MatrixBase) -> sp.ImmutableMatrix:
    """Geometric Jacobian ``[v; omega]`` of a point fixed in link ``link`` (0-based), shape
    (6, n), in that link's frame.

    Parameters
    ----------
    robot : Robot
    q : sequence of Expr, length n
    link : int
    point : (3, 1) matrix
        The point in the link frame, m.
    """
    n = robot.dof
    jac = sp.zeros(6, n)
    t = sp.eye(4)  # pose of link k's frame in link i's frame, k = i, i-1, ..., 0
    p = sp.Matrix(point)
    for k in range(link, -1, -1):
        joint = robot.joints[k]
        # frame after joint k's motion: ^iT_k post_k^-1 (the motion keeps the axis fixed)
        jf = t * S.inverse(joint.post)
        z = S.rotation(jf) * joint.axis
        if joint.type == "prismatic":
            jac[:3, k] = z
        else:
            # v = z x (p - o_k), omega = z
            jac[:3, k] = S.cross(z, p - S.translation(jf))
            jac[3:, k] = z
        # ^iT_(k-1) = ^iT_k post_k^-1 motion_k(q_k)^-1 pre_k^-1
        t = jf * S.inverse(motion(joint, q[k])) * S.inverse(joint.pre)
    return sp.ImmutableMatrix(jac)


def cylinder_motion(robot: Robot, kin: Kinematics, link: int, cyl: Cylinder,
                    q: Sequence[sp.Expr]) -> CylinderMotion:
    """Link-frame kinematics of cylinder ``cyl`` of link ``link`` (0-based); ``kin`` gives the
    link's orientation in the world (for the current)."""
    jac = link_frame_jacobian(robot, q, link, cyl.start)
    # J_b = -[a]x J_omega  (omega x a per joint velocity)
    j_bend = -S.skew(cyl.axis) * jac[3:, :]
    return CylinderMotion(axis=sp.ImmutableMatrix(cyl.axis), start=sp.ImmutableMatrix(cyl.start),
                          j_start=sp.ImmutableMatrix(jac[:3, :]), j_bend=sp.ImmutableMatrix(j_bend),
                          rotation=sp.ImmutableMatrix(S.rotation(kin.links[link])))


def velocity(motion: CylinderMotion, qd: Sequence[sp.Expr]) -> tuple[sp.Matrix, sp.Matrix]:
    """``(v(0), dv/dxi)``: start-point velocity and its change per metre along the axis, (3, 1),
    link-frame components."""
    qv = sp.Matrix(qd)
    return motion.j_start * qv, motion.j_bend * qv
