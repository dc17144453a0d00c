"""Kinematics of a cylinder fixed in a link: where it is and how fast its points move.

A point at arc length ``xi`` along cylinder ``(s, a, L)`` of link ``i`` (link frame ``R_i, p_i``
in the world) is ``x(xi) = p_i + R_i s + xi e`` with ``e = R_i a``. Its velocity is linear in
``xi``::

    v(xi) = J_s qd + xi (omega x e) = (J_s + xi J_b) qd,     J_b = -[e]x J_omega

with ``J_s`` (3, n) the translational Jacobian of the start point and ``J_omega`` (3, n) the
angular-velocity Jacobian of the link. ``omega x e`` is normal to the axis and the axial velocity
``e . v(xi) = e . J_s qd`` is the same at every point of the cylinder.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp

from robodyn import spatial as S
from robodyn.hydro.schema import Cylinder
from robodyn.robot.model import Robot
from robodyn.symbolic.kinematics import Kinematics, point_jacobian

__all__ = ["CylinderMotion", "cylinder_motion"]


@dataclass(frozen=True)
class CylinderMotion:
    """World-frame kinematics of one cylinder, expressions in q.

    Attributes
    ----------
    axis : ImmutableMatrix, shape (3, 1)
        e = R_i a (unit).
    start : ImmutableMatrix, shape (3, 1)
        x(0), m.
    j_start : ImmutableMatrix, shape (3, n)
        J_s: velocity of the start point, m/s per joint velocity.
    j_bend : ImmutableMatrix, shape (3, n)
        J_b = -[e]x J_omega: ``d v / d xi`` per joint velocity, 1/s.
    """

    axis: sp.ImmutableMatrix
    start: sp.ImmutableMatrix
    j_start: sp.ImmutableMatrix
    j_bend: sp.ImmutableMatrix

    def normal_projector(self) -> sp.ImmutableMatrix:
        """P = I - e e^T, shape (3, 3)."""
        e = self.axis
        return sp.ImmutableMatrix(sp.eye(3) - e * e.T)


def cylinder_motion(robot: Robot, kin: Kinematics, link: int, cyl: Cylinder) -> CylinderMotion:
    """Kinematics of cylinder ``cyl`` of link ``link`` (0-based) at the poses ``kin``."""
    t = kin.links[link]
    r, p = S.rotation(t), S.translation(t)
    # e = R_i a,  x(0) = p_i + R_i s
    e = sp.ImmutableMatrix(r * cyl.axis)
    x0 = sp.ImmutableMatrix(p + r * cyl.start)
    jac = point_jacobian(robot, kin, x0, link + 1)
    # J_b = -[e]x J_omega  (omega x e per joint velocity)
    j_bend = -S.skew(e) * jac[3:, :]
    return CylinderMotion(axis=e, start=x0, j_start=sp.ImmutableMatrix(jac[:3, :]),
                          j_bend=sp.ImmutableMatrix(j_bend))


def velocity(motion: CylinderMotion, qd: Sequence[sp.Expr]) -> tuple[sp.Matrix, sp.Matrix]:
    """``(v(0), dv/dxi)``: start-point velocity and its change per metre along the axis, (3, 1)."""
    qv = sp.Matrix(qd)
    return motion.j_start * qv, motion.j_bend * qv
